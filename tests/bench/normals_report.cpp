// codec_bench --normals MESH.obj [--bits B,...] [--headroom H] [--normal-mesh K] [--base BYTES]: the angular
// error of decoded normal maps (docs/codec-v3.md, "Normal maps: two-channel codings"). MESH goes through
// `geomip convert`'s pipeline once (default options: level 8, normal maps at level 9, hole masks;
// --normal-mesh as convert's); its uncompressed normal maps are the reference. Errors are the mean / 95th
// percentile / max angle in degrees between decoded and reference normals over all texels not in a filled
// hole (a texel counts as the quad it is the lower-left corner of; the last row and column use the quad
// before). Printed:
//   - the error of the fully decoded geometry's own normals (no normal map at all);
//   - the normal stream alone (model 0), per quantization (--bits, default 10), at normal-byte budgets
//     (complete segments plus a prefix of the next): xyz (the packs' coding, headroom included), xyz without
//     headroom and with headroom H (--headroom, default 2), octahedral in one global frame,
//     the residual against the fully decoded geometry, and two layers: the first BYTES of the xyz stream
//     (--base, default 20000) as the frames' normal, then the residual in those frames (normal_codings.h);
//   - today's pack (write_pack() defaults): the full pack and file prefixes of it, with the normal-chunk
//     bytes they hold; where no normal chunk has arrived, the decoded geometry's normals (what a viewer
//     shades with then).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "codec/pack.h"
#include "tools/convert_pipeline.h"
#include "tools/model_inputs.h"
#include "tests/bench/normal_codings.h"

namespace {

using namespace geomip::codec;
using geomip::bench::apply_normal_residual;
using geomip::bench::decode_budget;
using geomip::bench::normal_frames_along_grid;
using geomip::bench::normal_residual;
using geomip::bench::stream_bytes;

struct AngleStats {
  double mean = 0, p95 = 0, max = 0;
};

/// The decoded geometry's own normals (a zero residual), oriented as the encoder would choose.
std::vector<Grid3> geometry_normals(const PackModelInput& in, const std::vector<Grid3>& geometry) {
  std::vector<Grid3> normals(in.normals.size());
  for (std::size_t p = 0; p < normals.size(); ++p) {
    normals[p].level = in.normals[p].level;
    normals[p].values.assign(in.normals[p].values.size(), 0.f);
  }
  apply_normal_residual(normals, geometry, normal_frames_along_grid(in.normals, geometry));
  return normals;
}

/// Angles (degrees) between `normals` and the reference normal maps of `in`, hole-masked texels left out.
void collect_angles(const PackModelInput& in, const std::vector<Grid3>& normals, std::vector<double>& all) {
  const int mask_level = in.hole_mask_level < 0 ? in.geometry[0].level : in.hole_mask_level;
  for (std::size_t p = 0; p < in.normals.size(); ++p) {
    const Grid3& ref = in.normals[p];
    const int n = ref.size(), shift = ref.level - mask_level;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (!in.hole_mask.empty() && shift >= 0) {
          const int qi = std::min(i, n - 2) >> shift, qj = std::min(j, n - 2) >> shift;
          if (in.hole_mask[p][static_cast<std::size_t>(qj) * (1u << mask_level) + qi]) continue;
        }
        const std::size_t k = 3 * (static_cast<std::size_t>(j) * n + i);
        const double a[3] = {ref.values[k], ref.values[k + 1], ref.values[k + 2]};
        const double b[3] = {normals[p].values[k], normals[p].values[k + 1], normals[p].values[k + 2]};
        const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        const double sin = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        all.push_back(std::atan2(sin, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * 180.0 / M_PI);
      }
  }
}

AngleStats stats(std::vector<double> all) {
  AngleStats s;
  if (all.empty()) return s;
  for (double v : all) s.mean += v;
  s.mean /= static_cast<double>(all.size());
  std::sort(all.begin(), all.end());
  s.p95 = all[all.size() * 95 / 100];
  s.max = all.back();
  return s;
}

AngleStats angles(const std::vector<PackModelInput>& reference, const std::vector<DecodedModel>& decoded) {
  std::vector<double> all;
  for (std::size_t m = 0; m < reference.size(); ++m)
    collect_angles(reference[m], decoded[m].normals.empty()
                                     ? geometry_normals(reference[m], decoded[m].geometry)
                                     : decoded[m].normals, all);
  return stats(std::move(all));
}

/// Bytes of normal chunks that lie (wholly or partly) within the first `bytes` bytes.
std::size_t normal_bytes(const PackInfo& info, std::size_t bytes) {
  std::size_t sum = 0;
  for (const ChunkInfo& c : info.chunks)
    if (c.kind == ChunkKind::kNormals && c.offset < bytes)
      sum += static_cast<std::size_t>(std::min<std::uint64_t>(c.size, bytes - c.offset));
  return sum;
}

void row(const char* what, std::size_t size, const PackInfo& info, const std::vector<PackModelInput>& in,
         const std::vector<std::uint8_t>& pack) {
  const PackDecodeResult r = decode_pack(pack, {.max_bytes = size});
  const AngleStats s = angles(in, r.models);
  std::printf("  %-14s %9zu %9zu   %7.3f %7.3f %7.2f\n", what, std::min(size, pack.size()),
              normal_bytes(info, size), s.mean, s.p95, s.max);
}

void normalize_grid(Grid3& g) {
  for (std::size_t k = 0; k < g.values.size(); k += 3) {
    float* n = g.values.data() + k;
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0) n[0] /= len, n[1] /= len, n[2] /= len;
  }
}

