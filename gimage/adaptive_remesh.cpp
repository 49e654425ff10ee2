#include "gimage/adaptive_remesh.h"

#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"
#include "param/unit_square.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string>

namespace geomip {
namespace {

/// The least-squares plane of `points` (count > 0): through the centroid, normal = the covariance's smallest
/// eigenvector.
struct Plane {
  Eigen::Vector3d point, normal;
  double distance(const Eigen::Vector3d& x) const { return std::abs((x - point).dot(normal)); }
};

Plane fit_plane(const Eigen::Vector3d* points, std::size_t count) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < count; ++k) centroid += points[k];
  centroid /= static_cast<double>(count);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d d = points[k] - centroid;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  return {centroid, solver.eigenvectors().col(0).normalized()};
}

void check_adjacency(const std::vector<SideLink>& adjacency, std::size_t patches, const char* fn) {
  if (!adjacency.empty() && adjacency.size() != 4 * patches) {
    throw InvalidInput(std::string(fn) + ": adjacency must have 4 entries per patch");
  }
  for (std::size_t key = 0; key < adjacency.size(); ++key) {
    const SideLink& l = adjacency[key];
    if (l.patch != static_cast<int>(key / 4) || l.side != static_cast<int>(key % 4) || l.other_patch < 0 ||
        l.other_patch >= static_cast<int>(patches) || l.other_side < 0 || l.other_side > 3) {
      throw InvalidInput(std::string(fn) + ": adjacency entry " + std::to_string(key) +
                         " is out of place or range");
    }
  }
}

/// A finest cell of one patch.
struct Cell {
  int patch, ci, cj;
};

/// The cell across side `side` (0: −v, 1: +u, 2: +v, 3: −u, the patch sides' numbering) of cell (ci, cj), in
/// the same patch or, on the patch boundary, through the SideLink; nullopt on a side without a link.
std::optional<Cell> cell_across(const AdaptiveQuadtree& t, const Cell& c, int side) {
  const int cells = 1 << t.max_depth;
  int ci = c.ci, cj = c.cj;
  switch (side) {
    case 0:
      --cj;
      break;
    case 1:
      ++ci;
      break;
    case 2:
      ++cj;
      break;
    default:
      --ci;
      break;
  }
  if (ci >= 0 && cj >= 0 && ci < cells && cj < cells) return Cell{c.patch, ci, cj};
  if (t.adjacency.empty()) return std::nullopt;
  // Position k of the cell along patch side `side`, in the side's direction (corner side → corner side+1):
  // the cells along a side are indexed like a grid with last = cells − 1 (param/unit_square.h).
  const int k = side_grid_position(side, c.ci, c.cj, cells - 1);
  const SideLink& link = t.adjacency[4 * c.patch + side];
  const auto [oi, oj] = side_grid_index(link.other_side, link.reversed ? cells - 1 - k : k, cells - 1);
  return Cell{link.other_patch, oi, oj};
}

int depth_at(const AdaptiveQuadtree& t, const Cell& c) {
  return t.depth[c.patch][static_cast<std::size_t>(c.cj) * (1u << t.max_depth) + c.ci];
}

/// The largest depth among the cells across side `side` of leaf `leaf` (−1 without neighbours).
int max_neighbour_depth(const AdaptiveQuadtree& t, const AdaptiveQuadtree::Leaf& leaf, int side) {
  const int span = 1 << (t.max_depth - leaf.depth);
  const int x0 = leaf.i * span, y0 = leaf.j * span;
  int worst = -1;
  for (int k = 0; k < span; ++k) {
    Cell c{leaf.patch, 0, 0};
    switch (side) {
      case 0:
        c.ci = x0 + k, c.cj = y0;
        break;
      case 1:
        c.ci = x0 + span - 1, c.cj = y0 + k;
        break;
      case 2:
        c.ci = x0 + k, c.cj = y0 + span - 1;
        break;
      default:
        c.ci = x0, c.cj = y0 + k;
        break;
    }
    const std::optional<Cell> across = cell_across(t, c, side);
    if (across) worst = std::max(worst, depth_at(t, *across));
  }
  return worst;
}

void set_leaf_depth(AdaptiveQuadtree& t, int patch, int depth, int i, int j, int new_depth) {
  const int cells = 1 << t.max_depth;
  const int span = 1 << (t.max_depth - depth);
  for (int y = j * span; y < (j + 1) * span; ++y) {
    for (int x = i * span; x < (i + 1) * span; ++x) {
      t.depth[patch][static_cast<std::size_t>(y) * cells + x] = static_cast<std::uint8_t>(new_depth);
    }
  }
}

}  // namespace

