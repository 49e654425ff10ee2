#include "param/quad_layout.h"

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "mesh/predicates.h"
#include "param/geodesic_peaks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace geomip {
namespace {

const char* const kFn = "choose_quad_layout: ";

// Σ (A_q / Ā)² / K over the patches of `stats` (Ā the mean area): 1 when every patch has the same area,
// larger the more the areas spread. With the same grid on every patch, a patch's squared resampling
// error grows like its area squared, so this is the quantity that balancing lowers.
double area_spread(const PartitionStats& stats) {
  double total = 0.0, squares = 0.0;
  for (const auto& p : stats.patches) {
    total += p.area;
    squares += p.area * p.area;
  }
  const double k = static_cast<double>(stats.patches.size());
  return squares * k / (total * total);
}

// K · Σ A_q² / (flatness_q · A²) (A the total area): an estimate of the squared resampling error of a
// layout whose patches all get the same grid, relative to K equal flat squares (1). A patch's squared error
// grows like A_q² · σ_q² (σ_q its L2 stretch), and σ_q² grows like 1 / flatness_q (a patch that wraps around
// a leg or an ear folds more of its area onto the same square): on the horse's 8-patch layout σ_q² and
// 1 / flatness_q agree within a factor of 2 for 6 of its 8 patches (docs/measurements.md).
double sampling_cost(const PartitionStats& stats) {
  double total = 0.0, cost = 0.0;
  for (const auto& p : stats.patches) {
    total += p.area;
    cost += p.area * p.area / std::max(p.flatness, 0.05);
  }
  return cost * static_cast<double>(stats.patches.size()) / (total * total);
}

// What a layout is ranked by: the area / sampling term of `stats` plus the shape penalty of `partition`.
using Objective = std::function<double(const PartitionResult&, const PartitionStats&)>;

// The shape of each patch of `partition`: the 3D angle sum of its triangles at each of its 4 corners and the
// 3D length of each side over sqrt(its area). Both bound the L∞ stretch of any map of the patch to the
// square with the corners on the square's corners: side k lies on a unit edge, so some boundary edge is
// stretched by at least L_k / sqrt(A) (docs/measurements.md, "L∞ stretch per patch"), and a corner whose
// surface angle is far above 90° is squeezed into the square's 90° wedge.
struct PatchShape {
  std::array<double, 4> corner_angle{};  // radians
  std::array<double, 4> side_ratio{};    // side length / sqrt(area)
};

std::vector<PatchShape> patch_shapes(const PartitionResult& partition) {
  const auto& pm = partition.mesh;
  std::vector<PatchShape> shapes(partition.patches.size());
  for (std::size_t q = 0; q < partition.patches.size(); ++q) {
    const Patch& patch = partition.patches[q];
    double area = 0.0;
    for (int f : patch.faces) {
      const auto& t = pm.triangles[f];
      const Eigen::Vector3d e1 = pm.positions[t[1]] - pm.positions[t[0]], e2 = pm.positions[t[2]] - pm.positions[t[0]];
      area += 0.5 * e1.cross(e2).norm();
      for (int j = 0; j < 3; ++j) {
        for (int c = 0; c < 4; ++c) {
          if (t[j] != patch.corners[c]) continue;
          const Eigen::Vector3d u = pm.positions[t[(j + 1) % 3]] - pm.positions[t[j]],
                                v = pm.positions[t[(j + 2) % 3]] - pm.positions[t[j]];
          shapes[q].corner_angle[c] += std::atan2(u.cross(v).norm(), u.dot(v));
        }
      }
    }
    for (int s = 0; s < 4; ++s) {
      const auto& path = patch.sides[s].vertices;
      double length = 0.0;
      for (std::size_t i = 1; i < path.size(); ++i)
        length += (pm.positions[path[i]] - pm.positions[path[i - 1]]).norm();
      shapes[q].side_ratio[s] = area > 0.0 ? length / std::sqrt(area) : 0.0;
    }
  }
  return shapes;
}

// Σ over patches of Σ_corners (max(0, angle − max_angle) / 90°)² + Σ_sides max(0, ratio − max_ratio)² +
// (max(0, min_flatness − flatness) / 0.25)²: 0 when every corner, side and patch is within the bounds.
double shape_penalty(const std::vector<PatchShape>& shapes, const PartitionStats& stats, const QuadLayoutOptions& o) {
  const double max_angle = o.max_corner_angle_deg * M_PI / 180.0;
  double penalty = 0.0;
  for (std::size_t q = 0; q < shapes.size(); ++q) {
    const PatchShape& s = shapes[q];
    const double f = std::max(0.0, o.min_flatness - stats.patches[q].flatness) / 0.25;
    penalty += f * f;
    for (int k = 0; k < 4; ++k) {
      const double a = std::max(0.0, s.corner_angle[k] - max_angle) / (0.5 * M_PI);
      const double r = std::max(0.0, s.side_ratio[k] - o.max_side_ratio);
      penalty += a * a + r * r;
    }
  }
  return penalty;
}

// Half-edge collapses on a closed manifold triangle mesh, shortest edge first, vertices never moved.
class Simplifier {
 public:
  // `centroid_rule`: of two merged vertices the one nearer their area's centroid stays; else the one that
  // stands for more area. `error_weight` > 0: collapses by error and area instead (QuadLayoutOptions), either
  // vertex may stay, `centroid_rule` unused.
  // `pinned` vertices are never collapsed away (they stay coarse vertices); may be empty.
  Simplifier(const TriMesh& mesh, bool centroid_rule, const std::vector<int>& pinned, double error_weight)
      : m_(mesh), centroid_rule_(centroid_rule), error_weight_(error_weight) {
    pinned_.assign(m_.positions.size(), 0);
    for (int v : pinned) pinned_[v] = 1;
    vf_.resize(m_.positions.size());
    for (int f = 0; f < static_cast<int>(m_.triangles.size()); ++f) {
      for (int v : m_.triangles[f]) vf_[v].push_back(f);
    }
    face_alive_.assign(m_.triangles.size(), 1);
    stamp_.assign(m_.positions.size(), 0);
    carried_.assign(m_.positions.size(), 0.0);
    moment_.assign(m_.positions.size(), Eigen::Vector3d::Zero());
    const bool by_error = error_weight_ > 0.0;
    if (by_error) {  // quadrics only when they rank the collapses (128 bytes a vertex)
      quadric_.assign(m_.positions.size(), Eigen::Matrix4d::Zero());
      Eigen::AlignedBox3d box;
      for (const auto& q : m_.positions) box.extend(q);
      diagonal2_ = box.isEmpty() ? 1.0 : std::max(box.diagonal().squaredNorm(), 1e-300);
    }
    for (const auto& t : m_.triangles) {
      const Eigen::Vector3d n = normal(t);
      const double a = 0.5 * n.norm();
      total_area_ += a;
      Eigen::Matrix4d q = Eigen::Matrix4d::Zero();
      if (by_error && a > 0.0) {
        Eigen::Vector4d plane;
        plane.head<3>() = n.normalized();
        plane[3] = -plane.head<3>().dot(m_.positions[t[0]]);
        q = (a / 3.0) * plane * plane.transpose();
      }
      for (int v : t) {
        carried_[v] += n.norm() / 6.0;
        moment_[v] += n.norm() / 6.0 * m_.positions[v];
        if (by_error) quadric_[v] += q;
      }
    }
    for (int v = 0; v < static_cast<int>(vf_.size()); ++v) {
      if (!vf_[v].empty()) ++alive_;
    }
  }

