// libFuzzer target for the mesh readers (mesh/mesh_io.h): every input is parsed from memory as each of the
// five formats (OBJ, PLY ascii/binary, OFF, STL ascii/binary, glTF JSON/GLB), so one corpus serves all of them. Any bytes
// must either give a mesh that keeps read_mesh()'s promises (at least one triangle, every index in range,
// every coordinate finite and within float range) or throw InvalidInput — never a crash, hang, other
// exception, unbounded allocation or undefined behaviour (run under ASan + UBSan; OpenMesh itself is not
// instrumented, but its crashes and hangs are caught). Work per input is bounded by -max_len (scripts/test:
// 4096 bytes).
#include "mesh/errors.h"
#include "mesh/mesh_io.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>

namespace {

void check(const geomip::TriMesh& mesh) {
  const auto n = static_cast<long long>(mesh.positions.size());
  if (mesh.triangles.empty()) {
    std::fprintf(stderr, "read_mesh_from_memory returned a mesh without triangles\n");
    std::abort();
  }
  for (const auto& t : mesh.triangles) {
    for (int v : t) {
      if (v < 0 || v >= n) {
        std::fprintf(stderr, "index %d out of range [0, %lld)\n", v, n);
        std::abort();
      }
    }
  }
  for (const auto& p : mesh.positions) {
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(p[c]) || std::fabs(p[c]) > std::numeric_limits<float>::max()) {
        std::fprintf(stderr, "coordinate %g accepted\n", p[c]);
        std::abort();
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (geomip::MeshFormat format : {geomip::MeshFormat::kObj, geomip::MeshFormat::kPly,
                                    geomip::MeshFormat::kOff, geomip::MeshFormat::kStl,
                                    geomip::MeshFormat::kGltf}) {
    try {
      check(geomip::read_mesh_from_memory(bytes, format, "fuzz"));
    } catch (const geomip::InvalidInput&) {
      // The documented outcome for bad bytes. Anything else escapes and aborts the run.
    }
  }
  return 0;
}
