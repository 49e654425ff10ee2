// Two-channel normal-map codings measured by `codec_bench --normals` (issue #14 item 5; docs/codec-v3.md,
// "Normal maps: two-channel codings" and "Two-layer normal maps"). Of these the two-layer coding became pack
// format 11's (codec/normal_layers.h, whose frame math the bench uses); the others stay here, with the tool
// that measured them.
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
#pragma once

#include <cstddef>
#include <vector>

#include "codec/geometry_codec.h"
#include "codec/normal_layers.h"

namespace geomip::bench {

using codec::Grid3;

// The frame math is the packs' own (codec/normal_layers.h, two-layer normal maps since pack format 11).
using Orientation = codec::NormalOrientation;
using codec::apply_normal_residual;
using codec::normal_residual;
inline Orientation normal_frames_along_grid(const std::vector<Grid3>& normals,
                                            const std::vector<Grid3>& geometry) {
  return codec::normal_orientation(normals, geometry);
}

/// Bytes of all segments of an encoded stream.
std::size_t stream_bytes(const codec::EncodedGeometry& e);

/// The first `budget` bytes of an encoded stream (complete segments, then a prefix of the next), decoded
/// (what the normal chunks of a pack cut at that size hold).
std::vector<Grid3> decode_budget(const codec::EncodedGeometry& e, std::size_t budget);

}  // namespace geomip::bench
