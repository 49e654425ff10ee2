#include "param/coarse_to_fine.h"

#include "mesh/errors.h"
#include "mesh/predicates.h"
#include "param/mean_value_embedding.h"
#include "param/sampling_weights.h"
#include "param/unit_square.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace geomip {
namespace {

constexpr double kOnSideTolerance = 1e-12;

[[noreturn]] void fail(const char* function, const std::string& what) {
  throw InvalidInput(std::string(function) + ": " + what);
}

/// z of the 2D cross product (a value, for clipping and distances; signs that decide a flip use orient2d).
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// The corners of triangle t rotated so that `v` comes first: returns the opposite edge (x, y).
std::pair<int, int> opposite_edge(const std::array<int, 3>& t, int v) {
  if (t[0] == v) return {t[1], t[2]};
  if (t[1] == v) return {t[2], t[0]};
  return {t[0], t[1]};
}

/// Clips the convex polygon `poly` (counter-clockwise) to the half-plane left of the directed line a→b.
void clip_left_of(std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                  std::vector<Eigen::Vector2d>& scratch) {
  scratch.clear();
  const Eigen::Vector2d d = b - a;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % n];
    const double dp = cross(d, p - a), dq = cross(d, q - a);
    if (dp >= 0) scratch.push_back(p);
    if ((dp > 0 && dq < 0) || (dp < 0 && dq > 0)) scratch.push_back(p + (dp / (dp - dq)) * (q - p));
  }
  poly.swap(scratch);
}

/// Area centroid of a convex polygon; the vertex average when its area vanishes numerically.
Eigen::Vector2d polygon_centroid(const std::vector<Eigen::Vector2d>& poly) {
  double area2 = 0.0;
  Eigen::Vector2d c(0, 0), mean(0, 0);
  const Eigen::Vector2d o = poly[0];  // relative to the first vertex, for precision
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d p = poly[i] - o, q = poly[(i + 1) % poly.size()] - o;
    const double w = cross(p, q);
    area2 += w;
    c += w * (p + q);
    mean += poly[i];
  }
  mean /= static_cast<double>(poly.size());
  if (!(area2 > 1e-300)) return mean;
  return o + c / (3.0 * area2);
}

}  // namespace

CoarseToFine::CoarseToFine(const TriMesh& patch, const ProgressiveMesh& pm,
                           const std::vector<Eigen::Vector2d>& base_uv, const CoarseToFineOptions& options)
    : patch_(patch), pm_(pm), options_(options) {
  constexpr const char* kFn = "CoarseToFine";
  const std::size_t n = patch.positions.size();
  if (pm.num_vertices != n || pm.num_triangles != patch.triangles.size()) {
    fail(kFn, "the progressive mesh was not built from this patch");
  }
  if (options.side_metrics && options.side_metrics->size() != n)
    fail(kFn, "metric tensors per vertex: wrong count");
  if (base_uv.size() != n)
    fail(kFn, "base_uv has " + std::to_string(base_uv.size()) + " entries, not " + std::to_string(n));
  const double kNan = std::numeric_limits<double>::quiet_NaN();
  uv_.assign(n, Eigen::Vector2d(kNan, kNan));
  for (int v : pm.base_vertices) {
    if (v < 0 || static_cast<std::size_t>(v) >= n) fail(kFn, "base vertex id out of range");
    if (!base_uv[v].allFinite()) fail(kFn, "base vertex " + std::to_string(v) + " has no finite uv");
    uv_[v] = base_uv[v];
  }
  triangles_.assign(patch.triangles.size(), {-1, -1, -1});
  star_.assign(n, {});
  for (std::size_t i = 0; i < pm.base_triangles.size(); ++i) {
    const int id = pm.base_triangle_ids[i];
    if (id < 0 || static_cast<std::size_t>(id) >= triangles_.size())
      fail(kFn, "base triangle id out of range");
    triangles_[id] = pm.base_triangles[i];
    for (int v : pm.base_triangles[i]) {
      if (v < 0 || static_cast<std::size_t>(v) >= n || !uv_[v].allFinite()) {
        fail(kFn, "base triangle corner is not a base vertex");
      }
      star_[v].push_back(id);
    }
    if (orient2d(uv_[pm.base_triangles[i][0]], uv_[pm.base_triangles[i][1]], uv_[pm.base_triangles[i][2]]) <= 0) {
      fail(kFn, "base triangle " + std::to_string(id) + " is flipped or degenerate in base_uv");
    }
  }

  fixed_.assign(n, 0);
  off_chord_.assign(n, 0);
  side_of_.assign(n, -1);
  arclength_.assign(n, 0.0);
  for (int k = 0; k < 4; ++k) {
    const auto& side = pm.sides[k];
    if (side.size() < 2) fail(kFn, "progressive mesh has a side with fewer than 2 vertices");
    const int corner = side.front();
    fixed_[corner] = 1;
    if (!uv_[corner].allFinite() || (uv_[corner] - unit_square_corners()[k]).norm() > kOnSideTolerance) {
      fail(kFn, "corner " + std::to_string(k) + " is not at its place on the unit square in base_uv");
    }
    double s = 0.0;
    for (std::size_t i = 1; i < side.size(); ++i) {
      s += metric_edge_length(patch.positions, options.side_metrics, side[i - 1], side[i]);
      if (i + 1 < side.size()) {
        side_of_[side[i]] = k;
        arclength_[side[i]] = s;
      }
    }
    side_length_[k] = s;
  }
  for (int f : pm.features) fixed_[f] = 1;
  for (int v : pm.base_vertices) {
    const int k = side_of_[v];
    if (k < 0) continue;
    const Eigen::Vector2d a = unit_square_corners()[k], b = unit_square_corners()[(k + 1) % 4];
    if (std::abs(cross(b - a, uv_[v] - a)) > kOnSideTolerance) {
      fail(kFn, "base boundary vertex " + std::to_string(v) + " is not on its side in base_uv");
    }
  }
}

