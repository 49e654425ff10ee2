#include "mesh/mesh.h"

#include <cmath>
#include <limits>

namespace geomip {

double BoundingBox::diagonal() const {
  if (!(min.array() <= max.array()).all()) return 0.0;
  return (max - min).norm();
}

BoundingBox referenced_bounding_box(const TriMesh& mesh) {
  const double inf = std::numeric_limits<double>::infinity();
  BoundingBox box{Eigen::Vector3d::Constant(inf), Eigen::Vector3d::Constant(-inf)};
  for (const auto& t : mesh.triangles) {
    for (int v : t) {
      box.min = box.min.cwiseMin(mesh.positions[v]);
      box.max = box.max.cwiseMax(mesh.positions[v]);
    }
  }
  return box;
}

std::vector<Eigen::Vector3d> vertex_normals(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    // |cross| is twice the area: the sum weights every triangle by its area.
    const Eigen::Vector3d c = (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (int v : t) n[v] += c;
  }
  for (auto& v : n) {
    const double len = v.norm();
    v = len > 0 && std::isfinite(len) ? Eigen::Vector3d(v / len) : Eigen::Vector3d(0, 0, 1);
  }
  return n;
}

}  // namespace geomip
