// Error colouring as PLY (see error_map.h).
#include "tools/error_map.h"

#include "mesh/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <type_traits>
#include <vector>

namespace geomip::tools {
namespace {

template <typename T>
void put(std::ostream& out, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // x86-64 and aarch64 are little-endian, as the header says
  out.write(bytes, sizeof(T));
}

void put_color(std::ostream& out, const std::array<unsigned char, 3>& c) {
  out.write(reinterpret_cast<const char*>(c.data()), 3);
}

}  // namespace

std::array<unsigned char, 3> error_color(double d, double scale) {
  if (!std::isfinite(d)) return {128, 128, 128};
  // Stops of the ramp at 0, 1/4, 1/2, 3/4, 1.
  static constexpr double kStops[5][3] = {{0, 0, 1}, {0, 1, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
  const double x = std::clamp(scale > 0 ? d / scale : 0.0, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(x));
  const double t = x - i;
  std::array<unsigned char, 3> c{};
  for (int k = 0; k < 3; ++k)
    c[k] = static_cast<unsigned char>(std::lround(255 * ((1 - t) * kStops[i][k] + t * kStops[i + 1][k])));
  return c;
}

void write_error_map(const TriMesh& mesh, const OneSidedDistance& distance, const ErrorMapOptions& options,
                     std::ostream& out) {
  if (distance.vertex_distance.size() != mesh.positions.size() ||
      distance.face_rms.size() != mesh.triangles.size())
    throw InvalidInput("write_error_map: the distance was measured without error maps for this mesh");
  const double to_pct = 100 / options.diagonal;

  // Vertex colour: area-weighted RMS of the adjacent faces that have samples.
  std::vector<double> weighted(mesh.positions.size(), 0), weight(mesh.positions.size(), 0);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const double e = distance.face_rms[f];
    if (!std::isfinite(e)) continue;
    const auto& t = mesh.triangles[f];
    const double area = 0.5 * (mesh.positions[t[1]] - mesh.positions[t[0]])
                                  .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                                  .norm();
    for (int v : t) {
      weighted[v] += area * e * e;
      weight[v] += area;
    }
  }

  out << "ply\nformat binary_little_endian 1.0\ncomment geomip eval error map";
  if (!options.comment.empty()) out << ": " << options.comment;
  out << "\ncomment quality = distance in % of the original's bounding-box diagonal; red = "
      << options.scale * to_pct << " % or more\n"
      << "element vertex " << mesh.positions.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "element face " << mesh.triangles.size()
      << "\nproperty list uchar int vertex_indices\nproperty float quality\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) put(out, static_cast<float>(mesh.positions[v][k]));
    put(out, static_cast<float>(distance.vertex_distance[v] * to_pct));
    const double shown = weight[v] > 0 ? std::sqrt(weighted[v] / weight[v]) : distance.vertex_distance[v];
    put_color(out, error_color(shown, options.scale));
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    put(out, static_cast<std::uint8_t>(3));
    for (int v : mesh.triangles[f]) put(out, static_cast<std::int32_t>(v));
    put(out, static_cast<float>(distance.face_rms[f] * to_pct));
    put_color(out, error_color(distance.face_rms[f], options.scale));
  }
}

}  // namespace geomip::tools
