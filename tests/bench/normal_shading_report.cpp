// codec_bench --normals-shading MESH.obj: the shading error of decoded normal maps — the angle between the
// normal a renderer samples from a decoded map (bilinear between its texels, renormalized) and the surface's
// own normal at that point — for normal-map levels and quantizations (docs/codec-v3.md, "Normal maps:
// shading error"). MESH goes through `geomip convert`'s pipeline once with normal maps at level 10 (1025² per
// patch); they are the reference: the surface normal at every level-10 texel. A map of level L < 10 is that
// reference at every 2^(10−L)-th texel (the same points the pipeline samples at level L), coded with the
// packs' normal codec (xyz, B bits), decoded in full or from a byte budget of its stream, and compared at
// every level-10 texel not in a filled hole. Printed per (L, B): the stream bytes and the mean / p95 angle
// of the full decode, then at stream budgets; and the uncoded level-L map's own error (interpolation only).
//
// codec_bench --normals-shading MESH.obj --patches K --level N: the same on the automatic K-patch layout with
// level-N geometry (what `geomip convert` moves a stretched shape to: 16 patches, level 7), maps of levels
// N + 1 (convert's default) and N, the reference at level min(N + 3, 10).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "codec/pack.h"
#include "tools/convert_pipeline.h"
#include "tools/model_inputs.h"
#include "tests/bench/normal_codings.h"

namespace {

using namespace geomip::codec;
using geomip::bench::decode_budget;
using geomip::bench::stream_bytes;

constexpr int kReferenceLevel = 10;

/// Every 2^(ref.level − level)-th texel of `ref`.
Grid3 subsample(const Grid3& ref, int level) {
  Grid3 g;
  g.level = level;
  const int n = g.size(), stride = 1 << (ref.level - level), rn = ref.size();
  g.values.resize(3 * static_cast<std::size_t>(n) * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        g.values[3 * (static_cast<std::size_t>(j) * n + i) + c] =
            ref.values[3 * (static_cast<std::size_t>(j * stride) * rn + i * stride) + c];
  return g;
}

/// Mean and 95th percentile of the angle (degrees) between `map` sampled bilinearly at the reference's
/// texels (renormalized) and the reference, over texels whose hole-mask quad is not masked.
void shading_error(const PackModelInput& in, const std::vector<Grid3>& reference, const std::vector<Grid3>& maps,
                   double& mean, double& p95) {
  std::vector<double> all;
  const int mask_level = in.hole_mask_level < 0 ? in.geometry[0].level : in.hole_mask_level;
  for (std::size_t p = 0; p < reference.size(); ++p) {
    const Grid3& ref = reference[p];
    const Grid3& map = maps[p];
    const int rn = ref.size(), n = map.size(), shift = ref.level - map.level, mshift = ref.level - mask_level;
    const double scale = 1.0 / (1 << shift);
    for (int j = 0; j < rn; ++j)
      for (int i = 0; i < rn; ++i) {
        if (!in.hole_mask.empty()) {
          const int qi = std::min(i, rn - 2) >> mshift, qj = std::min(j, rn - 2) >> mshift;
          if (in.hole_mask[p][static_cast<std::size_t>(qj) * (1u << mask_level) + qi]) continue;
        }
        const double x = i * scale, y = j * scale;
        const int i0 = std::min(static_cast<int>(x), n - 2), j0 = std::min(static_cast<int>(y), n - 2);
        const double fx = x - i0, fy = y - j0;
        double v[3] = {0, 0, 0};
        for (int c = 0; c < 3; ++c) {
          const auto at = [&](int a, int b) { return map.values[3 * (static_cast<std::size_t>(b) * n + a) + c]; };
          v[c] = (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i0 + 1, j0)) +
                 fy * ((1 - fx) * at(i0, j0 + 1) + fx * at(i0 + 1, j0 + 1));
        }
        const float* r = ref.values.data() + 3 * (static_cast<std::size_t>(j) * rn + i);
        const double cr[3] = {r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0]};
        const double sin = std::sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        all.push_back(std::atan2(sin, r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) * 180.0 / M_PI);
      }
  }
  mean = 0;
  for (double a : all) mean += a;
  mean /= static_cast<double>(std::max<std::size_t>(all.size(), 1));
  std::sort(all.begin(), all.end());
  p95 = all.empty() ? 0 : all[all.size() * 95 / 100];
}

}  // namespace

int normals_shading_report(int argc, char** argv) {
  int patches = 2, level = 8;
  for (int a = 3; a + 1 < argc; a += 2) {
    if (std::strcmp(argv[a], "--patches") == 0)
      patches = std::atoi(argv[a + 1]);
    else if (std::strcmp(argv[a], "--level") == 0)
      level = std::atoi(argv[a + 1]);
    else {
      std::fprintf(stderr, "codec_bench --normals-shading MESH [--patches K --level N]\n");
      return 2;
    }
  }
  if (patches < 2 || level < 2 || level + 2 > kReferenceLevel) {
    std::fprintf(stderr, "codec_bench --normals-shading: --patches K >= 2, --level N in [2, %d]\n",
                 kReferenceLevel - 2);
    return 2;
  }
  const int reference_level = std::min(level + 3, kReferenceLevel);
  const geomip::tools::PreparedModels models =
      geomip::tools::prepare_models({argv[2]}, "", "codec_bench", true, patches);
  geomip::tools::ConvertOptions options;
  options.keep_inputs = true;
  options.level = level;
  options.normal_level = reference_level;
  const PackModelInput in = geomip::tools::convert_models(models, options).inputs.at(0);
  const std::vector<Grid3>& reference = in.normals;
  std::printf(
      "%s, %d patches, geometry level %d: shading error against the level-%d normal maps (mean° / p95°)\n",
      argv[2], patches, level, reference_level);
  std::printf("  %-5s %-4s %9s   %-17s %s\n", "level", "bits", "bytes", "full decode",
              "stream budgets 10K 20K 40K 80K 160K 320K 640K");
  for (int map_level : {level + 1, level}) {
    std::vector<Grid3> maps;
    for (const Grid3& g : reference) maps.push_back(subsample(g, map_level));
    double mean = 0, p95 = 0;
    shading_error(in, reference, maps, mean, p95);
    std::printf("  %-5d %-4s %9s   %6.3f / %6.3f   (uncoded)\n", map_level, "-", "-", mean, p95);
    for (int bits : {10, 9, 8, 7, 6}) {
      GeometryCodecOptions codec = PackWriteOptions{}.normal_codec;
      codec.quantization_bits = bits;
      const EncodedGeometry e = encode_geometry(maps, in.seams, codec);
      const std::size_t total = stream_bytes(e);
      std::printf("  %-5d %-4d %9zu  ", map_level, bits, total);
      for (std::size_t budget :
           {std::size_t{0}, std::size_t{10000}, std::size_t{20000}, std::size_t{40000}, std::size_t{80000},
            std::size_t{160000}, std::size_t{320000}, std::size_t{640000}}) {
        if (budget >= total) break;
        std::vector<Grid3> decoded = decode_budget(e, budget == 0 ? total : budget);
        for (Grid3& g : decoded)
          for (std::size_t k = 0; k + 2 < g.values.size(); k += 3) {
            float* v = g.values.data() + k;
            const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (len > 0) v[0] /= len, v[1] /= len, v[2] /= len;
          }
        shading_error(in, reference, decoded, mean, p95);
        std::printf(" %6.3f / %6.3f%s", mean, p95, budget == 0 ? "  |" : "");
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