double CoarseToFine::side_arclength(int side, int v) const {
  if (side_of_[v] == side) return arclength_[v];
  if (v == pm_.sides[side].front()) return 0.0;
  if (v == pm_.sides[side].back()) return side_length_[side];
  throw SolverFailure("CoarseToFine: boundary split between vertices of different sides");
}

bool CoarseToFine::move_to_kernel_centroid(int v, const Eigen::Vector2d& anchor) {
  // Kernel of the neighbourhood polygon: the unit square clipped to the left of every edge (x, y) opposite v.
  std::vector<Eigen::Vector2d> kernel(unit_square_corners().begin(), unit_square_corners().end());
  std::vector<Eigen::Vector2d> scratch;
  for (int id : star_[v]) {
    const auto [x, y] = opposite_edge(triangles_[id], v);
    clip_left_of(kernel, uv_[x], uv_[y], scratch);
    if (kernel.empty()) break;
  }
  auto all_positive = [&](const Eigen::Vector2d& p) {
    for (int id : star_[v]) {
      const auto [x, y] = opposite_edge(triangles_[id], v);
      if (orient2d(p, uv_[x], uv_[y]) <= 0) return false;
    }
    return true;
  };
  if (kernel.empty()) return false;
  // In exact arithmetic the centroid is inside the (open, convex) kernel and so is the whole segment from it
  // to the anchor, which lies on the kernel's closure; rounding can spoil the first, so walk towards it.
  Eigen::Vector2d p = polygon_centroid(kernel);
  for (int attempt = 0; attempt < 60; ++attempt) {
    if (all_positive(p)) {
      uv_[v] = p;
      return true;
    }
    p = 0.5 * (p + anchor);
  }
  return false;
}

void CoarseToFine::insert_interior(int v, int kept) {
  if (!move_to_kernel_centroid(v, uv_[kept])) {
    throw SolverFailure("CoarseToFine: empty kernel when re-inserting vertex " + std::to_string(v) +
                        " (the level before was not an embedding)");
  }
}

