// Writes a golden pack of pack_test's GoldenPackDecodes: two pillows (level 5, scales 1 and 2) with normal
// maps. Run by hand once per pack format version, to a new file (old ones stay: old packs must keep
// decoding):
//   ./build/tests/make_golden_pack tests/data/golden-pillow-v6.gip   (format version 6)
// (tests/data/golden-pillow.gip was written by format version 1, golden-pillow-v2.gip by version 2,
// golden-pillow-v3.gip by version 3, golden-pillow-v4.gip by version 4, golden-pillow-v5.gip by version 5.)
// With --per-patch, a small fuzzer seed instead: one level-4 pillow with normal maps whose joint part ends
// after 64 bytes, so most of its bytes are per-patch streams (the other seeds are smaller than the default
// 2 KB joint part) — tests/fuzz/seeds/pack/pillow-l4-per-patch.gip (format 3),
// pillow-l4-per-patch-v4.gip (format 4, its CRC groups and trailers), pillow-l4-per-patch-v5.gip (format 5,
// the lifting update), pillow-l4-per-patch-v6.gip (format 6, the filter kCubicLong):
//   ./build/tests/make_golden_pack --per-patch tests/fuzz/seeds/pack/pillow-l4-per-patch-v6.gip
#include "codec/pack.h"
#include "tests/codec/pillow.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  const bool per_patch = argc == 3 && std::string(argv[1]) == "--per-patch";
  if (argc != 2 && !per_patch) {
    std::fprintf(stderr, "usage: make_golden_pack [--per-patch] OUT.gip\n");
    return 2;
  }
  const char* path = argv[argc - 1];
  geomip::codec::PackWriteOptions options;
  if (per_patch) options.geometry.joint_bytes = options.normal_codec.joint_bytes = 64;
  std::vector<geomip::codec::PackModelInput> models;
  for (int m = 0; m < (per_patch ? 1 : 2); ++m) {
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