  // Collapses until `target` vertices remain; false when no legal collapse is left before that. When only
  // collapses that turn a normal by 90° or more are left, they are allowed (the coarse mesh only guides the
  // layout; the link condition keeps it a closed manifold).
  bool simplify_to(std::size_t target) {
    for (int v = 0; v < static_cast<int>(vf_.size()); ++v) push_edges(v);
    while (alive_ > target) {
      if (heap_.empty() && check_normals_) {
        check_normals_ = false;
        for (int v = 0; v < static_cast<int>(vf_.size()); ++v) push_edges(v);
      }
      if (heap_.empty()) return false;
      const Entry e = heap_.top();
      heap_.pop();
      if (e.stamp_u != stamp_[e.u] || e.stamp_v != stamp_[e.v] || vf_[e.u].empty() || vf_[e.v].empty())
        continue;
      if (!legal(e.u, e.v)) continue;  // re-pushed when a neighbour changes
      collapse(e.u, e.v);
    }
    return true;
  }

  // The coarse mesh: its triangles (original vertex ids), counter-clockwise.
  std::vector<std::array<int, 3>> triangles() const {
    std::vector<std::array<int, 3>> t;
    for (std::size_t f = 0; f < m_.triangles.size(); ++f) {
      if (face_alive_[f]) t.push_back(m_.triangles[f]);
    }
    return t;
  }

 private:
  struct Entry {
    double cost;
    int u, v;  // collapse u into v
    std::uint32_t stamp_u, stamp_v;
    bool operator<(const Entry& o) const {  // max-heap: invert for the cheapest, ties by ids
      return std::tie(cost, u, v) > std::tie(o.cost, o.u, o.v);
    }
  };

  std::vector<int> neighbours(int u) const {
    std::vector<int> n;
    for (int f : vf_[u]) {
      for (int w : m_.triangles[f]) {
        if (w != u) n.push_back(w);
      }
    }
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    return n;
  }

