// Writes a golden pack of pack_test's GoldenPackDecodes: two pillows (level 5, scales 1 and 2) with normal
// maps. Run by hand once per pack format version, to a new file (old ones stay: old packs must keep
// decoding):
//   ./build/tests/make_golden_pack tests/data/golden-pillow-v11.gip   (format version 11)
// (tests/data/golden-pillow.gip was written by format version 1, golden-pillow-v2.gip by version 2,
// golden-pillow-v3.gip by version 3, golden-pillow-v4.gip by version 4, golden-pillow-v5.gip by version 5,
// golden-pillow-v6.gip by version 6, golden-pillow-v7.gip by version 7, golden-pillow-v8.gip by version 8,
// golden-pillow-v9.gip by version 9, golden-pillow-v10.gip by version 10.)
// With --per-patch, a small fuzzer seed instead: one level-4 pillow with normal maps whose joint part ends
// after 64 bytes, so most of its bytes are per-patch streams (the other seeds are smaller than the default
// 2 KB joint part) — tests/fuzz/seeds/pack/pillow-l4-per-patch.gip (format 3),
// pillow-l4-per-patch-v4.gip (format 4, its CRC groups and trailers), pillow-l4-per-patch-v5.gip (format 5,
// the lifting update), pillow-l4-per-patch-v6.gip (format 6, the filter kCubicLong),
// pillow-l4-per-patch-v7.gip (format 7, compact seam tables), pillow-l4-per-patch-v8.gip (format 8, cell
// frames), pillow-l4-per-patch-v9.gip (format 9, the seam table as a layout code),
// pillow-l4-per-patch-v10.gip (format 10, a bottom bit-plane: the geometry's last 4 planes not coded),
// pillow-l4-per-patch-v10-normal-headroom.gip (format 10 as written since 2026-12-07: the normal maps' last
// 4 planes not coded either), pillow-l4-per-patch-v11.gip (format 11: two-layer normal maps):
//   ./build/tests/make_golden_pack --per-patch  (one command, continued:)
//     tests/fuzz/seeds/pack/pillow-l4-per-patch-v11.gip
// With --layout, a fuzzer seed whose seam tables are long: two models of 24 level-2 patches glued in random
// side pairs (a quad layout's mirrored table, then a reference to it), normal maps on the first —
// tests/fuzz/seeds/pack/layout-24-v7.gip (format 7), layout-24-v8.gip (format 8):
//   ./build/tests/make_golden_pack --layout tests/fuzz/seeds/pack/layout-24-v8.gip
// With --cube, a fuzzer seed whose seam table is a layout code (format 9): the 24 quads of a cube cut 2 × 2
// per face, numbered and turned at random, written with PackWriteOptions::canonical_layout, level-2 grids
// blended from random corner points, normal maps — tests/fuzz/seeds/pack/cube-24-v9.gip:
//   ./build/tests/make_golden_pack --cube tests/fuzz/seeds/pack/cube-24-v9.gip
// (golden-pillow-v9.gip: format 9, whose two squares are stored as a layout code.)
#include "codec/pack.h"
#include "tests/codec/pillow.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <string>

int main(int argc, char** argv) {
  const bool per_patch = argc == 3 && std::string(argv[1]) == "--per-patch";
  const bool layout = argc == 3 && std::string(argv[1]) == "--layout";
  const bool cube = argc == 3 && std::string(argv[1]) == "--cube";
  if (argc != 2 && !per_patch && !layout && !cube) {
    std::fprintf(stderr, "usage: make_golden_pack [--per-patch | --layout | --cube] OUT.gip\n");
    return 2;
  }
  const char* path = argv[argc - 1];
  geomip::codec::PackWriteOptions options;
  if (per_patch) options.geometry.joint_bytes = options.normal_codec.joint_bytes = 64;
  std::vector<geomip::codec::PackModelInput> models;
  if (layout) {
    std::mt19937 rng(24);
    constexpr int kPatches = 24;
    const std::vector<geomip::codec::PatchSeam> seams = geomip::test::random_layout_seams(kPatches, rng);
    for (int m = 0; m < 2; ++m) {
      geomip::codec::PackModelInput in;
      in.name = m == 0 ? "a" : "b";
      for (int p = 0; p < kPatches; ++p) {
        geomip::codec::Grid3 g{2, std::vector<float>(75)};
        for (float& v : g.values) v = static_cast<float>(rng() % 1000) / 1000.0f;
        in.geometry.push_back(g);
      }
      in.seams = seams;
      if (m == 0) in.normals = geomip::test::position_normals(in.geometry);
      models.push_back(std::move(in));
    }
  }
  if (cube) {
    std::mt19937 rng(6);
    std::vector<geomip::test::Quad> quads = geomip::test::cube_quads(2);
    std::shuffle(quads.begin(), quads.end(), rng);
    for (auto& q : quads) std::rotate(q.begin(), q.begin() + rng() % 4, q.end());
    std::map<int, std::array<float, 3>> corner;
    for (const auto& q : quads)
      for (int c : q)
        if (!corner.count(c))
          corner[c] = {static_cast<float>(rng() % 1000) / 1000.0f, static_cast<float>(rng() % 1000) / 1000.0f,
                       static_cast<float>(rng() % 1000) / 1000.0f};
    geomip::codec::PackModelInput in;
    in.name = "cube";
    in.seams = geomip::test::seams_of(quads);
    for (const auto& q : quads) {
      geomip::codec::Grid3 g{2, std::vector<float>(3 * 25)};
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i)
          for (int c = 0; c < 3; ++c) {
            const float u = static_cast<float>(i) / 4, v = static_cast<float>(j) / 4;
            g.values[static_cast<std::size_t>(3 * (j * 5 + i) + c)] =
                (1 - u) * (1 - v) * corner[q[0]][c] + u * (1 - v) * corner[q[1]][c] +
                u * v * corner[q[2]][c] + (1 - u) * v * corner[q[3]][c];
          }
      in.geometry.push_back(g);
    }
    in.normals = geomip::test::position_normals(in.geometry);
    models.push_back(std::move(in));
    options.canonical_layout = true;
  }
  for (int m = 0; m < (layout || cube ? 0 : per_patch ? 1 : 2); ++m) {
    const geomip::test::Pillow p = geomip::test::make_pillow(per_patch ? 4 : 5, m == 0 ? 1.0 : 2.0);
    geomip::codec::PackModelInput in;
    in.name = m == 0 ? "a" : "b";
    in.geometry = p.patches;
    in.seams = p.seams;
    in.normals = geomip::test::position_normals(p.patches);
    models.push_back(std::move(in));
  }
  const std::vector<std::uint8_t> pack = geomip::codec::write_pack(models, options);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(pack.data()), static_cast<std::streamsize>(pack.size()));
  std::printf("%s: %zu bytes\n", path, pack.size());
  return out ? 0 : 1;
}
