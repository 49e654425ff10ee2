// Google Draco as a rate–distortion baseline: encode an indexed triangle mesh (positions and faces only) with
// libdraco in-process, decode it back, and time the decode.
//
// Draco (https://github.com/google/draco, Debian libdraco-dev 1.5.5) quantizes each position coordinate to
// `quantization_bits` bits over the largest extent of the mesh's bounding box (one uniform grid for all three
// axes: step = extent / (2^Q − 1), so every decoded coordinate lies within step/2 of the original), predicts
// positions by parallelogram prediction along the Edgebreaker traversal (Rossignac 1999) and entropy-codes
// the residuals. The compression level follows `draco_encoder -cl`: level L sets encoding and decoding speed
// 10 − L, so level 10 (the default here) is Draco's slowest, smallest setting.
//
// This file is a baseline, not part of the geomip codec: it links Draco (the `geomip_baselines` target only).
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

struct DracoOptions {
  /// Position quantization bits Q (draco_encoder -qp), 1..30; 11 is Draco's default, 14 its "high".
  int quantization_bits = 11;
  /// Compression level 0..10 (draco_encoder -cl); speed = 10 − level for both encoder and decoder.
  int compression_level = 10;
  /// Decode runs timed; the reported decode time is the fastest (best of `decode_runs`, at least 1).
  int decode_runs = 5;
};

struct DracoResult {
  std::vector<std::uint8_t> bytes;  ///< the Draco bitstream (what a .drc file holds)
  TriMesh decoded;                  ///< the mesh decoded from `bytes` (Draco reorders vertices and faces)
  double encode_ms = 0;             ///< wall time of one encode, milliseconds
  /// Best wall time of `decode_runs` decodes (bitstream → draco::Mesh, Draco's own output; the copy into a
  /// TriMesh is not timed), milliseconds.
  double decode_ms = 0;
};

/// Encodes `mesh` (positions and triangles; no other attributes) with Draco's Edgebreaker mesh encoder,
/// decodes the bitstream in-process and times the decode.
///
/// Unreferenced vertices are dropped by Draco; faces are kept (a face with a repeated corner is dropped by
/// Draco's connectivity coder, so `decoded` may have fewer triangles only when `mesh` has such faces).
///
/// \param mesh #V×3 positions (any units), #F triangles, 0-based indices.
/// \pre at least one triangle, indices in range, finite coordinates within float range whose bounding box's
///      extent along each axis is finite as a float (check_draco_positions()), 1 ≤ quantization_bits ≤ 30,
///      0 ≤ compression_level ≤ 10.
/// \throw InvalidInput naming `draco_encode` for a precondition failure, SolverFailure when Draco fails to
///        encode or to decode its own stream.
DracoResult draco_encode(const TriMesh& mesh, const DracoOptions& options = {});

/// Decodes a Draco mesh bitstream into positions and triangles. Never throws on bad bytes: returns false
/// (and leaves `out` empty) for a stream Draco rejects or one that holds no mesh with positions.
bool draco_decode(const std::uint8_t* data, std::size_t size, TriMesh& out);

}  // namespace geomip
