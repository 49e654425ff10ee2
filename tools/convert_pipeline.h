// The convert pipeline shared by `geomip convert` and `geomip rd`: prepared (repaired) models → consistent
// parameterization → geometry images (+ normal maps, + hole masks of repaired meshes) → a .gip pack in memory.
#pragma once

#include "codec/pack.h"
#include "mesh/mesh.h"
#include "tools/model_inputs.h"

#include <cstdint>
#include <vector>

namespace geomip::tools {

struct ConvertOptions {
  int level = 8;              ///< geometry image level N: (2^N+1)² samples per patch
  int normal_level = -1;      ///< normal map level (-1: N+1, at most 10)
  bool normals = true;        ///< false: geometry-only pack
  int quantization_bits = 14; ///< position quantization over the largest bounding-box extent
  /// Level of the hole-mask grid (repaired meshes); -1 = the geometry's level.
  int hole_mask_level = -1;
  /// Curvature sampling exponent of the parameterization (SamplingWeightOptions::exponent; 0 = off, the
  /// default here because it costs the codec at low rates; the remeshing commands default to 1/3; README,
  /// "Curvature sampling").
  double sampling_exponent = 0;
  ProgressCallback progress;  ///< stages "parameterize …", "resample", "encode"
};

struct ConvertResult {
  std::vector<std::uint8_t> pack;
  std::vector<std::size_t> masked_quads;  ///< per model: grid quads left out as filled holes
  double param_seconds = 0, resample_seconds = 0, encode_seconds = 0;
};

/// \throw InvalidInput / SolverFailure from the parameterization; std::invalid_argument never escapes (the
/// images come from resample_geometry()).
ConvertResult convert_models(const PreparedModels& models, const ConvertOptions& options);

}  // namespace geomip::tools