  Eigen::Vector3d normal(const std::array<int, 3>& t) const {
    const auto& p = m_.positions;
    return (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
  }

  // The link condition (u and v share exactly the two wing vertices) and no normal turned by ≥ 90°.
  bool legal(int u, int v) const {
    const std::vector<int> nu = neighbours(u), nv = neighbours(v);
    if (!std::binary_search(nu.begin(), nu.end(), v)) return false;
    std::vector<int> common;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    if (common.size() != 2) return false;
    for (int f : vf_[u]) {
      if (!check_normals_) break;
      std::array<int, 3> t = m_.triangles[f];
      if (std::find(t.begin(), t.end(), v) != t.end()) continue;
      const Eigen::Vector3d before = normal(t);
      for (int& w : t) {
        if (w == u) w = v;
      }
      const Eigen::Vector3d after = normal(t);
      if (!(after.dot(before) > 0.0)) return false;
    }
    return true;
  }

  void collapse(int u, int v) {
    for (int f : vf_[u]) {
      auto& t = m_.triangles[f];
      if (std::find(t.begin(), t.end(), v) != t.end()) {
        face_alive_[f] = 0;
        for (int w : t) {
          if (w == u) continue;
          auto& list = vf_[w];
          list.erase(std::remove(list.begin(), list.end(), f), list.end());
        }
      } else {
        for (int& w : t) {
          if (w == u) w = v;
        }
        vf_[v].push_back(f);
      }
    }
    vf_[u].clear();
    carried_[v] += carried_[u];
    moment_[v] += moment_[u];
    if (!quadric_.empty()) quadric_[v] += quadric_[u];
    --alive_;
    const std::vector<int> around = neighbours(v);
    ++stamp_[v];
    for (int w : around) ++stamp_[w];
    push_edges(v);
    for (int w : around) push_edges(w);
  }

  // Cost of merging u into v: the surface area the two vertices then stand for (each vertex starts with a
  // third of its star's area and inherits the area of the vertices merged into it). Merging the smallest
  // pair first is greedy clustering into equal areas: every coarse vertex stands for a similar share of
  // the surface, so the coarse triangles, hence the patches, get similar areas. The vertex nearer the
  // merged area's centroid stays, so coarse vertices sit near the middle of what they stand for.
  void push_edges(int u) {
    for (int v : neighbours(u)) {
      const double merged = carried_[u] + carried_[v];
      const Eigen::Vector3d centre = (moment_[u] + moment_[v]) / merged;
      if (pinned_[u]) continue;  // a pinned vertex stays
      if (error_weight_ > 0.0) {
        // Equal error: the quadric error of the merged vertex kept where v is (Garland–Heckbert 1997: Σ of
        // area-weighted squared distances to the planes of the triangles merged into u and v), over the
        // total area and the squared diagonal, plus the merged area's share squared.
        const Eigen::Vector4d x(m_.positions[v].x(), m_.positions[v].y(), m_.positions[v].z(), 1.0);
        const double error = x.dot((quadric_[u] + quadric_[v]) * x) / (total_area_ * diagonal2_);
        const double share = merged / total_area_;
        heap_.push({error_weight_ * error + share * share, u, v, stamp_[u], stamp_[v]});
        continue;
      }
      if (!pinned_[v]) {
        const double du = (m_.positions[u] - centre).squaredNorm(),
                     dv = (m_.positions[v] - centre).squaredNorm();
        if (centroid_rule_) {
          if (dv > du || (dv == du && v > u)) continue;  // the vertex nearer the merged area's centroid stays
        } else if (carried_[u] > carried_[v] || (carried_[u] == carried_[v] && v > u)) {
          continue;  // the vertex that stands for more area stays
        }
      }
      heap_.push({merged, u, v, stamp_[u], stamp_[v]});
    }
  }

  TriMesh m_;
  std::vector<std::vector<int>> vf_;
  std::vector<char> pinned_;
  std::vector<char> face_alive_;
  std::vector<std::uint32_t> stamp_;
  std::vector<double> carried_;          // surface area each vertex stands for
  std::vector<Eigen::Vector3d> moment_;  // Σ area · position over that area
  std::vector<Eigen::Matrix4d> quadric_;  // Σ (area / 3) · plane planeᵀ over the triangles around the
                                          // vertices merged in; by error only
  double total_area_ = 0.0;
  double diagonal2_ = 1.0;  // squared bounding-box diagonal
  std::size_t alive_ = 0;
  bool check_normals_ = true;
  bool centroid_rule_ = true;
  double error_weight_ = 0.0;
  std::priority_queue<Entry> heap_;
};

// Delaunay edge flips on the coarse mesh (in 3D: an edge is flipped when the two angles opposite it sum to
// more than π and the new edge does not exist yet), so that its edges, later traced as shortest paths, join
// near corners and its triangles are not slivers. At most 50 flips per triangle (3D angles need not
// converge as in the plane).
void delaunay_flips(const std::vector<Eigen::Vector3d>& p, std::vector<std::array<int, 3>>& t) {
  auto angle = [&](int at, int a, int b) {
    const Eigen::Vector3d u = p[a] - p[at], v = p[b] - p[at];
    return std::atan2(u.cross(v).norm(), u.dot(v));
  };
  const std::size_t budget = 50 * t.size() + 100;
  for (std::size_t flips = 0; flips < budget;) {
    std::unordered_map<std::uint64_t, int> by_edge;
    for (int f = 0; f < static_cast<int>(t.size()); ++f) {
      for (int j = 0; j < 3; ++j) by_edge[directed_edge_key(t[f][j], t[f][(j + 1) % 3])] = f;
    }
    bool flipped = false;
    for (int f = 0; f < static_cast<int>(t.size()) && !flipped; ++f) {
      for (int j = 0; j < 3 && !flipped; ++j) {
        const int x = t[f][j], y = t[f][(j + 1) % 3], z = t[f][(j + 2) % 3];
        const auto it = by_edge.find(directed_edge_key(y, x));
        if (it == by_edge.end()) continue;
        const int g = it->second;
        int w = -1;
        for (int v : t[g]) {
          if (v != x && v != y) w = v;
        }
        if (w < 0 || w == z || by_edge.count(directed_edge_key(z, w))) continue;
        if (angle(z, x, y) + angle(w, y, x) <= M_PI + 1e-9) continue;
        t[f] = {x, w, z};
        t[g] = {w, y, z};
        flipped = true;
        ++flips;
      }
    }
    if (!flipped) break;
  }
}

// Maximum matching in a general graph: Edmonds' blossom algorithm, completing `match` (−1 = unmatched) by
// augmenting paths. O(V³).
class BlossomMatcher {
 public:
  BlossomMatcher(const std::vector<std::vector<int>>& graph, std::vector<int>& match)
      : g_(graph), match_(match), n_(static_cast<int>(graph.size())) {}