/// The normal stream alone (model 0), five codings at normal-byte budgets: xyz (the packs' coding: 3
/// channels, seams shared), xyz with the geometry's longer filter kCubicLong, octahedral in one global frame (2 channels; a flat grid's frames are the xyz
/// axes), the residual against the fully decoded geometry, and two layers — the first `base_bytes` of the
/// xyz stream, then the residual against their normals (bytes: both layers; normal_codings.h).
void stream_report(const PackModelInput& in, int bits, std::size_t base_bytes, int headroom) {
  const GeometryCodecOptions codec = PackWriteOptions{}.normal_codec;
  GeometryCodecOptions options = codec;
  options.quantization_bits = bits;
  const EncodedGeometry geometry = encode_geometry(in.geometry, in.seams, PackWriteOptions{}.geometry);
  const std::vector<Grid3> decoded_geometry = decode_budget(geometry, stream_bytes(geometry));
  std::vector<Grid3> flat = in.geometry;
  for (Grid3& g : flat)
    for (int j = 0; j < g.size(); ++j)
      for (int i = 0; i < g.size(); ++i) {
        float* v = g.values.data() + 3 * (static_cast<std::size_t>(j) * g.size() + i);
        v[0] = static_cast<float>(i), v[1] = static_cast<float>(j), v[2] = 0;
      }
  const geomip::bench::Orientation along = normal_frames_along_grid(in.normals, decoded_geometry);
  struct Variant {
    const char* name;
    EncodedGeometry encoded;
    const std::vector<Grid3>* frames;  // null: xyz
    geomip::bench::Orientation along;
    const std::vector<Grid3>* axes = nullptr;  // two layers: the base layer's normals
    std::size_t base_bytes = 0;                // bytes of the base layer (counted in the budgets)
  };
  // Two layers: the xyz stream's first base_bytes (today's options) as the frames' normal, the residual in
  // those frames.
  const EncodedGeometry base = encode_geometry(in.normals, in.seams, codec);
  std::vector<Grid3> axes = decode_budget(base, base_bytes);
  for (Grid3& g : axes) normalize_grid(g);
  GeometryCodecOptions long_filter = options;  // the geometry's 6-point / 4-tap filter (pack format 6)
  long_filter.filter = WaveletFilter::kCubicLong;
  GeometryCodecOptions headroom0 = options, other = options;  // other headrooms (pack format 10)
  headroom0.headroom_bits = 0;
  other.headroom_bits = headroom;
  char other_name[32];
  std::snprintf(other_name, sizeof other_name, "xyz head %d", headroom);
  const Variant variants[] = {
      {"xyz", encode_geometry(in.normals, in.seams, options), nullptr, {}},
      {"xyz+long", encode_geometry(in.normals, in.seams, long_filter), nullptr, {}},
      {"xyz head 0", encode_geometry(in.normals, in.seams, headroom0), nullptr, {}},
      {other_name, encode_geometry(in.normals, in.seams, other), nullptr, {}},
      {"octahedral", encode_geometry(normal_residual(in.normals, flat, {}), {}, options), &flat, {}},
      {"residual", encode_geometry(normal_residual(in.normals, decoded_geometry, along), {}, options),
       &decoded_geometry, along},
      {"two-layer", encode_geometry(normal_residual(in.normals, decoded_geometry, along, &axes), {}, options),
       &decoded_geometry, along, &axes, base_bytes},
  };
  std::printf("normal stream alone, %d bits (model %s)\n  %-12s %9s   %7s %7s %7s\n", bits, in.name.c_str(),
              "coding", "bytes", "mean°", "p95°", "max°");
  for (const Variant& v : variants) {
    const std::size_t total = v.base_bytes + stream_bytes(v.encoded);
    for (std::size_t budget :
         {10000, 20000, 40000, 80000, 160000, 320000, 400000, 450000, 500000, 550000, 575000, 600000, 0}) {
      if (budget >= total || (budget != 0 && budget <= v.base_bytes)) continue;
      const std::size_t b = budget == 0 ? total : budget;
      std::vector<Grid3> normals = decode_budget(v.encoded, b - v.base_bytes);
      if (v.frames) {
        apply_normal_residual(normals, *v.frames, v.along, v.axes);
      } else {
        for (Grid3& g : normals) normalize_grid(g);
      }
      std::vector<double> all;
      collect_angles(in, normals, all);
      const AngleStats st = stats(std::move(all));
      std::printf("  %-12s %9zu   %7.3f %7.3f %7.2f\n", v.name, b, st.mean, st.p95, st.max);
    }
  }
}

