// Codec benchmarks (Google Benchmark): encode and full decode of a synthetic two-patch level-8 model.
//
// Pack decode times (the benchmark: a whole level-8 bunny pack, in-process):
//   codec_bench --pack FILE.gip     (CODEC_DECODE_REPS = repetitions, best taken; default 20)
//
// Streaming and Draco (issue #16's figures, all ratios from one run):
//   codec_bench --stream FILE.gip [MESH.obj]     (CODEC_DECODE_REPS as above; default 10)
// prints the full one-shot decode time; the time to decode the pack as 64 equal byte increments with the
// incremental decoder (PackDecoder), (a) with the models reconstructed after every increment, as a viewer
// that shows each one does, (b) reconstructed once at the end, and (c) the old way, a one-shot decode of
// every prefix; each as a ratio to the full decode. With MESH (the mesh the pack was made from), also
// Draco's in-process decode of that full mesh (14-bit positions, compression level 10, best of the same
// repetitions) and geomip's full decode as a ratio to it.
//
// Angular error of decoded normal maps: the packs' xyz coding against two-channel codings (normal-byte
// budgets), and today's pack at file prefixes (normals_report.cpp):
//   codec_bench --normals MESH.obj [--bits B,...] [--headroom H] [--normal-mesh K] [--base BYTES]
//
// For instruction counts (valgrind --tool=callgrind, repeatable on a shared machine), one decode on one
// thread:
//   codec_bench --decode-once FILE.gip full|increments|shown
// (full: decode_pack; increments: 64 PackDecoder updates, models at the end; shown: models after each).
// Draco's side of the same count: the mesh encoded as in --stream (14 bits, level 10), then decoded once by
// geomip::draco_decode (bitstream → geomip mesh); count only that call:
//   valgrind --tool=callgrind --toggle-collect='geomip::draco_decode*'  (one command, continued:)
//     codec_bench --draco-decode-once MESH.obj
//
// Rate–distortion report instead of benchmarks:
//   codec_bench --rd FILE.geometry.exr|synthetic [--filter linear|cubic|both] [--steps N] [--bits B] [--mesh
//   M | --surface on] [--frames K] [--tshift T] [--orient 0|1]
// reads a geometry image written by `geomip gimage`, encodes it and prints, for byte budgets (prefixes of the
// concatenated segments), the grid RMS error (per-sample Euclidean distance) and the grid PSNR
// 20·log10(bbox diagonal / RMS), plus the full decode time; with --mesh, also the surface PSNR (Metro-style
// symmetric RMS distance to mesh M, gimage/surface_distance.h) of the decoded grids; with --surface on, the
// same against the uncompressed grids (the codec's own error, tangential displacement not counted).
// CODEC_BUDGETS=2000,4700,... in the environment measures only those byte budgets. CODEC_DUMP=PATH in the
// environment also writes the encoded stream (u32 header size, header, u32 segment count, then u32 size +
// bytes per segment; little-endian) for decoder experiments outside this program.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "baselines/draco_baseline.h"
#include "codec/geometry_codec.h"
#include "codec/pack.h"
#include "gimage/exr_io.h"
#include "gimage/surface_distance.h"
#include "mesh/mesh_io.h"
#include "tests/codec/codec_fixtures.h"