  void run() {
    for (int root = 0; root < n_; ++root) {
      if (match_[root] >= 0) continue;
      int v = find_path(root);
      while (v >= 0) {  // augment along parent links
        const int pv = parent_[v], ppv = match_[pv];
        match_[v] = pv;
        match_[pv] = v;
        v = ppv;
      }
    }
  }

 private:
  int lca(int a, int b) {
    std::vector<char> seen(n_, 0);
    for (;;) {
      a = base_[a];
      seen[a] = 1;
      if (match_[a] < 0) break;
      a = parent_[match_[a]];
    }
    for (;;) {
      b = base_[b];
      if (seen[b]) return b;
      b = parent_[match_[b]];
    }
  }

  void mark_path(int v, int b, int child) {
    while (base_[v] != b) {
      blossom_[base_[v]] = blossom_[base_[match_[v]]] = 1;
      parent_[v] = child;
      child = match_[v];
      v = parent_[match_[v]];
    }
  }

  int find_path(int root) {
    used_.assign(n_, 0);
    parent_.assign(n_, -1);
    base_.resize(n_);
    for (int i = 0; i < n_; ++i) base_[i] = i;
    used_[root] = 1;
    std::queue<int> q;
    q.push(root);
    while (!q.empty()) {
      const int v = q.front();
      q.pop();
      for (int to : g_[v]) {
        if (base_[v] == base_[to] || match_[v] == to) continue;
        if (to == root || (match_[to] >= 0 && parent_[match_[to]] >= 0)) {
          const int b = lca(v, to);
          blossom_.assign(n_, 0);
          mark_path(v, b, to);
          mark_path(to, b, v);
          for (int i = 0; i < n_; ++i) {
            if (blossom_[base_[i]]) {
              base_[i] = b;
              if (!used_[i]) {
                used_[i] = 1;
                q.push(i);
              }
            }
          }
        } else if (parent_[to] < 0) {
          parent_[to] = v;
          if (match_[to] < 0) return to;
          used_[match_[to]] = 1;
          q.push(match_[to]);
        }
      }
    }
    return -1;
  }