/// "a,b,c" → {a, b, c} (numbers as atof reads them).
template <typename T>
std::vector<T> comma_list(const char* text) {
  std::vector<T> out;
  for (const char* p = text; *p;) {
    out.push_back(static_cast<T>(std::atof(p)));
    while (*p && *p != ',') ++p;
    if (*p == ',') ++p;
  }
  return out;
}

}  // namespace

int normals_report(int argc, char** argv) {
  std::vector<int> bits_list = {10};
  int normal_mesh_steps = geomip::tools::ConvertOptions{}.normal_mesh_steps;
  std::size_t base_bytes = 20000;
  int headroom = 2;
  bool streams = true;
  std::vector<int> pack_layers = {1, 2};
  std::vector<double> residual_steps = {PackWriteOptions{}.normal_residual_step};
  for (int i = 3; i < argc; ++i)
    if (std::strcmp(argv[i], "--packs-only") == 0) streams = false;
  for (int i = 3; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--residual-step") == 0) residual_steps = comma_list<double>(argv[i + 1]);
    if (std::strcmp(argv[i], "--normal-mesh") == 0) normal_mesh_steps = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--base") == 0) base_bytes = static_cast<std::size_t>(std::atol(argv[i + 1]));
    if (std::strcmp(argv[i], "--headroom") == 0) headroom = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--bits") == 0) bits_list = comma_list<int>(argv[i + 1]);
  }
  const geomip::tools::PreparedModels models = geomip::tools::prepare_models({argv[2]}, "", "codec_bench", true);
  geomip::tools::ConvertOptions options;
  options.keep_inputs = true;
  options.normal_mesh_steps = normal_mesh_steps;
  const std::vector<PackModelInput> in = geomip::tools::convert_models(models, options).inputs;
  std::printf("%s: normal maps at level %d, geometry at level %d\n", argv[2], in[0].normals[0].level,
              in[0].geometry[0].level);
  {
    std::vector<double> all;
    const EncodedGeometry g = encode_geometry(in[0].geometry, in[0].seams, PackWriteOptions{}.geometry);
    collect_angles(in[0], geometry_normals(in[0], decode_budget(g, stream_bytes(g))), all);
    const AngleStats st = stats(std::move(all));
    std::printf("the fully decoded geometry's own normals: mean %.3f°, p95 %.3f°, max %.2f°\n", st.mean, st.p95,
                st.max);
  }
  if (streams)
    for (int bits : bits_list) stream_report(in[0], bits, base_bytes, headroom);
  std::printf("today's pack (xyz normal maps, %d bits), all models\n  %-14s %9s %9s   %7s %7s %7s\n",
              PackWriteOptions{}.normal_codec.quantization_bits, "decode", "bytes", "normal B", "mean°", "p95°",
              "max°");
  for (std::size_t si = 0; si < residual_steps.size(); ++si) {
    const double step = residual_steps[si];
    for (int layers : pack_layers) {
      if (layers == 1 && si > 0) continue;  // the residual step does not apply
      PackWriteOptions pw;
      pw.normal_layers = layers;
      pw.normal_residual_step = step;
      const std::vector<std::uint8_t> pack = write_pack(in, pw);
      PackInfo info;
      read_pack_info(pack, info);
      std::printf("normal layers %d%s\n", info.models[0].normal_layers,
                  layers == 2 ? (" (layer 2 step x" + std::to_string(step) + ")").c_str() : "");
      row("full", pack.size(), info, in, pack);
      for (std::size_t prefix : {25000, 50000, 100000, 200000, 300000, 400000, 500000, 600000}) {
        char label[32];
        std::snprintf(label, sizeof label, "prefix %zuK", prefix / 1000);
        if (prefix < pack.size()) row(label, prefix, info, in, pack);
      }
    }
  }
  return 0;
}
