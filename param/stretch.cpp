#include "param/stretch.h"

#include "mesh/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace geomip {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_triangles(const char* function, const std::vector<std::array<int, 3>>& triangles,
                     std::size_t num_vertices) {
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (int v : triangles[f]) {
      if (v < 0 || static_cast<std::size_t>(v) >= num_vertices) {
        throw InvalidInput(std::string(function) + ": triangle " + std::to_string(f) + " has vertex index " +
                           std::to_string(v) + " out of range [0, " + std::to_string(num_vertices) + ")");
      }
    }
  }
}

}  // namespace

StretchValues triangle_stretch(const Eigen::Vector3d q[3], const Eigen::Vector2d p[3]) {
  const double s1 = p[0].x(), t1 = p[0].y(), s2 = p[1].x(), t2 = p[1].y(), s3 = p[2].x(), t3 = p[2].y();
  const double double_area = (s2 - s1) * (t3 - t1) - (s3 - s1) * (t2 - t1);
  if (!(double_area > 0)) return {kInf, kInf};
  const Eigen::Vector3d ss = (q[0] * (t2 - t3) + q[1] * (t3 - t1) + q[2] * (t1 - t2)) / double_area;
  const Eigen::Vector3d st = (q[0] * (s3 - s2) + q[1] * (s1 - s3) + q[2] * (s2 - s1)) / double_area;
  const double a = ss.squaredNorm(), b = ss.dot(st), c = st.squaredNorm();
  const double root = std::sqrt((a - c) * (a - c) + 4 * b * b);
  return {std::sqrt(0.5 * (a + c)), std::sqrt(0.5 * ((a + c) + root))};
}

StretchValues mesh_stretch(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<std::array<int, 3>>& triangles,
                           const std::vector<Eigen::Vector2d>& uv) {
  if (uv.size() != positions.size()) {
    throw InvalidInput("mesh_stretch: " + std::to_string(uv.size()) + " uv coordinates for " +
                       std::to_string(positions.size()) + " vertices");
  }
  if (triangles.empty()) throw InvalidInput("mesh_stretch: no triangles");
  check_triangles("mesh_stretch", triangles, positions.size());

  double sum_a3 = 0, sum_a2 = 0, sum_l2sq_a3 = 0, max_linf = 0;
  bool flipped = false;
  for (const auto& t : triangles) {
    const Eigen::Vector3d q[3] = {positions[t[0]], positions[t[1]], positions[t[2]]};
    const Eigen::Vector2d p[3] = {uv[t[0]], uv[t[1]], uv[t[2]]};
    const double a3 = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
    sum_a3 += a3;
    const StretchValues s = triangle_stretch(q, p);
    if (std::isinf(s.l2)) {
      flipped = true;
      continue;
    }
    sum_a2 += 0.5 * signed_double_area(p[0], p[1], p[2]);
    sum_l2sq_a3 += s.l2 * s.l2 * a3;
    max_linf = std::max(max_linf, s.linf);
  }
  if (!(sum_a3 > 0)) throw InvalidInput("mesh_stretch: the total 3D area is zero");
  if (flipped) return {kInf, kInf};
  const double normalization = std::sqrt(sum_a2 / sum_a3);
  return {std::sqrt(sum_l2sq_a3 / sum_a3) * normalization, max_linf * normalization};
}

std::size_t count_flipped(const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Eigen::Vector2d>& uv) {
  check_triangles("count_flipped", triangles, uv.size());
  return count_flipped_triangles(uv, triangles);
}

}  // namespace geomip