namespace {

using namespace geomip::codec;

struct Model {
  std::vector<Grid3> patches;
  std::vector<PatchSeam> seams;
};

const Model& synthetic_model() {
  static const Model model = [] {
    Model m;
    m.patches = testing::two_patch_surface(8, m.seams);
    return m;
  }();
  return model;
}

void BM_EncodeLevel8TwoPatches(benchmark::State& state) {
  const Model& m = synthetic_model();
  std::size_t bytes = 0;
  for (auto _ : state) {
    auto enc = encode_geometry(m.patches, m.seams);
    bytes = 0;
    for (const auto& s : enc.segments) bytes += s.size();
    benchmark::DoNotOptimize(enc);
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodeLevel8TwoPatches)->Unit(benchmark::kMillisecond);

void BM_DecodeLevel8TwoPatches(benchmark::State& state) {
  const Model& m = synthetic_model();
  const auto enc = encode_geometry(m.patches, m.seams);
  std::vector<std::span<const std::uint8_t>> segs(enc.segments.begin(), enc.segments.end());
  for (auto _ : state) {
    DecodedGeometry dec;
    decode_geometry(enc.header, segs, {}, dec);
    benchmark::DoNotOptimize(dec);
  }
}
BENCHMARK(BM_DecodeLevel8TwoPatches)->Unit(benchmark::kMillisecond);

Model load_exr(const std::string& path) {
  const auto file = geomip::read_geometry_image_exr(path);
  const auto grids = geomip::finest_grids(file);
  Model m;
  for (const auto& g : grids) m.patches.push_back({g.level, g.values});
  for (const auto& l : file.info.adjacency) {
    m.seams.push_back({l.patch, l.side, l.other_patch, l.other_side, l.reversed});
  }
  return m;
}

struct Quality {
  double rms, psnr;
};

Quality measure(const Model& m, const std::vector<Grid3>& dec) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  double e = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    const auto& a = m.patches[p].values;
    for (std::size_t i = 0; i < a.size(); i += 3, ++n) {
      double d2 = 0;
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], static_cast<double>(a[i + c]));
        hi[c] = std::max(hi[c], static_cast<double>(a[i + c]));
        const double d = static_cast<double>(a[i + c]) - dec[p].values[i + c];
        d2 += d * d;
      }
      e += d2;
    }
  }
  const double rms = std::sqrt(e / static_cast<double>(n));
  const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  return {rms, 20 * std::log10(diag / rms)};
}

/// The decoded grids as one triangle mesh (seam vertices duplicated; distances do not care).
geomip::TriMesh grid_mesh(const std::vector<Grid3>& patches) {
  geomip::TriMesh mesh;
  for (const auto& g : patches) {
    const int n = g.size(), base = static_cast<int>(mesh.positions.size());
    for (std::size_t i = 0; i < g.values.size(); i += 3) {
      mesh.positions.emplace_back(g.values[i], g.values[i + 1], g.values[i + 2]);
    }
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const int a = base + j * n + i, b = a + 1, c = a + n + 1, d = a + n;
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      }
    }
  }
  return mesh;
}

const geomip::TriMesh* g_reference = nullptr;  // --mesh: surface PSNR against this mesh
GeometryCodecOptions g_v3;  // --frames K --tshift T --orient 0|1: the version-3 tools (defaults: the codec's)

double surface_psnr(const std::vector<Grid3>& patches) {
  geomip::SurfaceDistanceOptions o;
  o.face_samples = 100000;
  return geomip::measure_surface_distance(*g_reference, grid_mesh(patches), o).psnr_db;
}

