// Writes a golden pack of pack_test's GoldenPackDecodes: two pillows (level 5, scales 1 and 2) with normal
// maps. Run by hand once per pack format version, to a new file (old ones stay: old packs must keep
// decoding):
//   ./build/tests/make_golden_pack tests/data/golden-pillow-v3.gip   (format version 3)
// (tests/data/golden-pillow.gip was written by format version 1, golden-pillow-v2.gip by version 2.)
#include "codec/pack.h"
#include "tests/codec/pillow.h"

#include <cmath>
#include <cstdio>
#include <fstream>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_golden_pack OUT.gip\n");
    return 2;
  }
  std::vector<geomip::codec::PackModelInput> models;
  for (int m = 0; m < 2; ++m) {
    const geomip::test::Pillow p = geomip::test::make_pillow(5, m == 0 ? 1.0 : 2.0);
    geomip::codec::PackModelInput in;
    in.name = m == 0 ? "a" : "b";
    in.geometry = p.patches;
    in.seams = p.seams;
    in.normals = p.patches;
    for (auto& g : in.normals) {
      for (std::size_t k = 0; k < g.values.size(); k += 3) {
        float* v = g.values.data() + k;
        const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; ++c) v[c] = len > 0 ? v[c] / len : (c == 2 ? 1.f : 0.f);
      }
    }
    models.push_back(std::move(in));
  }
  const std::vector<std::uint8_t> pack = geomip::codec::write_pack(models);
  std::ofstream out(argv[1], std::ios::binary);
  out.write(reinterpret_cast<const char*>(pack.data()), static_cast<std::streamsize>(pack.size()));
  std::printf("%s: %zu bytes\n", argv[1], pack.size());
  return out ? 0 : 1;
}
