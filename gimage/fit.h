// Least-squares fitted geometry images: each sample moved a signed distance along its normal so that the
// uniform remesh (gimage/uniform_remesh.h, same connectivity and triangle count) is a least-squares FIT of
// the surface rather than its piecewise-linear interpolant.
//
// A resampled geometry image (resample_geometry()) puts every sample exactly on the surface, so in curved
// regions every remesh triangle lies on one side of the surface (its sag) and the symmetric RMS distance
// (surface_distance.h, the paper's PSNR, §5 of ../shared/seed/consistent-mesh-parameterizations.txt) pays all
// of it. Shifting the samples by about half the sag cuts the RMS (in 1D, a parabola's chordal interpolant
// shifted by the best constant has √(1/180 ÷ 1/30) ≈ 0.41× its RMS error).
//
// Method (Gauss–Newton on point-to-plane residuals, as ICP): dense points on the original (its vertices and
// area-uniform random points on its faces) are projected onto the remesh; each projection gives one linear
// equation in the offsets of the 3 vertices of the triangle it lands in (barycentric weights · normals, along
// the hit triangle's normal). Points on the remesh (Dunavant's 6-point rule on every triangle, exact for the
// square of a quadratic sag, weighted by area, plus its vertices with the weight Metro's sampling gives them)
// are projected onto the original likewise (along the normal of the original triangle hit). Both directions
// are averages over their samples and are added; a small Laplacian (offset differences across remesh edges)
// and Tikhonov term keep the system positive definite. The normal equations are solved by conjugate gradients
// from the previous pass's offsets to a relative residual of 1e-10 (~20 iterations; a sparse LDLT where that
// does not converge), the samples re-projected (each query started from its previous pass's answer), and this
// repeated `iterations` times.
//
// Guarantees:
// - One unknown per remesh vertex: a sample that seams share (SideLink) gets one offset, so shared
//   samples stay bit-identical in every image that holds them, and the remesh of the fitted images stays
//   watertight with the same face list.
// - |offset| ≤ FitOptions::max_offset × the vertex's mean incident edge length in the level's remesh.
// - No triangle of the fitted remesh has its normal turned by 90° or more from the same triangle of the
//   unfitted remesh (offsets of the vertices of such triangles are halved up to 8 times, then reset to 0;
//   checked in double before the positions are rounded to float).
// - Deterministic: the same inputs and options give bit-identical results, whatever `threads` is.
// - Correspondence: a sample moves only along the normal, by at most a fraction of an edge, so it stays
//   over the same surface point; the (u,v) of every sample and the face list are unchanged, and a
//   consistent set keeps its correspondences (each model is fitted to its own surface).
// - Samples that only masked quads (FitOptions::hole_quads) touch keep their exact position; masked quads'
//   triangles are neither sampled nor projected onto.
//
// Coarser remeshes of a fitted level-n image (every 2^(n−k)-th sample) are not refitted: the offsets are
// fitted for the level-n triangles.
//
// Cost: iterations passes (one more with FitOptions::measure_after), each an AABB tree of the remesh
// (SurfaceQuery) and one closest-point query per point (original side: its vertices + samples_per_triangle ×
// remesh triangles; remesh side: 6 per triangle + its vertices), and per iteration a conjugate-gradient solve
// of the vertices × vertices system. Memory: O(points + vertices), all points' linearizations held at once
// (timings and peak memory: docs/measurements.md).
#pragma once

#include "gimage/resample.h"
#include "gimage/uniform_remesh.h"
#include "mesh/mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

struct FitOptions {
  /// Gauss–Newton passes (project, solve). 0 = no fit (the images come back unchanged).
  int iterations = 3;
  /// Random face samples on the original per triangle of the remesh (plus every vertex of the original).
  double samples_per_triangle = 4;
  /// Weight of the Laplacian term, relative to the data terms (each normalized to an average).
  double smoothness = 1e-2;
  /// Weight of the Tikhonov term (offsets toward 0), relative to the data terms.
  double damping = 1e-4;
  /// Bound on |offset| as a fraction of the vertex's mean incident remesh edge length; in (0, 1].
  double max_offset = 0.25;
  /// Seed of the random face samples on the original.
  std::uint64_t seed = 0xf17;
  /// Worker threads for the closest-point queries; 0 = std::thread::hardware_concurrency().
  unsigned threads = 0;
  /// The split of the remesh's quads the fit is made for: kFixed for `geomip remesh`'s face list, kShorter for
  /// packs (decoded along the shorter diagonals; chosen here from the unfitted samples and kept through the
  /// fit — a decoder choosing from the fitted, decoded samples agrees on nearly every quad).
  QuadSplit quad_split = QuadSplit::kFixed;
  /// Optional hole mask, as HoleMaskResult::quads (per patch, per quad j·2^level + i, 1 = masked); empty =
  /// none.
  std::vector<std::vector<std::uint8_t>> hole_quads;
  /// Whether a last pass measures FitResult::rms_to_remesh_after and rms_to_original_after (one more pass
  /// of closest-point queries than the fit needs; false leaves them 0).
  bool measure_after = true;
};

struct FitResult {
  /// The fitted images: geometry moved, normals, adjacency and uncovered_samples copied from the input.
  GeometryImages images;
  /// Per patch, per sample (j·(2^level+1) + i): the signed offset along `normals` (mesh units).
  std::vector<std::vector<float>> offsets;
  /// Per patch, per sample: the unit direction of the offset (area-weighted vertex normal of the unfitted
  /// remesh).
  std::vector<std::vector<Eigen::Vector3f>> directions;
  /// RMS distance of the sampled points, original→remesh and remesh→original, before the fit and after it
  /// (the fit's own sample sets; `geomip eval` measures independently).
  double rms_to_remesh_before = 0, rms_to_original_before = 0;
  double rms_to_remesh_after = 0, rms_to_original_after = 0;  ///< 0 without FitOptions::measure_after
  std::size_t clamped = 0;         ///< offsets cut to the max_offset bound (last iteration)
  std::size_t flip_guarded = 0;    ///< offsets reduced by the flip guard (last iteration)
};

/// Fits `images` (all patches of one model, with their seam links) to `original` as above.
/// \param original the surface the samples were taken from (or the one the result will be measured against,
///   e.g. the mesh before hole filling together with a hole mask), in the images' units.
/// \throw InvalidInput naming fit_geometry_images for images without patches or of mixed levels, an original
///   without a triangle of nonzero area, options out of range (iterations < 0, samples_per_triangle ≤ 0,
///   smoothness < 0, damping ≤ 0, max_offset outside (0, 1]), or a hole mask of the wrong shape.
/// \throw SolverFailure when the sparse factorization fails (not expected: the system is positive definite).
FitResult fit_geometry_images(const TriMesh& original, const GeometryImages& images,
                              const FitOptions& options = {});

}  // namespace geomip