int rd_report(const Model& m, const std::string& filters, int steps, int bits) {
  std::vector<WaveletFilter> list;
  if (filters != "cubic") list.push_back(WaveletFilter::kLinear);
  if (filters != "linear") list.push_back(WaveletFilter::kCubic);
  for (auto filter : list) {
    GeometryCodecOptions o = g_v3;
    o.filter = filter;
    o.steps = steps;
    o.quantization_bits = bits;
    const auto t0 = std::chrono::steady_clock::now();
    const auto enc = encode_geometry(m.patches, m.seams, o);
    const auto t1 = std::chrono::steady_clock::now();
    std::size_t total = 0;
    for (const auto& s : enc.segments) total += s.size();
    if (const char* dump = std::getenv("CODEC_DUMP")) {
      FILE* f = std::fopen(dump, "wb");
      const auto hb = enc.header.serialize();
      const std::uint32_t hn = static_cast<std::uint32_t>(hb.size()),
                          ns = static_cast<std::uint32_t>(enc.segments.size());
      std::fwrite(&hn, 4, 1, f);
      std::fwrite(hb.data(), 1, hn, f);
      std::fwrite(&ns, 4, 1, f);
      for (const auto& s : enc.segments) {
        const std::uint32_t n = static_cast<std::uint32_t>(s.size());
        std::fwrite(&n, 4, 1, f);
        std::fwrite(s.data(), 1, n, f);
      }
      std::fclose(f);
    }
    std::printf(
        "filter %s: level %d, %zu patches, %zu segments, %zu bytes total, header %zu bytes, encode %.1f ms\n",
        filter == WaveletFilter::kCubic ? "cubic" : "linear", enc.header.level, m.patches.size(),
        enc.segments.size(), total, enc.header.serialize().size(),
        std::chrono::duration<double, std::milli>(t1 - t0).count());
    std::vector<std::size_t> budgets = {256,   512,   1024,  2000,  2048,  4096,   4700,   8192, 8800,
                                        16000, 16384, 32000, 32768, 65536, 131072, 262144, total};
    if (const char* only = std::getenv("CODEC_BUDGETS")) {  // e.g. "2000,4700,8800": only these
      budgets.clear();
      for (const char* c = only; *c;) {
        char* end;
        budgets.push_back(std::strtoull(c, &end, 10));
        c = *end ? end + 1 : end;
      }
    }
    for (std::size_t budget : budgets) {
      if (budget > total) continue;
      std::size_t left = budget, k = 0;
      while (k < enc.segments.size() && enc.segments[k].size() <= left) left -= enc.segments[k++].size();
      std::vector<std::span<const std::uint8_t>> segs(enc.segments.begin(), enc.segments.begin() + k);
      std::span<const std::uint8_t> tail;
      if (k < enc.segments.size()) tail = std::span<const std::uint8_t>(enc.segments[k].data(), left);
      DecodedGeometry dec;
      const auto d0 = std::chrono::steady_clock::now();
      decode_geometry(enc.header, segs, tail, dec);
      const auto d1 = std::chrono::steady_clock::now();
      const Quality q = measure(m, dec.patches);
      std::printf("  %7zu bytes: rms %.3e  grid psnr %6.2f dB  detail level %d  decode %.2f ms", budget,
                  q.rms, q.psnr, dec.detail_level,
                  std::chrono::duration<double, std::milli>(d1 - d0).count());
      if (g_reference) std::printf("  surface psnr %6.2f dB", surface_psnr(dec.patches));
      std::printf("\n");
    }
    // Full decode timing: best of 10.
    std::vector<std::span<const std::uint8_t>> all(enc.segments.begin(), enc.segments.end());
    double best = 1e30;
    const int reps = std::getenv("CODEC_DECODE_REPS") ? std::atoi(std::getenv("CODEC_DECODE_REPS")) : 10;
    for (int r = 0; r < reps; ++r) {
      DecodedGeometry dec;
      const auto d0 = std::chrono::steady_clock::now();
      decode_geometry(enc.header, all, {}, dec);
      best = std::min(
          best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - d0).count());
    }
    std::printf("  full decode: %.2f ms (best of 10)\n", best);
  }
  return 0;
}

/// The bytes of `path`; false (and a line on stderr) when it cannot be read.
bool read_file(const std::string& path, std::vector<std::uint8_t>& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "codec_bench: cannot open %s\n", path.c_str());
    return false;
  }
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}