std::vector<AdaptiveQuadtree::Leaf> AdaptiveQuadtree::leaves() const {
  std::vector<Leaf> out;
  const int cells = 1 << max_depth;
  for (std::size_t p = 0; p < depth.size(); ++p) {
    for (int cj = 0; cj < cells; ++cj) {
      for (int ci = 0; ci < cells; ++ci) {
        const int d = depth[p][static_cast<std::size_t>(cj) * cells + ci];
        const int shift = max_depth - d;
        if (((ci >> shift) << shift) == ci && ((cj >> shift) << shift) == cj) {
          out.push_back({static_cast<int>(p), d, ci >> shift, cj >> shift});
        }
      }
    }
  }
  return out;
}

AdaptiveQuadErrors adaptive_quad_errors(const ModelParameterization& model, const GeometryImages& images,
                                        const AdaptiveErrorOptions& options) {
  if (images.geometry.size() != model.patches.size() || images.geometry.empty()) {
    throw InvalidInput("adaptive_quad_errors: need one geometry image per patch");
  }
  const int n = images.geometry[0].level;
  for (const auto& g : images.geometry) {
    if (g.level != n || g.values.size() != 3 * static_cast<std::size_t>(g.size()) * g.size()) {
      throw InvalidInput("adaptive_quad_errors: geometry images of different levels or wrong sizes");
    }
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& p : model.mesh.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double diagonal = model.mesh.positions.empty() ? 0.0 : (hi - lo).norm();
  if (!(diagonal > 0)) throw InvalidInput("adaptive_quad_errors: the mesh's bounding box is a point");

  AdaptiveQuadErrors result;
  result.max_depth = n;
  result.errors.resize(model.patches.size());
  const int cells = 1 << n;
  for (std::size_t p = 0; p < model.patches.size(); ++p) {
    const PatchParameterization& patch = model.patches[p];
    if (patch.uv.size() != patch.vertices.size()) {
      throw InvalidInput("adaptive_quad_errors: patch " + std::to_string(p) +
                         " has uv and vertex arrays of different sizes");
    }
    // Finest cell of each vertex; vertices sorted by cell in Morton order so every quad's vertices form one
    // run.
    struct Item {
      std::uint32_t morton;
      int vertex;
    };
    auto spread = [](std::uint32_t x) {
      std::uint32_t r = 0;
      for (int b = 0; b < 16; ++b) r |= ((x >> b) & 1u) << (2 * b);
      return r;
    };
    std::vector<Item> items;
    items.reserve(patch.vertices.size());
    for (std::size_t v = 0; v < patch.vertices.size(); ++v) {
      const int id = patch.vertices[v];
      if (id < 0 || id >= static_cast<int>(model.mesh.positions.size())) {
        throw InvalidInput("adaptive_quad_errors: patch vertex id out of range");
      }
      const int ci = std::clamp(static_cast<int>(std::floor(patch.uv[v].x() * cells)), 0, cells - 1);
      const int cj = std::clamp(static_cast<int>(std::floor(patch.uv[v].y() * cells)), 0, cells - 1);
      items.push_back({spread(ci) | (spread(cj) << 1), id});
    }
    std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.morton < b.morton; });
    const GeometryImage& image = images.geometry[p];
    result.errors[p].resize(n + 1);
    std::vector<Eigen::Vector3d> points;
    for (int d = 0; d <= n; ++d) {
      const int side = 1 << d;
      const int span = 1 << (n - d);
      auto& errors = result.errors[p][d];
      errors.assign(static_cast<std::size_t>(side) * side, 0.0);
      // The run of `items` in each quad.
      const int shift = 2 * (n - d);
      std::vector<std::pair<std::size_t, std::size_t>> runs(static_cast<std::size_t>(side) * side, {0, 0});
      for (std::size_t a = 0; a < items.size();) {
        const std::uint32_t key = items[a].morton >> shift;
        std::size_t b = a;
        while (b < items.size() && (items[b].morton >> shift) == key) ++b;
        int i = 0, j = 0;  // the quad, decoded from the Morton key
        for (int bit = 0; bit < d; ++bit) {
          i |= static_cast<int>((key >> (2 * bit)) & 1u) << bit;
          j |= static_cast<int>((key >> (2 * bit + 1)) & 1u) << bit;
        }
        runs[static_cast<std::size_t>(j) * side + i] = {a, b};
        a = b;
      }
      for (int j = 0; j < side; ++j) {
        for (int i = 0; i < side; ++i) {
          const auto [a, b] = runs[static_cast<std::size_t>(j) * side + i];
          points.clear();
          for (std::size_t k = a; k < b; ++k) points.push_back(model.mesh.positions[items[k].vertex]);
          Plane plane;
          if (points.size() > 3) {
            plane = fit_plane(points.data(), points.size());
          } else {
            const std::array<Eigen::Vector3d, 4> corners = {
                image.sample(i * span, j * span).cast<double>(),
                image.sample((i + 1) * span, j * span).cast<double>(),
                image.sample((i + 1) * span, (j + 1) * span).cast<double>(),
                image.sample(i * span, (j + 1) * span).cast<double>()};
            plane = fit_plane(corners.data(), corners.size());
          }
          double e = 0;
          for (const auto& x : points) e = std::max(e, plane.distance(x));
          if (options.measure_samples || points.size() <= 3) {
            // The quad's level-n samples, which its triangles stand for: needed where it holds few vertices
            // (three always lie on their plane); optional elsewhere, where (u,v) triangles larger than the
            // quad make most of its surface an interpolation of vertices outside it.
            for (int y = j * span; y <= (j + 1) * span; ++y) {
              for (int x = i * span; x <= (i + 1) * span; ++x) {
                e = std::max(e, plane.distance(image.sample(x, y).cast<double>()));
              }
            }
          }
          errors[static_cast<std::size_t>(j) * side + i] = e / diagonal;
        }
      }
    }
  }
  return result;
}