  const std::vector<std::vector<int>>& g_;
  std::vector<int>& match_;
  int n_;
  std::vector<int> parent_, base_;
  std::vector<char> used_, blossom_;
};

// The quad of triangles a and b, which share an edge: the shared edge x→y of a, a's third vertex z, b's w.
std::array<int, 4> quad_of(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (int k = 0; k < 3; ++k) {
    const int x = a[k], y = a[(k + 1) % 3], z = a[(k + 2) % 3];
    for (int j = 0; j < 3; ++j) {
      if (b[j] == y && b[(j + 1) % 3] == x) return {x, b[(j + 2) % 3], y, z};
    }
  }
  return {-1, -1, -1, -1};
}

// Renumbers the quads so that quads at a corner of only two quads come first in even slots, as
// check_quad_layout() asks (the remesh's diagonal rule); best effort, the check decides.
void even_quads_at_two_quad_corners(QuadLayout& layout) {
  std::vector<int> count(layout.corners.size(), 0);
  for (const auto& q : layout.quads) {
    for (int c : q) ++count[c];
  }
  std::vector<std::array<int, 4>> marked, rest;
  for (const auto& q : layout.quads) {
    const bool at_two = std::any_of(q.begin(), q.end(), [&](int c) { return count[c] == 2; });
    (at_two ? marked : rest).push_back(q);
  }
  if (marked.empty()) return;
  std::vector<std::array<int, 4>> order(layout.quads.size());
  std::vector<char> used(order.size(), 0);
  std::size_t slot = 0;
  for (const auto& q : marked) {
    if (slot >= order.size()) slot = 1;  // more marked quads than even slots: odd slots too
    order[slot] = q;
    used[slot] = 1;
    slot += 2;
  }
  std::size_t next = 0;
  for (const auto& q : rest) {
    while (used[next]) ++next;
    order[next] = q;
    used[next] = 1;
  }
  layout.quads = std::move(order);
}

// Pairs `coarse` (closed, 2k triangles over mesh vertices) into k quads by each greedy score completed to a
// perfect matching; every pairing that partitions `mesh` is measured and kept in `best` if more balanced.
void pair_coarse_triangles(const TriMesh& mesh, const PartitionMeshCache& cache,
                           const std::vector<std::array<int, 3>>& coarse, long long k,
                           const Objective& objective, QuadLayoutChoice& best, double& best_cost,
                           std::string& last_error) {
  const int nf = static_cast<int>(coarse.size());
  // Dual graph: triangles sharing an edge.
  std::unordered_map<std::uint64_t, int> by_edge;
  for (int f = 0; f < nf; ++f) {
    for (int j = 0; j < 3; ++j) by_edge[directed_edge_key(coarse[f][j], coarse[f][(j + 1) % 3])] = f;
  }
  std::vector<std::vector<int>> dual(nf);
  for (int f = 0; f < nf; ++f) {
    for (int j = 0; j < 3; ++j) {
      const auto it = by_edge.find(directed_edge_key(coarse[f][(j + 1) % 3], coarse[f][j]));
      if (it != by_edge.end()) dual[f].push_back(it->second);
    }
  }
  const auto& p = mesh.positions;
  auto normal = [&](const std::array<int, 3>& t) {
    return Eigen::Vector3d((p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]));
  };
  double total_area = 0.0;
  for (const auto& t : coarse) total_area += 0.5 * normal(t).norm();
  const double mean_quad = total_area / static_cast<double>(k);
  // Scores of pairing f with g (lower first): flatness, area near the mean, longest shared edge.
  const std::array<std::function<double(int, int)>, 3> scores = {
      [&](int f, int g) { return -normal(coarse[f]).normalized().dot(normal(coarse[g]).normalized()); },
      [&](int f, int g) {
        return std::abs(0.5 * (normal(coarse[f]).norm() + normal(coarse[g]).norm()) - mean_quad);
      },
      [&](int f, int g) {
        const auto q = quad_of(coarse[f], coarse[g]);
        return -(p[q[0]] - p[q[2]]).norm();
      }};
  for (const auto& score : scores) {
    std::vector<std::tuple<double, int, int>> pairs;
    for (int f = 0; f < nf; ++f) {
      for (int g : dual[f]) {
        if (f < g) pairs.emplace_back(score(f, g), f, g);
      }
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<int> match(nf, -1);
    for (const auto& [s, f, g] : pairs) {
      if (match[f] < 0 && match[g] < 0) {
        match[f] = g;
        match[g] = f;
      }
    }
    BlossomMatcher(dual, match).run();
    if (std::count(match.begin(), match.end(), -1) > 0) {
      last_error = "the coarse mesh's triangles cannot all be paired";
      continue;
    }
    QuadLayout layout;
    std::unordered_map<int, int> corner_of;
    for (int f = 0; f < nf; ++f) {
      if (match[f] < f) continue;
      std::array<int, 4> q = quad_of(coarse[f], coarse[match[f]]);
      for (int& v : q) {
        const auto [it, fresh] = corner_of.emplace(v, static_cast<int>(layout.corners.size()));
        if (fresh) layout.corners.push_back(v);
        v = it->second;
      }
      layout.quads.push_back(q);
    }
    even_quads_at_two_quad_corners(layout);
    try {
      const PartitionResult partition = partition_mesh_layout(cache, layout);
      const PartitionStats stats = partition_stats(partition);
      const double cost = objective(partition, stats);
      ++best.candidates;
      if (best.candidates == 1 || cost < best_cost) {
        best_cost = cost;
        best.layout = std::move(layout);
      }
    } catch (const InvalidInput& e) {
      last_error = e.what();
    }
  }
}

// The tips of the shape's protrusions (legs, ears, head, tail): the maxima of the geodesic distance (Dijkstra
// on the edge graph) from the vertex nearest the area centroid whose persistence (how far the distance
// falls from the maximum before its region of the superlevel set joins one with a higher maximum) is at
// least `min_persistence` times the largest distance, most persistent first, at most `max_tips`.
std::vector<int> protrusion_tips(const TriMesh& mesh, double min_persistence, std::size_t max_tips) {
  const int nv = static_cast<int>(mesh.positions.size());
  const std::vector<std::vector<int>> adj = vertex_neighbours(mesh);
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const double a = (mesh.positions[t[1]] - mesh.positions[t[0]])
                         .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                         .norm();
    moment += a * (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.0;
    area += a;
  }
  const Eigen::Vector3d centre = moment / area;
  int source = -1;
  for (int v = 0; v < nv; ++v) {
    if (adj[v].empty()) continue;
    if (source < 0 || (mesh.positions[v] - centre).squaredNorm() <
                          (mesh.positions[source] - centre).squaredNorm())
      source = v;
  }
  const std::vector<double> dist = geodesic_distance(mesh, adj, {source}).dist;
  // Superlevel-set persistence; the global maximum's is the largest distance.
  std::vector<std::pair<double, int>> maxima = persistent_peaks(adj, dist);  // (persistence, vertex)
  double top = 0.0;
  for (const auto& m : maxima) top = std::max(top, m.first);
  std::sort(maxima.begin(), maxima.end(), std::greater<>());
  std::vector<int> tips;
  for (const auto& [persistence, v] : maxima) {
    if (persistence < min_persistence * top || tips.size() >= max_tips) break;
    tips.push_back(v);
  }
  return tips;
}

// A layout with its partition, stats and objective.
struct EvaluatedLayout {
  QuadLayout layout;
  PartitionResult partition;
  PartitionStats stats;
  double cost = 0.0;
};

// Partitions `mesh` by `layout` and measures it; nullopt when the layout cuts the mesh into other regions
// than its quads (partition_mesh_layout() refuses it).
std::optional<EvaluatedLayout> evaluate_layout(const PartitionMeshCache& cache, const Objective& objective,
                                               QuadLayout layout) {
  try {
    EvaluatedLayout e;
    e.partition = partition_mesh_layout(cache, layout);
    e.stats = partition_stats(e.partition);
    e.cost = objective(e.partition, e.stats);
    e.layout = std::move(layout);
    return e;
  } catch (const InvalidInput&) {
    return std::nullopt;
  }
}

// Area centroid, area and (original mesh) vertices of every patch of `partition`.
struct PatchGeometry {
  std::vector<Eigen::Vector3d> centroid;
  std::vector<double> area;
  std::vector<std::vector<int>> verts;  // ascending
  double mean = 0.0;                    // mean patch area

