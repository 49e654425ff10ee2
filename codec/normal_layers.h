// Two-layer normal maps (pack format 11; issue #14 item 5, docs/codec-v3.md "Two-layer normal maps"):
// layer 1 is the first passes of the packs' xyz normal stream (a coarse normal map, about 1.5° off on
// average), layer 2 the normal in a per-texel frame around layer 1's normal, as octahedral coordinates
// (u, v) ∈ [−1, 1]² in the first two channels of a grid (the third is 0). The residual is small, near the
// octahedron's pole and far from its folds, so the same codec spends fewer bytes on it than on xyz at equal
// angular error.
//
// Frame at a texel: g = layer 1's normal (unit), t = the geometry grid's ∂u (central differences,
// one-sided at the grid border, interpolated bilinearly to the texel when the normal map is finer than the
// grid) made orthogonal to g, b = g × t. The geometry is whatever the decoder has: the encoder uses the
// complete decode, a decoder of a prefix its prefix. The residual is not a prediction loop — a frame that
// differs (another prefix, another rounding) turns a small residual by a small angle and nothing accumulates
// — so encoder and decoder need not build the same frames bit for bit; they do at full decode (the same
// geometry), and the frame math uses only +, −, ×, ÷ and sqrt in double precision, each written as its own
// operation, so every IEEE platform (wasm included) gets the same result.
#pragma once

#include <vector>

#include "codec/geometry_codec.h"

namespace geomip::codec {

/// Per patch: whether ∂u × ∂v of the geometry grid points along the normals (true) or against them (false: a
/// patch whose grid runs the other way). Frames need it only when no layer-1 normal is given (a degenerate
/// one); it is stored in the pack, one bit per patch. A patch beyond the vector's size: true.
using NormalOrientation = std::vector<bool>;

/// Per patch, whether Σ n · (∂u × ∂v) over the patch's texels is ≥ 0 (`normals` unit vectors, one grid per
/// patch; `geometry` of the same patch count, any level).
NormalOrientation normal_orientation(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry);

/// Scales every texel of every grid to unit length (zero vectors stay zero): how a pack decoder turns a
/// decoded xyz normal stream into normals. Float arithmetic, one rounding per operation.
void normalize_normal_maps(std::vector<Grid3>& maps);

/// The layer-2 grids of `normals` (unit vectors, one grid per patch, all of one level) in the frames of
/// `axes` (layer 1's normals, unit, grids like `normals`) and `geometry` (same patch count, any level): per
/// texel (u, v, 0). `axes` null: the frames' normal is the grid's own, ∂u × ∂v oriented by `orientation` (a
/// residual against the geometry, measured in docs/codec-v3.md and not used by packs).
/// \throw std::invalid_argument when the patch counts or grid sizes differ (encoder input).
std::vector<Grid3> normal_residual(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry,
                                   const NormalOrientation& orientation,
                                   const std::vector<Grid3>* axes = nullptr);

/// Inverse of normal_residual() (same `axes`, or null): turns decoded layer-2 grids `maps` (channels 0 and 1;
/// any values: NaN → 0, clamped to [−1, 1]) in place into unit normals. Never throws on values: a degenerate
/// frame (zero, infinite or NaN derivatives, a zero axis) falls back to the grid's own normal or the xyz
/// axes, and grids whose patch has no axis or geometry of the right shape use the xyz axes. `max_threads` as
/// GeometryDecodeOptions::max_threads (the result does not depend on it). Cost: a few dozen double
/// operations per texel.
void apply_normal_residual(std::vector<Grid3>& maps, const std::vector<Grid3>& geometry,
                           const NormalOrientation& orientation, const std::vector<Grid3>* axes = nullptr,
                           int max_threads = 0);

}  // namespace geomip::codec
