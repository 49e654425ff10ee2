// meshoptimizer's own mesh codec as a rate–distortion and decode-speed baseline (Debian
// libmeshoptimizer-dev 0.18; the codec behind glTF's EXT_meshopt_compression).
//
// Positions are quantized to `quantization_bits` (≤ 16) unsigned integers per axis on one uniform grid over
// the bounding box (step = largest extent / (2^Q − 1), as Draco does), stored as four uint16 per vertex (the
// fourth is 0: meshoptimizer's vertex codec wants a stride that is a multiple of 4). Triangles are reordered
// for the post-transform vertex cache (meshopt_optimizeVertexCache, Forsyth-like) and vertices for fetch
// locality (meshopt_optimizeVertexFetch); then meshopt_encodeIndexBuffer and meshopt_encodeVertexBuffer code
// the two streams. The byte count is both streams plus a 28-byte header (counts, grid origin and step), the
// size a real container would need. Decoding is meshopt_decodeIndexBuffer + meshopt_decodeVertexBuffer +
// dequantization to floats.
//
// This file is a baseline, not part of the geomip codec (it lives in the `geomip_baselines` target).
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

struct MeshoptCodecOptions {
  /// Position quantization bits per axis, 1..16.
  int quantization_bits = 16;
  /// Decode runs timed; the reported decode time is the fastest.
  int decode_runs = 5;
};

struct MeshoptCodecResult {
  std::size_t bytes = 0;         ///< header + encoded index stream + encoded vertex stream
  std::size_t index_bytes = 0;   ///< meshopt_encodeIndexBuffer output
  std::size_t vertex_bytes = 0;  ///< meshopt_encodeVertexBuffer output
  TriMesh decoded;               ///< the decoded, dequantized mesh (vertices in fetch order)
  double encode_ms = 0;          ///< one encode (quantize, optimize, encode), milliseconds
  /// Best decode (both streams and dequantization to float xyz; the copy into a TriMesh is not timed), ms.
  double decode_ms = 0;
};

/// Encodes `mesh` with meshoptimizer's codec as described at the top of this file, decodes it and times the
/// decode. Faces with a repeated corner are kept as they are; unreferenced vertices are dropped.
///
/// \param mesh #V×3 positions, #F triangles.
/// \pre at least one triangle, indices in range, finite coordinates, 1 ≤ quantization_bits ≤ 16.
/// \throw InvalidInput naming `meshopt_encode` when a precondition fails; SolverFailure when meshoptimizer
///        rejects its own stream.
MeshoptCodecResult meshopt_encode(const TriMesh& mesh, const MeshoptCodecOptions& options = {});

}  // namespace geomip