  PatchGeometry(const TriMesh& mesh, const PartitionResult& partition, int nq)
      : centroid(nq, Eigen::Vector3d::Zero()), area(nq, 0.0), verts(nq) {
    const auto& pm = partition.mesh;
    for (std::size_t f = 0; f < pm.triangles.size(); ++f) {
      const auto& t = pm.triangles[f];
      const int q = partition.face_patch[f];
      const double a = 0.5 * (pm.positions[t[1]] - pm.positions[t[0]])
                                 .cross(pm.positions[t[2]] - pm.positions[t[0]])
                                 .norm();
      centroid[q] += a * (pm.positions[t[0]] + pm.positions[t[1]] + pm.positions[t[2]]) / 3.0;
      area[q] += a;
      for (int v : t) {
        if (v < static_cast<int>(mesh.positions.size())) verts[q].push_back(v);
      }
    }
    double total = 0.0;
    for (int q = 0; q < nq; ++q) {
      centroid[q] /= area[q];
      total += area[q];
      std::sort(verts[q].begin(), verts[q].end());
      verts[q].erase(std::unique(verts[q].begin(), verts[q].end()), verts[q].end());
    }
    mean = total / nq;
  }

  // The vertex of the patches `around` nearest `target` that is not `taken` (or is `own`); −1 if none.
  int snap(const TriMesh& mesh, const std::vector<int>& around, const Eigen::Vector3d& target,
           const std::vector<char>& taken, int own) const {
    int best_v = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int q : around) {
      for (int v : verts[q]) {
        if (taken[v] && v != own) continue;
        const double d = (mesh.positions[v] - target).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best_v = v;
        }
      }
    }
    return best_v;
  }
};

// Moves the corners of `layout` over the mesh so that its patches get more equal areas. A move takes a set
// of corners; each moves towards the area centroids of its larger neighbouring patches and away from its
// smaller ones (a corner moved into a patch takes area from it and gives it to the patches on its other
// sides), by `step` times the area-weighted sum of the directions, and lands on the nearest vertex of its
// neighbouring patches that is not another corner. A move is kept when the new layout partitions the mesh
// with a lower area_spread(). Each round tries all corners at once, then the corners of one patch at a time,
// the patch farthest from the mean area first (up to 3 patches); when nothing is kept the step is halved.
// At most `evaluations` partitions are tried. Returns the number of moves kept.
int relax_corners(const TriMesh& mesh, const PartitionMeshCache& cache, const Objective& objective,
                  const std::vector<int>& locked, QuadLayout& layout, PartitionResult& partition,
                  PartitionStats& stats, int evaluations) {
  const int nc = static_cast<int>(layout.corners.size());
  const int nq = static_cast<int>(layout.quads.size());
  std::vector<std::vector<int>> quads_at(nc);
  for (int q = 0; q < nq; ++q) {
    for (int c : layout.quads[q]) quads_at[c].push_back(q);
  }
  double spread = objective(partition, stats);
  double step = 0.5;
  int kept = 0, tried = 0;
  while (tried < evaluations && step > 0.03) {
    const PatchGeometry geometry(mesh, partition, nq);
    const auto& centroid = geometry.centroid;
    const auto& area = geometry.area;
    const double mean = geometry.mean;
    // The moves of this round: all corners, then each of the 3 patches farthest from the mean area.
    std::vector<int> order(nq);
    for (int q = 0; q < nq; ++q) order[q] = q;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      const double da = std::abs(area[a] - mean), db = std::abs(area[b] - mean);
      return da != db ? da > db : a < b;
    });
    std::vector<std::vector<int>> moves(1);
    for (int c = 0; c < nc; ++c) moves[0].push_back(c);
    for (int i = 0; i < std::min(nq, 3); ++i) {
      const auto& q = layout.quads[order[i]];
      moves.emplace_back(q.begin(), q.end());
    }
    bool improved = false;
    for (const auto& move : moves) {
      if (tried >= evaluations) break;
      QuadLayout moved = layout;
      std::vector<char> taken(mesh.positions.size(), 0);
      for (int v : layout.corners) taken[v] = 1;
      for (int c : move) {
        if (std::find(locked.begin(), locked.end(), layout.corners[c]) != locked.end()) continue;
        const Eigen::Vector3d& pc = mesh.positions[layout.corners[c]];
        double local = 0.0;
        for (int q : quads_at[c]) local += area[q];
        local /= static_cast<double>(quads_at[c].size());
        Eigen::Vector3d target = pc;
        for (int q : quads_at[c]) target += step * (area[q] - local) / mean * (centroid[q] - pc);
        const int best_v = geometry.snap(mesh, quads_at[c], target, taken, moved.corners[c]);
        if (best_v < 0) continue;
        taken[moved.corners[c]] = 0;
        moved.corners[c] = best_v;
        taken[best_v] = 1;
      }
      if (moved.corners == layout.corners) continue;
      ++tried;
      if (auto candidate = evaluate_layout(cache, objective, std::move(moved));
          candidate && candidate->cost < spread) {
        spread = candidate->cost;
        layout = std::move(candidate->layout);
        partition = std::move(candidate->partition);
        stats = std::move(candidate->stats);
        ++kept;
        improved = true;
        break;
      }
    }
    step = improved ? std::min(1.0, step * 1.25) : step * 0.5;
  }
  return kept;
}

