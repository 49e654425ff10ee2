#include "mesh/mesh.h"

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

}  // namespace geomip
