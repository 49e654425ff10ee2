// Encoder-side normal-mesh resampling of a geometry image: moves the samples that the finest wavelet steps
// predict so that each one's detail points along the normal of the surface the coarser samples predict
// (Guskov, Vidimče, Sweldens & Schröder, "Normal meshes", SIGGRAPH 2000; Khodakovsky & Guskov,
// "Compression of normal meshes", 2002). A sample of step k (spacing s = 2^(k−1), the positions that are not
// both multiples of 2s) is replaced by the point where the line through its prediction P, along the normal n
// of the predicted surface there, crosses the original surface — the crossing nearest the foot of the
// sample's current position on that line (so the normal offset stays about what it was, and a thin part's
// other side is not taken), and only within `max_shift` local sample spacings of that foot. The sample's
// tangential position is then the prediction's: where the coarser samples put it. Its detail x − P is then
// (up to float rounding) a multiple of n: the tangential components that the codec's local frames
// (geometry_codec.h, docs/codec-v3.md) code coarser are near zero, and fewer bits describe the same surface.
//
// The decoder does not change: a resampled grid is an ordinary geometry image. It is a different sampling
// of the same surface, though — a sample no longer stands for the parameterization's (u,v) — so a
// consistent multi-model pack, whose morphs rely on corresponding samples, must not use it (the convert
// pipeline turns it off there).
//
// Order, matching the separable transform of wavelet.h: for each step k from the coarsest resampled one to
// k = 1, first the row and column details (whose prediction uses only the coarser grid), then the diagonal
// details (whose prediction also uses the row and column samples just placed). Predictions are computed with
// the codec's own integer transform (wavelet_forward of one step) on the positions scaled to 2^22 steps
// across the grid's bounding box; normals are those of the coarser grid subdivided with the same filter
// (central differences, one-sided at the border), as the codec's frames are.
//
// Samples on the border of the patch (seams shared with other patches, corners) never move, so seams stay
// bit-identical across patches. In the coarser steps (NormalMeshOptions::fold_guard_from_step) a crossing
// that would fold the step's grid around the sample is refused.
#pragma once

#include "codec/geometry_codec.h"
#include "codec/wavelet.h"

#include <array>
#include <cstddef>
#include <functional>
#include <optional>

namespace geomip::codec {

using Point3d = std::array<double, 3>;

/// The point where the line {origin + t·direction} crosses the surface closest to `hint`, when one lies
/// within `radius` of `hint`. Called concurrently from several threads.
using SurfaceCrossing = std::function<std::optional<Point3d>(const Point3d& origin, const Point3d& direction,
                                                             const Point3d& hint, double radius)>;

struct NormalMeshOptions {
  /// The finest `steps` wavelet steps have their samples moved (0 = none; clamped to the grid's level).
  int steps = 3;
  /// The crossing taken lies within this many local sample spacings (of its step) of the foot of the
  /// sample's position on the normal line.
  double max_shift = 0.5;
  /// The prediction filter; must be the codec's (GeometryCodecOptions::filter) for the details to come out
  /// normal.
  WaveletFilter filter = WaveletFilter::kCubicLong;
  /// Steps k ≥ this (the coarser resampled ones) refuse a crossing that would turn a triangle of the sample's
  /// umbrella in the step's grid (the sample and its four neighbours there) from facing along the predicted
  /// normal to facing against it; the sample then stays where it was (NormalMeshStats::would_fold). A fold in
  /// a coarse step's grid is predicted into every finer step, which pays for it in detail; the finest steps'
  /// folds are small and cheaper than the tangential details a refusal would leave (measured:
  /// docs/codec-v3.md, "Folds in the coarser normal-mesh steps"). 0 = no step refuses; 1 = every step.
  int fold_guard_from_step = 3;
  /// Worker threads (0 = one per hardware thread).
  int threads = 0;
};

struct NormalMeshStats {
  std::size_t candidates = 0;   ///< interior samples of the resampled steps
  std::size_t moved = 0;        ///< of those, replaced by a crossing
  std::size_t no_crossing = 0;  ///< left where they were (no crossing within reach)
  std::size_t would_fold = 0;   ///< left where they were (the crossing would fold, see fold_guard_from_step)
  /// Mean and largest move of the moved samples, in local sample spacings.
  double mean_shift = 0, max_shift = 0;
};

/// Resamples `grid` (positions of one patch) in place as described at the top of this file. candidates =
/// moved + no_crossing + would_fold.
/// \throw std::invalid_argument on a grid whose size does not match its level or with non-finite values.
NormalMeshStats normal_mesh_resample(Grid3& grid, const SurfaceCrossing& crossing,
                                     const NormalMeshOptions& options = {});

}  // namespace geomip::codec