// Moves the corners whose patches are worst shaped (shape_penalty(): a corner angle above
// `max_corner_angle_deg`, a side longer than `max_side_ratio` · sqrt(area), a flatness below `min_flatness`)
// to lower `objective`. Each round
// ranks the corners by their share of the penalty and, for the worst 8 in turn, tries landing it (on the
// nearest free vertex of its patches) at `step` towards and away from each of its patches' area centroids and
// `step`/2 of the way towards and away from each corner it shares a side with; the best candidate that
// lowers the objective is kept. When no corner improves the step is halved. At most `evaluations`
// partitions are tried. Returns the number of moves kept.
int reshape_corners(const TriMesh& mesh, const PartitionMeshCache& cache, const Objective& objective,
                    const QuadLayoutOptions& options, const std::vector<int>& locked, QuadLayout& layout,
                    PartitionResult& partition, PartitionStats& stats, int evaluations) {
  const int nc = static_cast<int>(layout.corners.size());
  const int nq = static_cast<int>(layout.quads.size());
  std::vector<std::vector<int>> quads_at(nc), side_neighbours(nc);
  for (int q = 0; q < nq; ++q) {
    for (int i = 0; i < 4; ++i) {
      const int c = layout.quads[q][i];
      quads_at[c].push_back(q);
      side_neighbours[c].push_back(layout.quads[q][(i + 1) % 4]);
      side_neighbours[c].push_back(layout.quads[q][(i + 3) % 4]);
    }
  }
  for (auto& n : side_neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  const double max_angle = options.max_corner_angle_deg * M_PI / 180.0;
  double cost = objective(partition, stats);
  double step = 0.5;
  int kept = 0, tried = 0;
  while (tried < evaluations && step > 0.03) {
    // Each corner's share of the shape penalty (a side's share goes to both its ends).
    std::unordered_map<int, int> corner_of;
    for (int c = 0; c < nc; ++c) corner_of[layout.corners[c]] = c;
    const std::vector<PatchShape> shapes = patch_shapes(partition);
    std::vector<double> badness(nc, 0.0);
    for (std::size_t q = 0; q < shapes.size(); ++q) {
      const auto& corners = partition.patches[q].corners;
      const double flat = std::max(0.0, options.min_flatness - stats.patches[q].flatness) / 0.25;
      for (int k = 0; k < 4; ++k) {
        if (const auto it = corner_of.find(corners[k]); it != corner_of.end()) badness[it->second] += flat * flat;
        const double a = std::max(0.0, shapes[q].corner_angle[k] - max_angle) / (0.5 * M_PI);
        const double r = std::max(0.0, shapes[q].side_ratio[k] - options.max_side_ratio);
        const auto here = corner_of.find(corners[k]), next = corner_of.find(corners[(k + 1) % 4]);
        if (here != corner_of.end()) badness[here->second] += a * a + r * r;
        if (next != corner_of.end()) badness[next->second] += r * r;
      }
    }
    std::vector<int> order;
    for (int c = 0; c < nc; ++c) {
      if (badness[c] > 0.0 && std::find(locked.begin(), locked.end(), layout.corners[c]) == locked.end())
        order.push_back(c);
    }
    if (order.empty()) break;
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return badness[a] != badness[b] ? badness[a] > badness[b] : a < b; });
    if (order.size() > 8) order.resize(8);
    const PatchGeometry geometry(mesh, partition, nq);
    std::vector<char> taken(mesh.positions.size(), 0);
    for (int v : layout.corners) taken[v] = 1;
    bool improved = false;
    for (int c : order) {
      const Eigen::Vector3d pc = mesh.positions[layout.corners[c]];
      std::vector<Eigen::Vector3d> targets;
      for (int q : quads_at[c]) {
        targets.push_back(pc + step * (geometry.centroid[q] - pc));
        targets.push_back(pc - step * (geometry.centroid[q] - pc));
      }
      for (int n : side_neighbours[c]) {
        targets.push_back(pc + 0.5 * step * (mesh.positions[layout.corners[n]] - pc));
        targets.push_back(pc - 0.5 * step * (mesh.positions[layout.corners[n]] - pc));
      }
      std::vector<int> landed;
      for (const auto& target : targets) {
        const int v = geometry.snap(mesh, quads_at[c], target, taken, layout.corners[c]);
        if (v >= 0 && v != layout.corners[c] && std::find(landed.begin(), landed.end(), v) == landed.end())
          landed.push_back(v);
      }
      std::optional<EvaluatedLayout> best;
      for (int v : landed) {
        if (tried >= evaluations) break;
        QuadLayout moved = layout;
        moved.corners[c] = v;
        ++tried;
        auto candidate = evaluate_layout(cache, objective, std::move(moved));
        if (candidate && candidate->cost < (best ? best->cost : cost)) best = std::move(candidate);
      }
      if (best) {
        cost = best->cost;
        layout = std::move(best->layout);
        partition = std::move(best->partition);
        stats = std::move(best->stats);
        ++kept;
        improved = true;
        break;
      }
    }
    step = improved ? std::min(1.0, step * 1.25) : step * 0.5;
  }
  return kept;
}

}  // namespace