bool CoarseToFine::settle_on_chord(int v, int rounds) {
  // Each round moves v as far towards its chord-length position as its ring allows (place_on_side), then
  // relaxes the free interior vertices of its 2-ring to the centroids of their kernels, which moves them away
  // from the crowded stretch of the side and widens the admissible interval.
  std::vector<int> region;
  for (int round = 0; round < rounds; ++round) {
    if (place_on_side(v)) return true;
    region.clear();
    for (int id : star_[v]) {
      for (int w : triangles_[id]) {
        if (std::find(region.begin(), region.end(), w) == region.end()) region.push_back(w);
      }
    }
    const std::size_t one_ring = region.size();
    for (std::size_t i = 0; i < one_ring; ++i) {
      for (int id : star_[region[i]]) {
        for (int w : triangles_[id]) {
          if (std::find(region.begin(), region.end(), w) == region.end()) region.push_back(w);
        }
      }
    }
    for (int w : region) {
      if (fixed_[w] || side_of_[w] >= 0 || w == v) continue;
      move_to_kernel_centroid(w, uv_[w]);
    }
  }
  return place_on_side(v);
}

void CoarseToFine::settle_off_chord() {
  for (int v = 0; v < static_cast<int>(off_chord_.size()); ++v) {
    if (off_chord_[v] && settle_on_chord(v, kSettleRounds)) {
      off_chord_[v] = 0;
      --num_off_chord_;
    }
  }
}

bool CoarseToFine::place_on_side(int v) {
  const int side = side_of_[v];
  if (side < 0) throw SolverFailure("CoarseToFine: boundary split of a vertex that is not on a side");
  // v = corner + s·dir, s ∈ [0,1]. Each triangle (v, x, y) stays counter-clockwise for s in an open interval
  // (orient is affine in s); the triangles on v's two boundary edges keep s between its boundary neighbours.
  const Eigen::Vector2d corner = unit_square_corners()[side], dir = unit_square_corners()[(side + 1) % 4] - corner;
  const double s_chord = arclength_[v] / side_length_[side];
  double lo = 0.0, hi = 1.0;
  for (int id : star_[v]) {
    const auto [x, y] = opposite_edge(triangles_[id], v);
    const double f0 = signed_double_area(corner, uv_[x], uv_[y]),
                 f1 = signed_double_area(corner + dir, uv_[x], uv_[y]);
    const double slope = f1 - f0;
    if (slope > 0) {
      lo = std::max(lo, -f0 / slope);
    } else if (slope < 0) {
      hi = std::min(hi, -f0 / slope);
    } else if (!(f0 > 0)) {
      hi = lo;
    }
  }
  const Eigen::Vector2d before = uv_[v];
  auto try_at = [&](double s) {
    uv_[v] = corner + s * dir;
    for (int id : star_[v]) {
      if (orient2d(uv_[triangles_[id][0]], uv_[triangles_[id][1]], uv_[triangles_[id][2]]) <= 0) {
        uv_[v] = before;
        return false;
      }
    }
    return true;
  };
  if (lo < hi) {
    if (s_chord > lo && s_chord < hi && try_at(s_chord)) return true;
    // As close to the chord-length position as keeps a quarter of the admissible interval on either side.
    const double margin = 0.25 * (hi - lo);
    try_at(std::clamp(s_chord, lo + margin, hi - margin));
  }
  return false;
}

void CoarseToFine::insert_boundary(const HalfEdgeCollapse& c) {
  const int v = c.removed;
  const int side = side_of_[v];
  if (side < 0) throw SolverFailure("CoarseToFine: boundary split of a vertex that is not on a side");
  const double sa = side_arclength(side, c.kept), sb = side_arclength(side, c.boundary_neighbor);
  const double sv = arclength_[v];
  if (!((sv - sa) * (sb - sv) > 0.0)) {
    throw SolverFailure("CoarseToFine: boundary vertex " + std::to_string(v) +
                        " is not between its neighbours");
  }
  if (!settle_on_chord(v, kInsertSettleRounds)) {
    if (!uv_[v].allFinite()) {
      throw SolverFailure("CoarseToFine: no place on its side for boundary vertex " + std::to_string(v));
    }
    off_chord_[v] = 1;
    ++num_off_chord_;
  }
}

void CoarseToFine::retry_off_chord(int v) {
  if (off_chord_[v] && place_on_side(v)) {
    off_chord_[v] = 0;
    --num_off_chord_;
  }
}

