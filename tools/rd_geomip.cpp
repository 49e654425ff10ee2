#include "tools/rd_geomip.h"

#include "gimage/surface_distance.h"
#include "param/errors.h"
#include "tools/pack_models.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace geomip::tools {

std::vector<PrefixRdPoint> prefix_rate_distortion(const std::vector<std::uint8_t>& pack, const TriMesh& original,
                                                  const PrefixRdOptions& options) {
  codec::PackInfo info;
  if (codec::read_pack_info(pack, info) != codec::Status::kOk || info.file_size() > pack.size())
    throw InvalidInput("prefix_rate_distortion: the pack does not decode");
  std::vector<std::size_t> sizes = options.sizes;
  if (sizes.empty()) {
    const double lo = static_cast<double>(info.manifest_end + 64), hi = static_cast<double>(pack.size());
    const int count = 24;
    for (int k = 0; k < count; ++k)
      sizes.push_back(static_cast<std::size_t>(std::round(lo * std::pow(hi / lo, k / double(count - 1)))));
  }
  std::vector<PrefixRdPoint> points;
  for (std::size_t size : sizes) {
    if (size < info.manifest_end) continue;
    size = std::min(size, pack.size());
    codec::PackDecodeOptions decode;
    decode.max_bytes = size;
    decode.normals = false;
    codec::PackDecodeResult result;
    double best_ms = INFINITY;
    for (int r = 0; r < std::max(1, options.decode_repeats); ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      result = codec::decode_pack(pack, decode);
      best_ms = std::min(best_ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    if (result.models.empty()) continue;
    const TriMesh mesh = decoded_mesh(result.models.front(), options.output_level);
    const SurfaceDistance d = measure_surface_distance(original, mesh);
    PrefixRdPoint p;
    p.bytes = size;
    p.psnr_db = d.psnr_db;
    p.hausdorff_pct = d.hausdorff_pct;
    p.rms_pct = d.rms_pct;
    p.decode_ms = best_ms;
    p.detail_level = result.models.front().detail_level;
    p.faces = mesh.num_triangles();
    points.push_back(p);
  }
  return points;
}

}  // namespace geomip::tools