std::size_t restrict_quadtree(AdaptiveQuadtree& tree) {
  std::size_t splits = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (const AdaptiveQuadtree::Leaf& leaf : tree.leaves()) {
      // The tree may have changed in this pass: skip leaves that are no longer leaves.
      const int cells = 1 << tree.max_depth;
      const int span = 1 << (tree.max_depth - leaf.depth);
      if (tree.depth[leaf.patch][static_cast<std::size_t>(leaf.j * span) * cells + leaf.i * span] !=
          leaf.depth) {
        continue;
      }
      bool split = false;
      for (int side = 0; side < 4 && !split; ++side)
        split = max_neighbour_depth(tree, leaf, side) > leaf.depth + 1;
      if (split) {
        set_leaf_depth(tree, leaf.patch, leaf.depth, leaf.i, leaf.j, leaf.depth + 1);
        ++splits;
        changed = true;
      }
    }
  }
  return splits;
}

namespace {

// Whether the level-0 uniform remesh of the layout walks every directed edge once (a simplicial surface). A
// torus's 2x2 grid does not (its 4 vertices repeat edges), so its tree starts at depth 1.
bool level0_is_simplicial(std::size_t patches, const std::vector<SideLink>& adjacency) {
  const TriMesh m = uniform_remesh_connectivity(patches, adjacency, 0).mesh;
  std::set<std::pair<int, int>> directed;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) {
      if (!directed.insert({t[k], t[(k + 1) % 3]}).second) return false;
    }
  }
  return true;
}

}  // namespace

AdaptiveQuadtree adaptive_quadtree(const std::vector<AdaptiveQuadErrors>& errors,
                                   const std::vector<SideLink>& adjacency,
                                   const AdaptiveRemeshOptions& options) {
  if (errors.empty()) throw InvalidInput("adaptive_quadtree: no models");
  if (!(options.epsilon >= 0)) throw InvalidInput("adaptive_quadtree: epsilon must be >= 0");
  const int n = errors[0].max_depth;
  const std::size_t patches = errors[0].errors.size();
  for (const auto& e : errors) {
    if (e.max_depth != n || e.errors.size() != patches) {
      throw InvalidInput("adaptive_quadtree: the models differ in maximum depth or patch count");
    }
    for (const auto& per_patch : e.errors) {
      if (per_patch.size() != static_cast<std::size_t>(n) + 1) {
        throw InvalidInput("adaptive_quadtree: errors missing for some depths");
      }
      for (int d = 0; d <= n; ++d) {
        if (per_patch[d].size() != (std::size_t{1} << (2 * d))) {
          throw InvalidInput("adaptive_quadtree: wrong number of quad errors at depth " + std::to_string(d));
        }
      }
    }
  }
  if (n < 0 || n > kMaxGeometryImageLevel)
    throw InvalidInput("adaptive_quadtree: maximum depth out of range");
  check_adjacency(adjacency, patches, "adaptive_quadtree");
  AdaptiveQuadtree tree;
  tree.max_depth = n;
  tree.adjacency = adjacency;
  const std::size_t cells = std::size_t{1} << n;
  tree.depth.assign(patches, std::vector<std::uint8_t>(cells * cells, 0));
  const int min_depth = std::min(n, level0_is_simplicial(patches, adjacency) ? 0 : 1);
  // Top-down: (patch, depth, i, j) stack.
  std::vector<std::array<int, 4>> stack;
  for (std::size_t p = 0; p < patches; ++p) {
    const int side = 1 << min_depth;
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) stack.push_back({static_cast<int>(p), min_depth, i, j});
    }
  }
  while (!stack.empty()) {
    const auto [p, d, i, j] = stack.back();
    stack.pop_back();
    if (d >= n) continue;
    double e = 0;
    for (const auto& model : errors)
      e = std::max(e, model.errors[p][d][static_cast<std::size_t>(j) * (1u << d) + i]);
    if (e > options.epsilon) {
      set_leaf_depth(tree, p, d, i, j, d + 1);
      for (int c = 0; c < 4; ++c) stack.push_back({p, d + 1, 2 * i + (c & 1), 2 * j + (c >> 1)});
    } else {
      set_leaf_depth(tree, p, d, i, j, d);
    }
  }
  if (options.restrict_levels) restrict_quadtree(tree);
  return tree;
}