void CoarseToFine::check_star(int v, const char* when) const {
  for (int id : star_[v]) {
    if (orient2d(uv_[triangles_[id][0]], uv_[triangles_[id][1]], uv_[triangles_[id][2]]) <= 0) {
      throw SolverFailure("CoarseToFine: triangle " + std::to_string(id) + " flipped " + when + " (vertex " +
                          std::to_string(v) + ", split " + std::to_string(done_ + 1) + ")");
    }
  }
  const int k = side_of_[v];
  if (k >= 0) {
    const Eigen::Vector2d a = unit_square_corners()[k], b = unit_square_corners()[(k + 1) % 4];
    const double along = (uv_[v] - a).dot(b - a);
    if (std::abs(cross(b - a, uv_[v] - a)) > kOnSideTolerance || !(along > 0.0 && along < 1.0)) {
      throw SolverFailure("CoarseToFine: boundary vertex " + std::to_string(v) + " left its side " + when);
    }
  }
}

int CoarseToFine::split_next(const VertexOptimizer& optimize) {
  if (finished()) return -1;
  const HalfEdgeCollapse& c = pm_.collapses[pm_.collapses.size() - 1 - done_];
  apply_vertex_split(c, triangles_);
  auto& kept_star = star_[c.kept];
  for (int id : c.moved_triangles) {
    const auto it = std::find(kept_star.begin(), kept_star.end(), id);
    if (it == kept_star.end()) throw SolverFailure("CoarseToFine: vertex-triangle adjacency out of sync");
    kept_star.erase(it);
    star_[c.removed].push_back(id);
  }
  for (int id : {c.left_triangle, c.right_triangle}) {
    if (id < 0) continue;
    for (int w : triangles_[id]) star_[w].push_back(id);
  }

  if (c.boundary_neighbor >= 0) {
    insert_boundary(c);
  } else {
    insert_interior(c.removed, c.kept);
  }
  check_star(c.removed, "by the insertion");

  if (options_.check_all_triangles) {
    const std::size_t flipped = count_flipped_triangles(uv_, triangles_);
    if (flipped != 0) {
      throw SolverFailure("CoarseToFine: " + std::to_string(flipped) + " flipped triangles after split " +
                          std::to_string(done_ + 1));
    }
  }

  std::vector<int> ring;
  for (int id : star_[c.removed]) {
    for (int w : triangles_[id]) {
      if (w != c.removed && !fixed_[w] && std::find(ring.begin(), ring.end(), w) == ring.end())
        ring.push_back(w);
    }
  }
  if (optimize) {
    optimize(c.removed, star_[c.removed]);
    check_star(c.removed, "by the optimizer");
    for (int w : ring) {
      optimize(w, star_[w]);
      check_star(w, "by the optimizer");
    }
  }
  // Boundary vertices left off their chord-length position get another chance when their ring changes.
  if (num_off_chord_ != 0) {
    for (int w : ring) retry_off_chord(w);
  }
  ++done_;
  if (finished() && num_off_chord_ != 0) {
    for (int w = 0; w < static_cast<int>(off_chord_.size()); ++w) retry_off_chord(w);
    settle_off_chord();
  }
  return c.removed;
}

void CoarseToFine::refine_all(const VertexOptimizer& optimize) {
  while (!finished()) split_next(optimize);
}

CoarseToFineResult CoarseToFine::result() const {
  if (!finished()) fail("CoarseToFine::result", "not all vertex splits are done");
  CoarseToFineResult r;
  r.uv = uv_;
  r.triangles = patch_.triangles;
  r.boundary_off_chord = num_off_chord_;
  r.min_area2 = std::numeric_limits<double>::infinity();
  for (std::size_t id = 0; id < patch_.triangles.size(); ++id) {
    // The replay must land on the patch's own triangles (up to a rotation of the corners).
    auto t = triangles_[id], u = patch_.triangles[id];
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    std::rotate(u.begin(), std::min_element(u.begin(), u.end()), u.end());
    if (t != u)
      throw SolverFailure("CoarseToFine: the vertex splits did not rebuild triangle " + std::to_string(id));
    r.min_area2 = std::min(r.min_area2, signed_uv_area2(uv_, patch_.triangles[id]));
  }
  return r;
}

CoarseToFineResult coarse_to_fine(const TriMesh& patch, const ProgressiveMesh& pm,
                                  const std::vector<Eigen::Vector2d>& base_uv,
                                  const CoarseToFineOptions& options) {
  CoarseToFine c2f(patch, pm, base_uv, options);
  c2f.refine_all();
  return c2f.result();
}

}  // namespace geomip
