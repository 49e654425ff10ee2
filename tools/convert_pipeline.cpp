#include "tools/convert_pipeline.h"

#include "gimage/hole_mask.h"
#include "gimage/resample.h"
#include "param/consistent_parameterization.h"
#include "tools/pack_models.h"

#include <algorithm>
#include <chrono>

namespace geomip::tools {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

ConvertResult convert_models(const PreparedModels& models, const ConvertOptions& options) {
  auto progress = [&](const char* stage, double fraction) {
    if (options.progress) options.progress(stage, fraction);
  };
  ConvertResult result;
  ParameterizationOptions param;
  param.measure_mvc_baseline = false;
  param.curvature_sampling = options.sampling_exponent > 0;
  param.sampling_weights.exponent = options.sampling_exponent;
  param.progress = [&](const char* stage, double fraction) { progress(stage, 0.8 * fraction); };
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> params = parameterize_consistently(models.inputs, param);
  result.param_seconds = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  std::vector<codec::PackModelInput> inputs;
  const int mask_level = options.hole_mask_level < 0 ? options.level : std::min(options.hole_mask_level, options.level);
  for (std::size_t m = 0; m < params.size(); ++m) {
    progress("resample", 0.8 + 0.1 * static_cast<double>(m) / static_cast<double>(params.size()));
    ResampleOptions resample;
    resample.normals = options.normals;
    resample.normal_level = options.normal_level;
    const GeometryImages images = resample_geometry(params[m], options.level, resample);
    HoleMaskResult mask;
    if (m < models.originals.size() && !models.originals[m].triangles.empty())
      mask = hole_mask(params[m], models.originals[m], mask_level);
    result.masked_quads.push_back(mask.masked_quads);
    inputs.push_back(pack_model_input(models.inputs[m].name, images, &mask, options.normals));
    inputs.back().hole_mask_level = mask_level;
  }
  result.resample_seconds = seconds_since(t0);

  progress("encode", 0.9);
  t0 = std::chrono::steady_clock::now();
  codec::PackWriteOptions write;
  write.normals = options.normals;
  write.geometry.quantization_bits = options.quantization_bits;
  result.pack = codec::write_pack(inputs, write);
  result.encode_seconds = seconds_since(t0);
  progress("encode", 1.0);
  return result;
}

}  // namespace geomip::tools
