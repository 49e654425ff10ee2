// Two-channel normal-map codings measured by `codec_bench --normals` (issue #14 item 5; docs/codec-v3.md,
// "Normal maps: two-channel codings (measured, not kept)"). Not part of any pack format: the measurement
// found neither better than the packs' xyz coding, so they live here, with the tool that measured them.
//
// Octahedral coordinates of a unit normal in a per-texel frame: (u, v) ∈ [−1, 1]², (n·t, n·b) / (|n·t| +
// |n·b| + |n·g|) in g's hemisphere, folded outside it; the third channel of the grids is 0.
//   - Residual against the decoded geometry: at every normal-map texel the frame comes from a geometry grid
//     (the decoder's): its parametric derivatives (central differences, one-sided at the grid border)
//     interpolated bilinearly to the texel, g = ∂u × ∂v normalized (negated for a patch whose grid runs the
//     other way), t = ∂u made orthogonal to g, b = g × t.
//   - Global octahedral coding: the same with a flat grid P(i, j) = (i, j, 0), whose frames are the xyz axes.
//   - Two layers: g from a given normal field (a coarse decode of the xyz normal map), t from the grid.
// The frames of two patches differ along their common side: residual grids are coded without seams.
// A decoder would have to build the same frames bit for bit: the frame math uses only double-precision
// +, −, ×, ÷ and sqrt on float inputs, each written as its own operation.
#pragma once

#include <cstddef>
#include <vector>

#include "codec/geometry_codec.h"

namespace geomip::bench {

using codec::Grid3;

/// Per patch: whether the frames use ∂u × ∂v (true) or −∂u × ∂v (false; a patch whose grid runs the other
/// way). A patch beyond the vector's size: true.
using Orientation = std::vector<bool>;

/// Per patch, whether ∂u × ∂v of `geometry`'s grid points along `normals` (the sum of n·g over the patch's
/// texels is ≥ 0). Grids as for normal_residual().
Orientation normal_frames_along_grid(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry);

/// The residual grids of `normals` (unit vectors, one grid per patch, all of one level) against the frames of
/// `geometry` (the decoder's geometry: same patch count, any level; a normal level finer than the geometry's
/// interpolates its frames, a coarser one samples them): per texel (u, v, 0), u, v ∈ [−1, 1].
/// \throw std::invalid_argument when the patch counts differ (encoder input, not bytes).
/// `axes` (optional, grids like `normals`): a normal field to use as the frames' g instead of the grid's
/// (t from ∂u as ever) — e.g. a coarse decode of the normal map itself (a two-layer coding).
std::vector<Grid3> normal_residual(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry,
                                   const Orientation& along_grid, const std::vector<Grid3>* axes = nullptr);

/// Inverse of normal_residual(): turns the decoded residual grids `maps` (channels 0 and 1 used; any values,
/// clamped to [−1, 1]) in place into unit normals in the frames of `geometry` (a decoder's geometry: any
/// prefix). Never throws on values: a degenerate frame (zero, infinite or NaN derivatives) falls back to
/// the xyz axes (so do grids beyond geometry's patch count). Every output texel is a unit
/// vector (to float rounding). `max_threads` as GeometryDecodeOptions::max_threads (the texels are
/// independent: the result does not depend on it). Cost: a few dozen double operations per texel.
void apply_normal_residual(std::vector<Grid3>& maps, const std::vector<Grid3>& geometry,
                           const Orientation& along_grid, const std::vector<Grid3>* axes = nullptr,
                           int max_threads = 0);

/// Bytes of all segments of an encoded stream.
std::size_t stream_bytes(const codec::EncodedGeometry& e);

/// The first `budget` bytes of an encoded stream (complete segments, then a prefix of the next), decoded
/// (what the normal chunks of a pack cut at that size hold).
std::vector<Grid3> decode_budget(const codec::EncodedGeometry& e, std::size_t budget);

}  // namespace geomip::bench