/// --pack FILE: in-process decode time of a .gip (best of `reps`), whole and for a few prefixes, geometry
/// only and with normal maps, on one thread and on every hardware thread.
int pack_report(const std::string& path) {
  std::vector<std::uint8_t> pack;
  if (!read_file(path, pack)) return 2;
  const int reps = std::getenv("CODEC_DECODE_REPS") ? std::atoi(std::getenv("CODEC_DECODE_REPS")) : 20;
  std::printf("%s: %zu bytes, %u hardware threads, best of %d\n", path.c_str(), pack.size(),
              std::thread::hardware_concurrency(), reps);
  std::vector<std::size_t> sizes = {2048, 4700, 8800, 16384, 65536, pack.size()};
  for (bool normals : {false, true}) {
    for (int threads : {1, 0}) {
      for (std::size_t n : sizes) {
        if (n > pack.size()) continue;
        double best = 1e30;
        PackDecodeResult r;
        for (int k = 0; k < reps; ++k) {
          const auto t0 = std::chrono::steady_clock::now();
          r = decode_pack(pack, {.max_bytes = n, .normals = normals, .max_threads = threads});
          best = std::min(
              best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        std::printf("  %-14s %-9s %7zu bytes: %6.2f ms  (%s, detail level %d)\n",
                    normals ? "with normals" : "geometry only", threads == 1 ? "1 thread" : "threads", n,
                    best, std::string(status_message(r.status)).c_str(),
                    r.models.empty() ? -1 : r.models[0].detail_level);
      }
    }
  }
  return 0;
}

/// Best wall time of `reps` runs of f(), milliseconds.
template <typename F>
double best_ms(int reps, F&& f) {
  double best = 1e30;
  for (int k = 0; k < reps; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best,
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

/// --stream FILE [MESH]: see the file comment.
int stream_report(const std::string& path, const char* mesh_path) {
  std::vector<std::uint8_t> pack;
  if (!read_file(path, pack)) return 2;
  const int reps = std::getenv("CODEC_DECODE_REPS") ? std::atoi(std::getenv("CODEC_DECODE_REPS")) : 10;
  constexpr int kIncrements = 64;
  std::vector<std::size_t> cuts;
  for (int k = 1; k <= kIncrements; ++k)
    cuts.push_back(pack.size() * static_cast<std::size_t>(k) / kIncrements);
  std::printf("%s: %zu bytes, %u hardware threads, best of %d\n", path.c_str(), pack.size(),
              std::thread::hardware_concurrency(), reps);
  for (int threads : {1, 0}) {
    const PackDecodeOptions options{.max_threads = threads};
    PackDecodeResult r;
    const double full = best_ms(reps, [&] { r = decode_pack(pack, options); });
    const double shown = best_ms(reps, [&] {
      PackDecoder decoder(options);
      for (std::size_t n : cuts) {
        decoder.update(std::span<const std::uint8_t>(pack.data(), n));
        benchmark::DoNotOptimize(decoder.result());
      }
    });
    const double at_end = best_ms(reps, [&] {
      PackDecoder decoder(options);
      for (std::size_t n : cuts) decoder.update(std::span<const std::uint8_t>(pack.data(), n));
      benchmark::DoNotOptimize(decoder.result());
    });
    const double prefixes = best_ms(std::max(1, reps / 5), [&] {
      for (std::size_t n : cuts)
        benchmark::DoNotOptimize(decode_pack(pack, {.max_bytes = n, .max_threads = threads}));
    });
    std::printf("  %-9s full decode %7.2f ms (%s, detail level %d)\n", threads == 1 ? "1 thread" : "threads",
                full, std::string(status_message(r.status)).c_str(),
                r.models.empty() ? -1 : r.models[0].detail_level);
    std::printf("  %-9s %d increments, shown after each: %7.2f ms = %.2fx the full decode\n", "", kIncrements,
                shown, shown / full);
    std::printf("  %-9s %d increments, shown at the end: %7.2f ms = %.2fx\n", "", kIncrements, at_end,
                at_end / full);
    std::printf("  %-9s %d one-shot decodes of the prefixes: %7.2f ms = %.2fx\n", "", kIncrements, prefixes,
                prefixes / full);
    if (mesh_path && threads == 1) {
      const geomip::TriMesh mesh = geomip::read_mesh(mesh_path);
      const geomip::DracoResult draco =
          geomip::draco_encode(mesh, {.quantization_bits = 14, .compression_level = 10, .decode_runs = reps});
      std::printf("  Draco (in-process, %s, %zu vertices, 14 bits, level 10): %zu bytes, decode %.2f ms\n",
                  mesh_path, mesh.positions.size(), draco.bytes.size(), draco.decode_ms);
      std::printf("  geomip full decode (1 thread) / Draco decode = %.2f\n", full / draco.decode_ms);
      const double full_threads = best_ms(reps, [&] { r = decode_pack(pack); });
      std::printf("  geomip full decode (all threads, %.2f ms) / Draco decode = %.2f\n", full_threads,
                  full_threads / draco.decode_ms);
    }
  }
  return 0;
}

/// --decode-once FILE MODE: see the file comment.
int decode_once(const std::string& path, const std::string& mode) {
  std::vector<std::uint8_t> pack;
  if (!read_file(path, pack)) return 2;
  const PackDecodeOptions options{.max_threads = 1};
  if (mode == "full") {
    benchmark::DoNotOptimize(decode_pack(pack, options));
    return 0;
  }
  PackDecoder decoder(options);
  for (int k = 1; k <= 64; ++k) {
    decoder.update(
        std::span<const std::uint8_t>(pack.data(), pack.size() * static_cast<std::size_t>(k) / 64));
    if (mode == "shown") benchmark::DoNotOptimize(decoder.result());
  }
  benchmark::DoNotOptimize(decoder.result());
  return 0;
}

/// --draco-decode-once MESH: see the file comment.
int draco_decode_once(const char* mesh_path) {
  const geomip::TriMesh mesh = geomip::read_mesh(mesh_path);
  const geomip::DracoResult draco =
      geomip::draco_encode(mesh, {.quantization_bits = 14, .compression_level = 10, .decode_runs = 1});
  geomip::TriMesh decoded;
  if (!geomip::draco_decode(draco.bytes.data(), draco.bytes.size(), decoded)) return 2;
  std::printf("%s: %zu Draco bytes decoded to %zu vertices\n", mesh_path, draco.bytes.size(),
              decoded.positions.size());
  return 0;
}

}  // namespace

int normals_report(int argc, char** argv);          // normals_report.cpp
int normals_shading_report(int argc, char** argv);  // normal_shading_report.cpp

int main(int argc, char** argv) {
  if (argc >= 3 && std::strcmp(argv[1], "--normals") == 0) return normals_report(argc, argv);
  if ((argc == 3 || argc == 5 || argc == 7) && std::strcmp(argv[1], "--normals-shading") == 0)
    return normals_shading_report(argc, argv);
  if (argc == 4 && std::strcmp(argv[1], "--decode-once") == 0) return decode_once(argv[2], argv[3]);
  if (argc == 3 && std::strcmp(argv[1], "--draco-decode-once") == 0) return draco_decode_once(argv[2]);
  if (argc == 3 && std::strcmp(argv[1], "--pack") == 0) return pack_report(argv[2]);
  if ((argc == 3 || argc == 4) && std::strcmp(argv[1], "--stream") == 0)
    return stream_report(argv[2], argc == 4 ? argv[3] : nullptr);
  if (argc >= 3 && std::strcmp(argv[1], "--rd") == 0) {
    std::string filters = "both";
    int steps = -1, bits = 16;
    geomip::TriMesh reference;
    for (int i = 3; i + 1 < argc; i += 2) {
      if (std::strcmp(argv[i], "--filter") == 0) filters = argv[i + 1];
      if (std::strcmp(argv[i], "--steps") == 0) steps = std::atoi(argv[i + 1]);
      if (std::strcmp(argv[i], "--bits") == 0) bits = std::atoi(argv[i + 1]);
      if (std::strcmp(argv[i], "--frames") == 0) g_v3.frame_steps = std::atoi(argv[i + 1]);
      if (std::strcmp(argv[i], "--tshift") == 0) g_v3.tangential_shift = std::atoi(argv[i + 1]);
      if (std::strcmp(argv[i], "--orient") == 0) g_v3.orientation_weights = std::atoi(argv[i + 1]) != 0;
      if (std::strcmp(argv[i], "--mesh") == 0) {
        reference = geomip::read_mesh(argv[i + 1]);
        g_reference = &reference;
      }
      if (std::strcmp(argv[i], "--surface") == 0 && std::strcmp(argv[i + 1], "on") == 0)
        g_reference = &reference;
    }
    const Model m = std::string(argv[2]) == "synthetic" ? synthetic_model() : load_exr(argv[2]);
    if (g_reference && reference.positions.empty()) reference = grid_mesh(m.patches);
    return rd_report(m, filters, steps, bits);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
