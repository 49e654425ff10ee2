#include "gimage/hole_mask.h"

#include "gimage/resample.h"
#include "gimage/surface_distance.h"

#include <algorithm>

namespace geomip {

HoleMaskResult hole_mask(const ModelParameterization& model, const TriMesh& original, int level,
                         const HoleMaskOptions& options) {
  HoleMaskResult result;
  // Fill flags of every parameterized triangle: its centroid's distance to the original surface.
  std::vector<Eigen::Vector3d> centroids;
  std::vector<double> longest_edge;
  for (const PatchParameterization& patch : model.patches) {
    for (const auto& t : patch.triangles) {
      const Eigen::Vector3d& a = model.mesh.positions[patch.vertices[t[0]]];
      const Eigen::Vector3d& b = model.mesh.positions[patch.vertices[t[1]]];
      const Eigen::Vector3d& c = model.mesh.positions[patch.vertices[t[2]]];
      centroids.push_back((a + b + c) / 3);
      longest_edge.push_back(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}));
    }
  }
  const std::vector<double> distance = distances_to_surface(original, centroids);
  std::vector<std::uint8_t> fill(centroids.size());
  for (std::size_t k = 0; k < fill.size(); ++k) {
    fill[k] = distance[k] > options.relative_tolerance * longest_edge[k];
    result.fill_triangles += fill[k];
  }
  if (result.fill_triangles == 0) return result;

  const int intervals = 1 << level;
  const int n = intervals + 1;
  std::size_t first_triangle = 0;
  for (const PatchParameterization& patch : model.patches) {
    const GridLocation location = locate_grid_samples(patch, level);
    auto filled = [&](int i, int j) {
      const int t = location.triangle[static_cast<std::size_t>(j) * n + i];
      return t >= 0 && fill[first_triangle + static_cast<std::size_t>(t)];
    };
    std::vector<std::uint8_t> quads(static_cast<std::size_t>(intervals) * intervals, 0);
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i) {
        const int corners = filled(i, j) + filled(i + 1, j) + filled(i, j + 1) + filled(i + 1, j + 1);
        const bool masked = corners >= options.min_fill_corners;
        quads[static_cast<std::size_t>(j) * intervals + i] = masked;
        result.masked_quads += masked;
      }
    }
    result.quads.push_back(std::move(quads));
    first_triangle += patch.triangles.size();
  }
  return result;
}

}  // namespace geomip
