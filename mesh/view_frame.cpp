#include "mesh/view_frame.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace geomip {
namespace {

std::vector<Eigen::Vector3d> referenced_points(const TriMesh& mesh) {
  std::vector<char> used(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int v : t)
      if (v >= 0 && static_cast<std::size_t>(v) < used.size()) used[static_cast<std::size_t>(v)] = 1;
  std::vector<Eigen::Vector3d> out;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v] && mesh.positions[v].allFinite()) out.push_back(mesh.positions[v]);
  return out;
}

/// Area of the convex hull of 2D points (Andrew's monotone chain).
double hull_area(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return 0;
  std::sort(p.begin(), p.end(),
            [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  double area = 0;
  for (std::size_t i = 0; i + 1 < k; ++i) area += h[i].x() * h[i + 1].y() - h[i + 1].x() * h[i].y();
  return std::abs(area) / 2;
}

}  // namespace

Eigen::Vector3d ground_direction(const TriMesh& mesh, double band) {
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  if (points.empty()) return -Eigen::Vector3d::UnitY();
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d extent = hi - lo;
  Eigen::Vector3d best = -Eigen::Vector3d::UnitY();
  double best_ratio = -1;
  for (int axis : {1, 0, 2}) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double face = extent[a] * extent[b];
    for (int sign : {-1, 1}) {
      const double plane = sign < 0 ? lo[axis] : hi[axis];
      std::vector<Eigen::Vector2d> contact;
      for (const auto& p : points)
        if (std::abs(p[axis] - plane) <= band * extent[axis]) contact.emplace_back(p[a], p[b]);
      const double ratio = face > 0 ? hull_area(std::move(contact)) / face : 0;
      if (ratio > best_ratio) {
        best_ratio = ratio;
        best = Eigen::Vector3d::Unit(axis) * sign;
      }
    }
  }
  return best;
}

Eigen::Matrix3d upright_rotation(const TriMesh& mesh, UpAxis up_axis) {
  const Eigen::Vector3d up = up_axis == UpAxis::kX   ? Eigen::Vector3d::UnitX()
                             : up_axis == UpAxis::kY ? Eigen::Vector3d::UnitY()
                             : up_axis == UpAxis::kZ ? Eigen::Vector3d::UnitZ()
                                                     : Eigen::Vector3d(-ground_direction(mesh));
  int up_index = 0;
  up.cwiseAbs().maxCoeff(&up_index);
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  if (!points.empty()) {
    lo = hi = points[0];
    for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  // The longer horizontal axis (ties: the first in x, y, z order).
  int length = -1;
  for (int c = 0; c < 3; ++c)
    if (c != up_index && (length < 0 || hi[c] - lo[c] > hi[length] - lo[length])) length = c;
  // Its end that reaches higher: the largest up coordinate in the quarter of the length at each end.
  const double quarter = 0.25 * (hi[length] - lo[length]);
  double top_low = -HUGE_VAL, top_high = -HUGE_VAL;
  for (const auto& p : points) {
    const double height = up.dot(p);
    if (p[length] <= lo[length] + quarter) top_low = std::max(top_low, height);
    if (p[length] >= hi[length] - quarter) top_high = std::max(top_high, height);
  }
  const Eigen::Vector3d front = Eigen::Vector3d::Unit(length) * (top_low > top_high ? -1.0 : 1.0);
  Eigen::Matrix3d r;
  r.row(0) = front.transpose();
  r.row(1) = up.transpose();
  r.row(2) = front.cross(up).transpose();
  return r;
}

std::array<double, 16> view_normalization(const TriMesh& mesh, const Eigen::Matrix3d& rotation) {
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  if (!points.empty()) {
    lo = hi = rotation * points[0];
    for (const auto& p : points) {
      const Eigen::Vector3d q = rotation * p;
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
  }
  double extent = (hi - lo).maxCoeff();
  if (!(extent > 0) || !std::isfinite(extent)) extent = 1;
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  std::array<double, 16> m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[static_cast<std::size_t>(4 * r + c)] = rotation(r, c) / extent;
    m[static_cast<std::size_t>(4 * r + 3)] = -centre[r] / extent;
  }
  m[15] = 1;
  return m;
}

}  // namespace geomip