TriMesh adaptive_remesh(const GeometryImages& images, const AdaptiveQuadtree& tree) {
  const int n = tree.max_depth;
  if (images.geometry.size() != tree.depth.size() || images.geometry.empty()) {
    throw InvalidInput("adaptive_remesh: the images and the tree differ in patch count");
  }
  for (const auto& g : images.geometry) {
    if (g.level != n || g.values.size() != 3 * static_cast<std::size_t>(g.size()) * g.size()) {
      throw InvalidInput("adaptive_remesh: geometry images not of the tree's level " + std::to_string(n));
    }
  }
  check_adjacency(tree.adjacency, tree.depth.size(), "adaptive_remesh");
  // Welded ids of every level-n sample (seam samples joined through the SideLinks).
  const UniformRemeshResult grid = uniform_remesh_connectivity(tree.depth.size(), tree.adjacency, n);
  const int size = (1 << n) + 1;
  std::vector<int> compact(grid.mesh.positions.size(), -1);
  TriMesh mesh;
  auto vertex = [&](int p, int x, int y) {
    const int welded = grid.grid_vertex[p][static_cast<std::size_t>(y) * size + x];
    if (compact[welded] < 0) {
      compact[welded] = static_cast<int>(mesh.positions.size());
      mesh.positions.push_back(images.geometry[p].sample(x, y).cast<double>());
    }
    return compact[welded];
  };
  for (const AdaptiveQuadtree::Leaf& leaf : tree.leaves()) {
    std::array<bool, 4> finer{};
    for (int side = 0; side < 4; ++side) {
      const int deepest = max_neighbour_depth(tree, leaf, side);
      if (deepest > leaf.depth + 1) {
        throw InvalidInput("adaptive_remesh: the quadtree is not restricted (run restrict_quadtree)");
      }
      finer[side] = deepest == leaf.depth + 1;
    }
    const int span = 1 << (n - leaf.depth);
    const int x0 = leaf.i * span, y0 = leaf.j * span, x1 = x0 + span, y1 = y0 + span;
    const int p = leaf.patch;
    if (!finer[0] && !finer[1] && !finer[2] && !finer[3]) {
      const int a = vertex(p, x0, y0), b = vertex(p, x1, y0), c = vertex(p, x1, y1), d = vertex(p, x0, y1);
      if ((leaf.i + leaf.j + p) % 2 == 0) {
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      } else {
        mesh.triangles.push_back({a, b, d});
        mesh.triangles.push_back({b, c, d});
      }
      continue;
    }
    // Fan from the centre over the counter-clockwise boundary: corners and the midpoints of finer sides.
    const int h = span / 2;
    std::vector<int> ring;
    ring.push_back(vertex(p, x0, y0));
    if (finer[0]) ring.push_back(vertex(p, x0 + h, y0));
    ring.push_back(vertex(p, x1, y0));
    if (finer[1]) ring.push_back(vertex(p, x1, y0 + h));
    ring.push_back(vertex(p, x1, y1));
    if (finer[2]) ring.push_back(vertex(p, x0 + h, y1));
    ring.push_back(vertex(p, x0, y1));
    if (finer[3]) ring.push_back(vertex(p, x0, y0 + h));
    const int centre = vertex(p, x0 + h, y0 + h);
    for (std::size_t k = 0; k < ring.size(); ++k) {
      mesh.triangles.push_back({centre, ring[k], ring[(k + 1) % ring.size()]});
    }
  }
  return mesh;
}

}  // namespace geomip
