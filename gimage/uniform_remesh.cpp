#include "gimage/uniform_remesh.h"

#include "mesh/errors.h"

#include <numeric>
#include <string>

namespace geomip {
namespace {

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

}  // namespace

UniformRemeshResult uniform_remesh_connectivity(std::size_t num_patches,
                                                const std::vector<SideLink>& adjacency, int level) {
  if (level < 0 || level > kMaxGeometryImageLevel) {
    throw InvalidInput("uniform_remesh: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  if (!adjacency.empty() && adjacency.size() != 4 * num_patches) {
    throw InvalidInput("uniform_remesh: adjacency must have 4 entries per patch");
  }
  const int intervals = 1 << level;
  const int n = intervals + 1;
  const std::size_t per_patch = static_cast<std::size_t>(n) * n;
  // Union-find over all samples of all patches; only seam samples are ever joined.
  std::vector<int> parent(num_patches * per_patch);
  std::iota(parent.begin(), parent.end(), 0);
  auto side_index = [&](int p, int s, int k) {
    int i, j;
    switch (s) {
      case 0:
        i = k, j = 0;
        break;
      case 1:
        i = intervals, j = k;
        break;
      case 2:
        i = intervals - k, j = intervals;
        break;
      default:
        i = 0, j = intervals - k;
        break;
    }
    return static_cast<int>(p * per_patch + static_cast<std::size_t>(j) * n + i);
  };
  for (std::size_t key = 0; key < adjacency.size(); ++key) {
    const SideLink& link = adjacency[key];
    if (link.patch != static_cast<int>(key / 4) || link.side != static_cast<int>(key % 4) ||
        link.other_patch < 0 || link.other_patch >= static_cast<int>(num_patches) || link.other_side < 0 ||
        link.other_side > 3) {
      throw InvalidInput("uniform_remesh: adjacency entry " + std::to_string(key) +
                         " is out of place or range");
    }
    for (int k = 0; k <= intervals; ++k) {
      const int a = find_root(parent, side_index(link.patch, link.side, k));
      const int b =
          find_root(parent, side_index(link.other_patch, link.other_side, link.reversed ? intervals - k : k));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  UniformRemeshResult result;
  std::vector<int> vertex_of_root(parent.size(), -1);
  int next = 0;
  result.grid_vertex.resize(num_patches);
  for (std::size_t p = 0; p < num_patches; ++p) {
    auto& grid = result.grid_vertex[p];
    grid.resize(per_patch);
    for (std::size_t k = 0; k < per_patch; ++k) {
      const int root = find_root(parent, static_cast<int>(p * per_patch + k));
      if (vertex_of_root[root] < 0) vertex_of_root[root] = next++;
      grid[k] = vertex_of_root[root];
    }
  }
  result.mesh.positions.assign(next, Eigen::Vector3d::Zero());
  result.mesh.triangles.reserve(2 * num_patches * static_cast<std::size_t>(intervals) * intervals);
  for (std::size_t p = 0; p < num_patches; ++p) {
    const auto& g = result.grid_vertex[p];
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i) {
        const int a = g[j * n + i], b = g[j * n + i + 1], c = g[(j + 1) * n + i + 1], d = g[(j + 1) * n + i];
        if ((i + j + static_cast<int>(p)) % 2 == 0) {
          result.mesh.triangles.push_back({a, b, c});
          result.mesh.triangles.push_back({a, c, d});
        } else {
          result.mesh.triangles.push_back({a, b, d});
          result.mesh.triangles.push_back({b, c, d});
        }
      }
    }
  }
  return result;
}

void split_along_shorter_diagonals(UniformRemeshResult& remesh, int level,
                                   const std::vector<const std::vector<Eigen::Vector3d>*>& models) {
  if (models.empty()) throw InvalidInput("split_along_shorter_diagonals: no model positions");
  for (const auto* positions : models) {
    if (positions == nullptr || positions->size() != remesh.mesh.positions.size()) {
      throw InvalidInput("split_along_shorter_diagonals: a model's positions do not match the remesh");
    }
  }
  if (level < 0 || level > kMaxGeometryImageLevel) {
    throw InvalidInput("split_along_shorter_diagonals: level " + std::to_string(level) + " is out of range");
  }
  const int intervals = 1 << level;
  const int n = intervals + 1;
  const std::size_t num_patches = remesh.grid_vertex.size();
  if (remesh.mesh.triangles.size() != 2 * num_patches * static_cast<std::size_t>(intervals) * intervals) {
    throw InvalidInput("split_along_shorter_diagonals: the remesh is not a level-" + std::to_string(level) +
                       " grid triangulation");
  }
  std::size_t t = 0;
  for (std::size_t p = 0; p < num_patches; ++p) {
    const auto& g = remesh.grid_vertex[p];
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i, t += 2) {
        const bool corner = (i == 0 || i == intervals - 1) && (j == 0 || j == intervals - 1);
        if (corner) continue;
        const int a = g[j * n + i], b = g[j * n + i + 1], c = g[(j + 1) * n + i + 1], d = g[(j + 1) * n + i];
        double ac_minus_bd = 0.0;
        for (const auto* positions : models) {
          const auto& x = *positions;
          ac_minus_bd += (x[a] - x[c]).squaredNorm() - (x[b] - x[d]).squaredNorm();
        }
        bool along_ac = (i + j + static_cast<int>(p)) % 2 == 0;
        if (ac_minus_bd < 0.0) along_ac = true;
        if (ac_minus_bd > 0.0) along_ac = false;
        if (along_ac) {
          remesh.mesh.triangles[t] = {a, b, c};
          remesh.mesh.triangles[t + 1] = {a, c, d};
        } else {
          remesh.mesh.triangles[t] = {a, b, d};
          remesh.mesh.triangles[t + 1] = {b, c, d};
        }
      }
    }
  }
}

UniformRemeshResult uniform_remesh(const GeometryImages& images, int level) {
  if (images.geometry.empty()) throw InvalidInput("uniform_remesh: no geometry images");
  const int n = images.geometry[0].level;
  for (const auto& g : images.geometry) {
    if (g.level != n || g.values.size() != 3 * static_cast<std::size_t>(g.size()) * g.size()) {
      throw InvalidInput("uniform_remesh: geometry images of different levels or wrong sizes");
    }
  }
  if (level < 0 || level > n) {
    throw InvalidInput("uniform_remesh: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(n) + "] (the geometry images' level)");
  }
  UniformRemeshResult result = uniform_remesh_connectivity(images.geometry.size(), images.adjacency, level);
  const int size = (1 << level) + 1;
  const int step = 1 << (n - level);
  for (std::size_t p = 0; p < images.geometry.size(); ++p) {
    for (int j = 0; j < size; ++j) {
      for (int i = 0; i < size; ++i) {
        result.mesh.positions[result.grid_vertex[p][j * size + i]] =
            images.geometry[p].sample(i * step, j * step).cast<double>();
      }
    }
  }
  return result;
}

}  // namespace geomip