QuadLayoutChoice choose_quad_layout(const TriMesh& mesh, const QuadLayoutOptions& options) {
  const TopologyReport topo = analyze_topology(mesh);
  if (!topo.manifold || topo.boundary_edges > 0 || topo.components != 1 || !topo.genus ||
      topo.degenerate_faces > 0) {
    throw InvalidInput(std::string(kFn) +
                       "the mesh must be one closed, manifold, oriented component without degenerate "
                       "triangles; run repair_mesh first");
  }
  const int genus = *topo.genus;
  const long long k = options.patches;
  const long long target = k + 2 - 2LL * genus;
  const long long vertices = static_cast<long long>(mesh.positions.size() - topo.unreferenced_vertices);
  if (k < 2)
    throw InvalidInput(std::string(kFn) + "a layout needs at least 2 patches, got " + std::to_string(k));
  if (target < 4) {
    throw InvalidInput(std::string(kFn) + std::to_string(k) + " patches are too few for genus " +
                       std::to_string(genus) + " (K + 2 - 2g = " + std::to_string(target) +
                       " coarse vertices; at least 4 are needed)");
  }
  if (target > vertices) {
    throw InvalidInput(std::string(kFn) + std::to_string(k) + " patches need " + std::to_string(target) +
                       " corners but the mesh has " + std::to_string(vertices) + " vertices");
  }
  const PartitionMeshCache cache(mesh);  // every partition below is of this mesh
  const std::function<double(const PartitionStats&)> base =
      options.objective == LayoutObjective::kSamplingCost ? sampling_cost : area_spread;
  const Objective objective = [&](const PartitionResult& partition, const PartitionStats& stats) {
    const double cost = base(stats);
    if (options.shape_weight <= 0.0) return cost;
    return cost + options.shape_weight * shape_penalty(patch_shapes(partition), stats, options);
  };
  std::string last_error;
  // Two groups of candidates: coarse meshes without and with the protrusion tips pinned (at most half the
  // corners), by either collapse rule, each paired three ways. The best pairing of each group is balanced
  // (corners moved, tips stay), and the better of the two balanced layouts is returned.
  const std::vector<int> tips =
      options.tip_persistence > 0.0
          ? protrusion_tips(mesh, options.tip_persistence, static_cast<std::size_t>(target / 2))
          : std::vector<int>{};
  QuadLayoutChoice best;
  double best_cost = 0.0;
  std::size_t candidates = 0;
  for (const bool pin_tips : {false, true}) {
    if ((pin_tips && tips.empty()) || (!pin_tips && options.only_pinned_tips && !tips.empty())) continue;
    QuadLayoutChoice group;
    double group_cost = 0.0;
    // Equal error: one coarse mesh per error weight (the error picks the survivor of a collapse); the
    // equal-area ones, by either rule, only when none of their pairings partitions the mesh.
    const bool by_error = options.error_weight > 0.0 && k >= options.min_error_patches;
    std::vector<std::pair<bool, double>> simplifications;  // (centroid rule, error weight)
    if (by_error)
      for (double factor : options.error_weight_factors)
        if (factor > 0.0) simplifications.emplace_back(true, options.error_weight * factor);
    simplifications.emplace_back(true, 0.0);
    simplifications.emplace_back(false, 0.0);
    for (const auto& [centroid_rule, error_weight] : simplifications) {
      if (error_weight == 0.0 && by_error && group.candidates > 0) break;
      Simplifier simplifier(mesh, centroid_rule, pin_tips ? tips : std::vector<int>{}, error_weight);
      if (!simplifier.simplify_to(static_cast<std::size_t>(target))) {
        last_error = "cannot simplify the mesh to " + std::to_string(target) + " vertices without folding it";
        continue;
      }
      std::vector<std::array<int, 3>> coarse = simplifier.triangles();
      delaunay_flips(mesh.positions, coarse);
      pair_coarse_triangles(mesh, cache, coarse, k, objective, group, group_cost, last_error);
    }
    if (group.candidates == 0) continue;
    candidates += group.candidates;
    if (options.balance_steps > 0) {
      PartitionResult partition = partition_mesh_layout(cache, group.layout);
      PartitionStats stats = partition_stats(partition);
      group.balance_steps =
          relax_corners(mesh, cache, objective, tips, group.layout, partition, stats, options.balance_steps);
      group_cost = objective(partition, stats);
    }
    if (options.shape_weight > 0.0 && options.shape_steps > 0) {
      PartitionResult partition = partition_mesh_layout(cache, group.layout);
      PartitionStats stats = partition_stats(partition);
      group.shape_steps = reshape_corners(mesh, cache, objective, options, tips, group.layout, partition,
                                          stats, options.shape_steps);
      group_cost = objective(partition, stats);
    }
    if (best.candidates == 0 || group_cost < best_cost) {
      best = std::move(group);
      best_cost = group_cost;
      best.tips_pinned = pin_tips;
    }
  }
  if (best.candidates == 0) {
    throw InvalidInput(std::string(kFn) + "no layout of " + std::to_string(k) +
                       " patches partitions the mesh (" + last_error + "); try another number of patches");
  }
  best.candidates = candidates;
  best.tips = tips;
  {
    const PartitionResult partition = partition_mesh_layout(cache, best.layout);
    const PartitionStats stats = partition_stats(partition);
    best.area_balance = stats.area_balance;
    best.area_spread = area_spread(stats);
    best.sampling_cost = sampling_cost(stats);
    const std::vector<PatchShape> shapes = patch_shapes(partition);
    best.shape_penalty = shape_penalty(shapes, stats, options);
    for (const PatchShape& shape : shapes) {
      for (int j = 0; j < 4; ++j) {
        best.max_corner_angle_deg = std::max(best.max_corner_angle_deg, shape.corner_angle[j] * 180.0 / M_PI);
        best.max_side_ratio = std::max(best.max_side_ratio, shape.side_ratio[j]);
      }
    }
  }
  return best;
}

}  // namespace geomip
