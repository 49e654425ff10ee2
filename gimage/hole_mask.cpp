#include "gimage/hole_mask.h"

#include "gimage/resample.h"
#include "gimage/surface_distance.h"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

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
    std::vector<std::uint8_t> samples(static_cast<std::size_t>(n) * n, 0);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) samples[static_cast<std::size_t>(j) * n + i] = filled(i, j);
    }
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
    result.fill_samples.push_back(std::move(samples));
    first_triangle += patch.triangles.size();
  }
  return result;
}

std::vector<std::vector<std::uint8_t>> refine_hole_quads(const std::vector<std::vector<std::uint8_t>>& quads,
                                                         int from_level, int to_level) {
  const int shift = to_level - from_level, n = 1 << to_level, coarse = 1 << from_level;
  std::vector<std::vector<std::uint8_t>> fine(quads.size(),
                                              std::vector<std::uint8_t>(static_cast<std::size_t>(n) * n, 0));
  for (std::size_t p = 0; p < quads.size(); ++p) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i)
        fine[p][static_cast<std::size_t>(j) * n + i] =
            quads[p][static_cast<std::size_t>(j >> shift) * coarse + (i >> shift)];
    }
  }
  return fine;
}

std::size_t snap_hole_borders(GeometryImages& images, const HoleMaskResult& mask, const TriMesh& original) {
  if (mask.quads.empty() || mask.fill_samples.size() != images.geometry.size()) return 0;
  using Key = std::array<float, 3>;
  std::map<Key, Key> moved;  // a sample's position -> its closest point on the original, for every copy
  for (std::size_t p = 0; p < images.geometry.size(); ++p) {
    const GeometryImage& image = images.geometry[p];
    const int n = image.size(), intervals = n - 1;
    if (mask.fill_samples[p].size() != static_cast<std::size_t>(n) * n ||
        mask.quads[p].size() != static_cast<std::size_t>(intervals) * intervals)
      return 0;
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i) {
        if (mask.quads[p][static_cast<std::size_t>(j) * intervals + i]) continue;
        for (const auto& [a, b] : {std::pair{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}}) {
          if (!mask.fill_samples[p][static_cast<std::size_t>(b) * n + a]) continue;
          const float* s = image.at(a, b);
          moved.emplace(Key{s[0], s[1], s[2]}, Key{s[0], s[1], s[2]});
        }
      }
    }
  }
  if (moved.empty()) return 0;
  const SurfaceQuery query(original);
  for (auto& [from, to] : moved) {
    const Eigen::Vector3d point = query.closest(Eigen::Vector3d(from[0], from[1], from[2])).point;
    to = Key{static_cast<float>(point[0]), static_cast<float>(point[1]), static_cast<float>(point[2])};
  }
  for (GeometryImage& image : images.geometry) {
    for (std::size_t k = 0; k + 2 < image.values.size(); k += 3) {
      const auto it = moved.find(Key{image.values[k], image.values[k + 1], image.values[k + 2]});
      if (it == moved.end()) continue;
      for (int c = 0; c < 3; ++c) image.values[k + c] = it->second[c];
    }
  }
  return moved.size();
}

}  // namespace geomip
