#include "gimage/resample.h"

#include "mesh/errors.h"
#include "mesh/predicates.h"
#include "param/unit_square.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <string>

namespace geomip {
namespace {

// Is `p` inside triangle edge a→b's closed left half-plane, ties broken by the symbolic perturbation
// p + ε·(sx, sy·η) (ε ≫ η > 0 infinitesimal)? The same perturbation for every triangle at p makes the inside
// test a partition: each p in the (perturbed-into-the-square) domain is in exactly one triangle.
inline bool left_of(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p, int sx,
                    int sy) {
  const int o = orient2d(a, b, p);
  if (o != 0) return o > 0;
  // cross(b − a, (sx, sy·η)) = (bx−ax)·sy·η − (by−ay)·sx
  if (b.y() != a.y()) return (b.y() > a.y() ? -sx : sx) > 0;
  return (b.x() > a.x() ? sy : -sy) > 0;
}

using Attribute = std::vector<Eigen::Vector3d>;  // per mesh vertex

inline void store(float* out, const Eigen::Vector3d& v, bool renormalize) {
  Eigen::Vector3d w = v;
  if (renormalize) {
    const double len = w.norm();
    w = len > 0 ? Eigen::Vector3d(w / len) : Eigen::Vector3d(0, 0, 1);
  }
  out[0] = static_cast<float>(w.x());
  out[1] = static_cast<float>(w.y());
  out[2] = static_cast<float>(w.z());
}

// Rasterizes the (u,v) triangles of `patch` onto the level-`level` grid and calls
// claim(i, j, triangle, wa, wb, wc) for every (sample, claiming triangle), with the sample's (unnormalized)
// barycentric weights. Triangles with (u,v) area <= 0 claim nothing.
template <typename Claim>
void rasterize(const PatchParameterization& patch, int level, Claim&& claim) {
  const int intervals = 1 << level;
  const double h = std::ldexp(1.0, -level);
  for (std::size_t tri = 0; tri < patch.triangles.size(); ++tri) {
    const auto& t = patch.triangles[tri];
    const Eigen::Vector2d& a = patch.uv[t[0]];
    const Eigen::Vector2d& b = patch.uv[t[1]];
    const Eigen::Vector2d& c = patch.uv[t[2]];
    if (orient2d(a, b, c) <= 0) continue;  // flipped or degenerate: claims nothing
    const double umin = std::min({a.x(), b.x(), c.x()}), umax = std::max({a.x(), b.x(), c.x()});
    const double vmin = std::min({a.y(), b.y(), c.y()}), vmax = std::max({a.y(), b.y(), c.y()});
    const int i0 = std::max(0, static_cast<int>(std::ceil(umin * intervals)));
    const int i1 = std::min(intervals, static_cast<int>(std::floor(umax * intervals)));
    const int j0 = std::max(0, static_cast<int>(std::ceil(vmin * intervals)));
    const int j1 = std::min(intervals, static_cast<int>(std::floor(vmax * intervals)));
    for (int j = j0; j <= j1; ++j) {
      const int sy = 2 * j < intervals ? 1 : -1;  // perturb toward the square's centre
      for (int i = i0; i <= i1; ++i) {
        const int sx = 2 * i < intervals ? 1 : -1;
        const Eigen::Vector2d p(i * h, j * h);
        if (!left_of(a, b, p, sx, sy) || !left_of(b, c, p, sx, sy) || !left_of(c, a, p, sx, sy)) continue;
        const Eigen::Vector2d pa = a - p, pb = b - p, pc = c - p;
        claim(i, j, static_cast<int>(tri), pb.x() * pc.y() - pb.y() * pc.x(),
              pc.x() * pa.y() - pc.y() * pa.x(), pa.x() * pb.y() - pa.y() * pb.x());
      }
    }
  }
}

// Resamples one patch: every sample claimed by a (u,v) triangle gets its barycentric interpolation. Returns
// the number of unclaimed samples, which are then filled from their nearest claimed neighbour on the grid.
std::size_t rasterize_patch(const PatchParameterization& patch, const Attribute& attribute, bool renormalize,
                            GeometryImage& image) {
  const int n = image.size();
  std::vector<char> claimed(static_cast<std::size_t>(n) * n, 0);
  rasterize(patch, image.level, [&](int i, int j, int tri, double wa, double wb, double wc) {
    const auto& t = patch.triangles[tri];
    const Eigen::Vector3d v = (wa * attribute[patch.vertices[t[0]]] + wb * attribute[patch.vertices[t[1]]] +
                               wc * attribute[patch.vertices[t[2]]]) /
                              (wa + wb + wc);
    store(image.at(i, j), v, renormalize);
    claimed[static_cast<std::size_t>(j) * n + i] = 1;
  });
  // Unclaimed samples (only with flipped or degenerate triangles): breadth-first fill from claimed ones.
  std::deque<int> queue;
  std::size_t unclaimed = 0;
  for (int k = 0; k < n * n; ++k) {
    if (claimed[k])
      queue.push_back(k);
    else
      ++unclaimed;
  }
  if (unclaimed == 0) return 0;
  if (queue.empty()) {
    throw InvalidInput("resample_geometry: a patch has no triangle with positive (u,v) area");
  }
  while (!queue.empty()) {
    const int k = queue.front();
    queue.pop_front();
    const int i = k % n, j = k / n;
    const int next[4][2] = {{i + 1, j}, {i - 1, j}, {i, j + 1}, {i, j - 1}};
    for (const auto& q : next) {
      if (q[0] < 0 || q[0] >= n || q[1] < 0 || q[1] >= n) continue;
      const int kk = q[1] * n + q[0];
      if (claimed[kk]) continue;
      claimed[kk] = 1;
      std::copy(image.at(i, j), image.at(i, j) + 3, image.at(q[0], q[1]));
      queue.push_back(kk);
    }
  }
  return unclaimed;
}

// The varying (u,v) coordinate along side s (u on sides 0 and 2, v on sides 1 and 3).
inline double along_coordinate(const Eigen::Vector2d& uv, int s) {
  return (s % 2 == 0) ? uv.x() : uv.y();
}

// Walks side s of `patch` in its varying coordinate and writes its 2^level + 1 samples in place (the
// interpolation the boundary triangle would give, restricted to its boundary edge; corners exactly).
void walk_side(const PatchParameterization& patch, const std::vector<int>& local, int s,
               const Attribute& attribute, bool renormalize, GeometryImage& image, const std::string& where) {
  const std::vector<int>& side = patch.sides[s];
  if (side.size() < 2 || side.front() != patch.corners[s] || side.back() != patch.corners[(s + 1) % 4]) {
    throw InvalidInput("resample_geometry: " + where + " does not run from its corner to the next");
  }
  std::vector<double> coord(side.size());
  for (std::size_t m = 0; m < side.size(); ++m) {
    const int l = side[m] >= 0 && side[m] < static_cast<int>(local.size()) ? local[side[m]] : -1;
    if (l < 0) throw InvalidInput("resample_geometry: " + where + " has a vertex outside the patch");
    coord[m] = along_coordinate(patch.uv[l], s);
  }
  const bool increasing = s < 2;
  for (std::size_t m = 1; m < coord.size(); ++m) {
    if (increasing ? !(coord[m] > coord[m - 1]) : !(coord[m] < coord[m - 1])) {
      throw InvalidInput("resample_geometry: " + where + " is not monotone in (u,v)");
    }
  }
  const int intervals = 1 << image.level;
  const double h = std::ldexp(1.0, -image.level);
  std::size_t m = 0;  // current segment [m, m+1]
  for (int k = 0; k <= intervals; ++k) {
    const auto [i, j] = side_grid_index(s, k, intervals);
    float* out = image.at(i, j);
    if (k == 0) {
      store(out, attribute[side.front()], renormalize);
      continue;
    }
    if (k == intervals) {
      store(out, attribute[side.back()], renormalize);
      continue;
    }
    const double cc = ((s % 2 == 0) ? i : j) * h;  // the sample's varying coordinate
    while (m + 2 < coord.size() && (increasing ? coord[m + 1] < cc : coord[m + 1] > cc)) ++m;
    const double t = (cc - coord[m]) / (coord[m + 1] - coord[m]);
    const Eigen::Vector3d& v0 = attribute[side[m]];
    const Eigen::Vector3d& v1 = attribute[side[m + 1]];
    store(out, t == 0.0 ? v0 : t == 1.0 ? v1 : Eigen::Vector3d(v0 + t * (v1 - v0)), renormalize);
  }
}

void check_patch(const PatchParameterization& p, std::size_t num_vertices, const std::string& where) {
  if (p.uv.size() != p.vertices.size()) throw InvalidInput(where + ": uv and vertices differ in size");
  for (int v : p.vertices) {
    if (v < 0 || static_cast<std::size_t>(v) >= num_vertices) {
      throw InvalidInput(where + ": vertex id out of range");
    }
  }
  for (const auto& t : p.triangles) {
    for (int c : t) {
      if (c < 0 || static_cast<std::size_t>(c) >= p.vertices.size()) {
        throw InvalidInput(where + ": triangle index out of range");
      }
    }
  }
}

// All patches of `model` at `level`, with shared sides computed once and copied.
std::vector<GeometryImage> resample_attribute(const ModelParameterization& model, const Attribute& attribute,
                                              int level, bool renormalize, std::size_t& uncovered) {
  const std::size_t num_patches = model.patches.size();
  std::vector<GeometryImage> images(num_patches);
  const int intervals = 1 << level;
  std::vector<int> local(model.mesh.positions.size(), -1);
  for (std::size_t p = 0; p < num_patches; ++p) {
    const PatchParameterization& patch = model.patches[p];
    images[p].level = level;
    images[p].values.assign(3 * static_cast<std::size_t>(images[p].size()) * images[p].size(), 0.0f);
    uncovered += rasterize_patch(patch, attribute, renormalize, images[p]);
    for (std::size_t l = 0; l < patch.vertices.size(); ++l) local[patch.vertices[l]] = static_cast<int>(l);
    for (int s = 0; s < 4; ++s) {
      const std::size_t key = 4 * p + s;
      const bool linked = key < model.adjacency.size();
      if (linked) {
        const SideLink& link = model.adjacency[key];
        if (4 * link.other_patch + link.other_side < static_cast<int>(key)) continue;  // copied below
      }
      walk_side(patch, local, s, attribute, renormalize, images[p],
                "patch " + std::to_string(p) + " side " + std::to_string(s));
    }
    for (int v : patch.vertices) local[v] = -1;
  }
  // Copy each shared side from its canonical (smaller) owner.
  for (std::size_t key = 0; key < model.adjacency.size(); ++key) {
    const SideLink& link = model.adjacency[key];
    const int from = 4 * link.other_patch + link.other_side;
    if (from >= static_cast<int>(key)) continue;
    const GeometryImage& src = images[link.other_patch];
    GeometryImage& dst = images[link.patch];
    for (int k = 0; k <= intervals; ++k) {
      const auto [si, sj] = side_grid_index(link.other_side, link.reversed ? intervals - k : k, intervals);
      const auto [di, dj] = side_grid_index(link.side, k, intervals);
      std::copy(src.at(si, sj), src.at(si, sj) + 3, dst.at(di, dj));
    }
  }
  return images;
}

}  // namespace

GridLocation locate_grid_samples(const PatchParameterization& patch, int level) {
  if (level < 0 || level > kMaxGeometryImageLevel) {
    throw InvalidInput("locate_grid_samples: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  check_patch(patch, std::numeric_limits<std::size_t>::max(), "locate_grid_samples: the patch");
  GridLocation location;
  location.level = level;
  const int n = (1 << level) + 1;
  location.triangle.assign(static_cast<std::size_t>(n) * n, -1);
  location.claims.assign(static_cast<std::size_t>(n) * n, 0);
  rasterize(patch, level, [&](int i, int j, int tri, double, double, double) {
    const std::size_t k = static_cast<std::size_t>(j) * n + i;
    if (location.triangle[k] < 0) location.triangle[k] = tri;
    if (location.claims[k] < 255) ++location.claims[k];
  });
  return location;
}

std::vector<Eigen::Vector3d> area_weighted_vertex_normals(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d n =
        (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (int c : t) normals[c] += n;
  }
  for (auto& n : normals) {
    const double len = n.norm();
    n = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d(0, 0, 1);
  }
  return normals;
}

GeometryImages resample_geometry(const ModelParameterization& model, int level,
                                 const ResampleOptions& options) {
  if (level < 0 || level > kMaxGeometryImageLevel) {
    throw InvalidInput("resample_geometry: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  if (model.patches.empty()) throw InvalidInput("resample_geometry: the model has no patches");
  const int normal_level =
      options.normal_level < 0 ? std::min(level + 1, kMaxGeometryImageLevel) : options.normal_level;
  if (options.normals && (normal_level < level || normal_level > kMaxGeometryImageLevel)) {
    throw InvalidInput("resample_geometry: normal level " + std::to_string(normal_level) + " is outside [" +
                       std::to_string(level) + ", " + std::to_string(kMaxGeometryImageLevel) + "]");
  }
  const std::size_t num_patches = model.patches.size();
  for (std::size_t p = 0; p < num_patches; ++p) {
    check_patch(model.patches[p], model.mesh.positions.size(),
                "resample_geometry: patch " + std::to_string(p));
  }
  if (!model.adjacency.empty() && model.adjacency.size() != 4 * num_patches) {
    throw InvalidInput("resample_geometry: adjacency must have 4 entries per patch");
  }
  for (std::size_t key = 0; key < model.adjacency.size(); ++key) {
    const SideLink& link = model.adjacency[key];
    if (link.patch != static_cast<int>(key / 4) || link.side != static_cast<int>(key % 4) ||
        link.other_patch < 0 || link.other_patch >= static_cast<int>(num_patches) || link.other_side < 0 ||
        link.other_side > 3) {
      throw InvalidInput("resample_geometry: adjacency entry " + std::to_string(key) +
                         " is out of place or range");
    }
    const SideLink& back = model.adjacency[4 * link.other_patch + link.other_side];
    std::vector<int> a = model.patches[link.patch].sides[link.side];
    const std::vector<int>& b = model.patches[link.other_patch].sides[link.other_side];
    if (link.reversed) std::reverse(a.begin(), a.end());
    if (back.other_patch != link.patch || back.other_side != link.side || back.reversed != link.reversed ||
        a != b) {
      throw InvalidInput("resample_geometry: adjacency entry " + std::to_string(key) +
                         " glues sides that are not the same mesh path");
    }
  }

  GeometryImages result;
  result.adjacency = model.adjacency;
  result.geometry = resample_attribute(model, model.mesh.positions, level, false, result.uncovered_samples);
  if (options.normals) {
    const Attribute normals = area_weighted_vertex_normals(model.mesh);
    std::size_t uncovered_normals = 0;  // the same triangles, a finer grid: not counted again
    result.normals = resample_attribute(model, normals, normal_level, true, uncovered_normals);
  }
  return result;
}

}  // namespace geomip
