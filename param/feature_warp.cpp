// Foldover-free feature alignment ("triangulation over time", paper §3.4). The only translation unit of
// geomip::param that includes CGAL's 2D triangulations: Delaunay_triangulation_2 builds the initial warp mesh
// and the exact orientation predicate (orient2d, mesh/predicates.h) decides every sign; the kinetic part (moves,
// edge flips, barycentric re-binding, base-mesh repair) works on a small triangle list of its own.
#include "param/feature_warp.h"

#include "mesh/errors.h"
#include "mesh/predicates.h"
#include "param/unit_square.h"

// CGAL's headers shadow names freely; silence that for them only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#pragma GCC diagnostic pop

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

namespace geomip {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;
using Vec2 = Eigen::Vector2d;
using Tri = std::array<int, 3>;

constexpr int kCorners = 4;
constexpr std::size_t kStallSteps = 500;  // a feature that gains < 0.1% of its remaining way in this many steps is stuck
const Vec2* const kCornerUv = unit_square_corners().data();

bool on_boundary(const Vec2& p) { return p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1; }
bool strictly_inside(const Vec2& p, double margin) {
  return p.x() > margin && p.y() > margin && p.x() < 1 - margin && p.y() < 1 - margin;
}
double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double len2 = d.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (a + s * d - p).norm();
}

std::vector<Tri> delaunay(const std::vector<Vec2>& points, const char* function) {
  std::vector<std::pair<Kernel::Point_2, int>> input;
  input.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) input.emplace_back(Kernel::Point_2(points[i].x(), points[i].y()), int(i));
  Delaunay dt;
  dt.insert(input.begin(), input.end());
  if (dt.number_of_vertices() != points.size()) {
    throw InvalidInput(std::string(function) + ": two features have the same uv");
  }
  std::vector<Tri> triangles;
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    triangles.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  }
  return triangles;
}

std::vector<Vec2> warp_points(const std::vector<Vec2>& feature_uv, const char* function) {
  std::vector<Vec2> points(kCornerUv, kCornerUv + kCorners);
  for (const Vec2& p : feature_uv) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !strictly_inside(p, 0.0)) {
      throw InvalidInput(std::string(function) + ": a feature is not strictly inside the unit square");
    }
    points.push_back(p);
  }
  return points;
}

/// Convex kernel of a vertex's star: the points left of every directed link edge (a, b), clipped from the unit
/// square (Sutherland–Hodgman). Returns false when it has no area.
bool kernel_centroid(const std::vector<std::pair<Vec2, Vec2>>& link, Vec2& centroid) {
  std::vector<Vec2> poly(kCornerUv, kCornerUv + kCorners), next;
  for (const auto& [a, b] : link) {
    next.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % poly.size()];
      const double sp = signed_double_area(a, b, p), sq = signed_double_area(a, b, q);
      if (sp > 0) next.push_back(p);
      if ((sp > 0) != (sq > 0) && sp != sq) next.push_back(p + (sp / (sp - sq)) * (q - p));
    }
    poly.swap(next);
    if (poly.size() < 3) return false;
  }
  double area = 0;
  Vec2 c(0, 0);
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    const double w = p.x() * q.y() - q.x() * p.y();
    area += w;
    c += w * (p + q);
  }
  if (!(area > 0)) return false;
  centroid = c / (3 * area);
  return std::isfinite(centroid.x()) && std::isfinite(centroid.y());
}

/// The point of a vertex's kernel that maximizes the smallest area of its star triangles (the local
/// untangling LP of Freitag & Plassmann 2000): max z subject to signed_double_area(a, b, x) >= z for every directed link
/// edge (a, b). The optimum is a vertex of that 3D polytope, so every triple of constraints is tried (stars
/// are small). Returns false when no such point has a positive minimum.
bool max_min_area_point(const std::vector<std::pair<Vec2, Vec2>>& link, Vec2& best) {
  const std::size_t n = link.size();
  std::vector<Vec2> g(n);
  std::vector<double> c(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 e = link[i].second - link[i].first;
    g[i] = Vec2(-e.y(), e.x());
    c[i] = -g[i].dot(link[i].first);
  }
  double best_z = 0;
  bool found = false;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec2 r0 = g[i] - g[j], r1 = g[i] - g[k];  // r0·x = c_j - c_i, r1·x = c_k - c_i (Cramer)
        const double det = r0.x() * r1.y() - r0.y() * r1.x();
        if (std::abs(det) < 1e-300) continue;
        const double b0 = c[j] - c[i], b1 = c[k] - c[i];
        const Vec2 x((b0 * r1.y() - r0.y() * b1) / det, (r0.x() * b1 - b0 * r1.x()) / det);
        const double z = g[i].dot(x) + c[i];
        if (!(z > best_z) || !std::isfinite(z)) continue;
        bool feasible = true;
        for (std::size_t l = 0; l < n && feasible; ++l) feasible = g[l].dot(x) + c[l] >= z * (1 - 1e-9);
        if (feasible) {
          best_z = z;
          best = x;
          found = true;
        }
      }
    }
  }
  return found;
}

/// The warp mesh (corners + features, counter-clockwise triangles with adjacency) and the barycentric binding
/// of every interior non-feature uv point to its enclosing warp triangle.
class WarpMesh {
 public:
  WarpMesh(std::vector<Vec2> points, std::vector<Tri> triangles, std::vector<Vec2>& uv)
      : pos(std::move(points)), tri(std::move(triangles)), uv_(uv) {
    nbr.assign(tri.size(), {-1, -1, -1});
    members.assign(tri.size(), {});
    std::vector<std::pair<std::pair<int, int>, std::pair<int, int>>> edges;  // (min,max) -> (t, i)
    for (int t = 0; t < int(tri.size()); ++t) {
      for (int i = 0; i < 3; ++i) {
        const int a = tri[t][(i + 1) % 3], b = tri[t][(i + 2) % 3];
        edges.push_back({{std::min(a, b), std::max(a, b)}, {t, i}});
      }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t e = 0; e + 1 < edges.size(); ++e) {
      if (edges[e].first == edges[e + 1].first) {
        nbr[edges[e].second.first][edges[e].second.second] = edges[e + 1].second.first;
        nbr[edges[e + 1].second.first][edges[e + 1].second.second] = edges[e].second.first;
      }
    }
    bound.assign(uv.size(), -1);
    bary.assign(uv.size(), Eigen::Vector3d::Zero());
  }

  std::vector<Vec2> pos;
  std::vector<Tri> tri;
  std::vector<Tri> nbr;                   // nbr[t][i]: triangle across the edge opposite tri[t][i], -1 on the hull
  std::vector<std::vector<int>> members;  // uv points bound to each triangle
  std::vector<int> bound;                 // per uv point: its warp triangle, -1 when not bound
  std::vector<Eigen::Vector3d> bary;      // per uv point: barycentric coordinates in `bound`

  int local(int t, int v) const { return tri[t][0] == v ? 0 : tri[t][1] == v ? 1 : tri[t][2] == v ? 2 : -1; }

  std::vector<int> incident(int v) const {
    std::vector<int> out;
    for (int t = 0; t < int(tri.size()); ++t) {
      if (local(t, v) >= 0) out.push_back(t);
    }
    return out;
  }

  /// Position of warp vertex v, or `x` when v is `moving`.
  const Vec2& at(int v, int moving, const Vec2& x) const { return v == moving ? x : pos[v]; }
  int orientation_with(int t, int moving, const Vec2& x) const {
    return orient2d(at(tri[t][0], moving, x), at(tri[t][1], moving, x), at(tri[t][2], moving, x));
  }
  double area2_with(int t, int moving, const Vec2& x) const {
    return signed_double_area(at(tri[t][0], moving, x), at(tri[t][1], moving, x), at(tri[t][2], moving, x));
  }

  /// Barycentric coordinates of p in triangle t (all >= 0 inside).
  Eigen::Vector3d barycentric(int t, const Vec2& p) const {
    const Vec2 &a = pos[tri[t][0]], &b = pos[tri[t][1]], &c = pos[tri[t][2]];
    const double total = signed_double_area(a, b, c);
    Eigen::Vector3d l(signed_double_area(p, b, c) / total, signed_double_area(a, p, c) / total, 0.0);
    l[2] = 1.0 - l[0] - l[1];
    return l;
  }

  /// Binds uv point p (at its current uv) to the candidate triangle that contains it best.
  void bind(int p, const std::vector<int>& candidates) {
    int best = -1;
    double best_quality = -std::numeric_limits<double>::infinity();
    Eigen::Vector3d best_l = Eigen::Vector3d::Zero();
    for (int t : candidates) {
      const Eigen::Vector3d l = barycentric(t, uv_[p]);
      if (l.minCoeff() > best_quality) {
        best_quality = l.minCoeff();
        best = t;
        best_l = l;
      }
    }
    bound[p] = best;
    bary[p] = best_l;
    members[best].push_back(p);
  }
  void bind_anywhere(int p) {
    std::vector<int> all(tri.size());
    for (int t = 0; t < int(tri.size()); ++t) all[t] = t;
    bind(p, all);
  }
  void unbind(int p) {
    auto& m = members[bound[p]];
    m.erase(std::find(m.begin(), m.end(), p));
    bound[p] = -1;
  }

  Vec2 evaluate(int p) const {
    const Tri& T = tri[bound[p]];
    return bary[p][0] * pos[T[0]] + bary[p][1] * pos[T[1]] + bary[p][2] * pos[T[2]];
  }

  /// The two triangles a flip of the edge opposite tri[t][i] creates: (m, p, r) and (m, r, q).
  bool flip_quad(int t, int i, int& m, int& p, int& q, int& r) const {
    const int t2 = nbr[t][i];
    if (t2 < 0) return false;
    m = tri[t][i];
    p = tri[t][(i + 1) % 3];
    q = tri[t][(i + 2) % 3];
    r = -1;
    for (int v : tri[t2]) {
      if (v != p && v != q) r = v;
    }
    return r >= 0;
  }

  /// Lawson flips until every interior edge is locally Delaunay (exact in-circle predicate); the triangulation
  /// must be valid. Returns the number of flips.
  template <class OnFlip>
  std::size_t make_delaunay(OnFlip on_flip) {
    std::size_t flips = 0;
    for (bool changed = true; changed;) {
      changed = false;
      for (int t = 0; t < int(tri.size()); ++t) {
        for (int i = 0; i < 3; ++i) {
          int m, p, q, r;
          if (!flip_quad(t, i, m, p, q, r)) continue;
          const auto pt = [&](int v) { return Kernel::Point_2(pos[v].x(), pos[v].y()); };
          if (CGAL::side_of_oriented_circle(pt(m), pt(p), pt(q), pt(r)) != CGAL::ON_POSITIVE_SIDE) continue;
          if (orient2d(pos[m], pos[p], pos[r]) <= 0 || orient2d(pos[m], pos[r], pos[q]) <= 0) continue;
          for (int n : flip(t, i)) on_flip(n);
          ++flips;
          changed = true;
        }
      }
    }
    return flips;
  }

  /// Flips the edge opposite tri[t][i] (the quad must be strictly convex) and re-binds the points of both
  /// triangles at their current uv. Returns the two new triangles.
  std::array<int, 2> flip(int t, int i) {
    const int t2 = nbr[t][i];
    const int m = tri[t][i], p = tri[t][(i + 1) % 3], q = tri[t][(i + 2) % 3];
    const int j = (local(t2, p) + 1) % 3;  // t2 = (r, q, p) starting at r
    const int r = tri[t2][j];
    const int A = nbr[t][(i + 2) % 3];  // across (m, p)
    const int B = nbr[t][(i + 1) % 3];  // across (q, m)
    const int C = nbr[t2][(j + 2) % 3];  // across (r, q)
    const int E = nbr[t2][(j + 1) % 3];  // across (p, r)
    tri[t] = {m, p, r};
    nbr[t] = {E, t2, A};
    tri[t2] = {m, r, q};
    nbr[t2] = {C, B, t};
    auto repoint = [&](int n, int from, int to) {
      if (n < 0) return;
      for (int& x : nbr[n]) {
        if (x == from) x = to;
      }
    };
    repoint(E, t2, t);
    repoint(B, t, t2);
    std::vector<int> moved;
    moved.swap(members[t]);
    moved.insert(moved.end(), members[t2].begin(), members[t2].end());
    members[t2].clear();
    for (int pt : moved) bind(pt, {t, t2});
    return {t, t2};
  }

 private:
  std::vector<Vec2>& uv_;
};

/// Moves the features one at a time; owns the base-mesh bookkeeping (vertex stars, repair).
class Warper {
 public:
  Warper(const std::vector<Tri>& triangles, std::vector<Vec2>& uv, const std::vector<int>& features,
         const FeatureWarpOptions& options, FeatureWarpResult& result, WarpMesh& warp)
      : triangles_(triangles), uv_(uv), features_(features), options_(options), result_(result), warp_(warp) {
    star_.assign(uv.size(), {});
    for (int t = 0; t < int(triangles.size()); ++t) {
      for (int v : triangles[t]) star_[v].push_back(t);
    }
    fixed_.assign(uv.size(), 0);
    for (int f : features) fixed_[f] = 1;
    for (std::size_t v = 0; v < uv.size(); ++v) {
      if (on_boundary(uv[v])) fixed_[v] = 1;
    }
    mu_.assign(uv.size(), 0.0);
    stamp_.assign(triangles.size(), 0);
  }

  enum class Outcome { kArrived, kStuck };
  Outcome stuck(const char* why) {
    stuck_reason_ = why;
    return Outcome::kStuck;
  }

  const std::vector<int>& star_of(int v) const { return star_[v]; }

  /// The longest base edge at feature k (current uv): the size of the star that travels with it.
  double star_radius(int k) const {
    double r = 0;
    const int f = features_[k];
    for (int t : star_[f]) {
      for (int v : triangles_[t]) r = std::max(r, (uv_[v] - uv_[f]).norm());
    }
    return r;
  }

  /// Moves feature k along the straight segment to q (the caller checked that it passes no warp vertex).
  Outcome move(int k, const Vec2& q) {
    const int w = kCorners + k;
    double checkpoint = (warp_.pos[w] - q).norm();
    for (std::size_t step = 0; step < options_.max_steps_per_feature; ++step) {
      const Vec2 x0 = warp_.pos[w];
      if (x0 == q) return Outcome::kArrived;
      if (step % kStallSteps == kStallSteps - 1) {  // a stall: repairs that keep the feature in place
        const double remaining = (x0 - q).norm();
        if (remaining > checkpoint * (1 - 1e-3)) return stuck("stalled: the base triangles ahead of it could not be kept positive");
        checkpoint = remaining;
      }
      const Vec2 d = q - x0;
      auto point_at = [&](double t) -> Vec2 { return t >= 1 ? q : Vec2(x0 + t * d); };
      const std::vector<int> inc = warp_.incident(w);
      auto warp_valid = [&](const Vec2& x) {
        for (int t : inc) {
          if (warp_.orientation_with(t, w, x) <= 0) return false;
        }
        return true;
      };

      // 1. The first event on the path, by binary search (§3.4.2), and where to flip before it.
      double t_candidate = 1;
      if (options_.max_step_fraction > 0) {
        // Short steps keep every affine piece of the warp close to the identity; with the Delaunay flips after
        // each step, the kinks of the map move with the feature instead of piling up along fixed warp edges.
        double nearest = std::numeric_limits<double>::infinity();
        for (int v = 0; v < int(warp_.pos.size()); ++v) {
          if (v != w) nearest = std::min(nearest, (warp_.pos[v] - x0).norm());
        }
        t_candidate = std::min(1.0, options_.max_step_fraction * nearest / d.norm());
      }
      int flip_t = -1, flip_i = -1;
      if (!warp_valid(q)) {
        double lo = 0, hi = 1;
        while (hi - lo > options_.event_tolerance) {
          const double mid = 0.5 * (lo + hi);
          (warp_valid(point_at(mid)) ? lo : hi) = mid;
        }
        // The degenerating triangle: invalid at hi; among several, the one whose (linear) area vanishes first.
        double first = std::numeric_limits<double>::infinity();
        for (int t : inc) {
          if (warp_.orientation_with(t, w, point_at(hi)) > 0) continue;
          const double a0 = warp_.area2_with(t, w, x0), a1 = warp_.area2_with(t, w, q);
          const double zero = a0 > a1 ? a0 / (a0 - a1) : 0.0;
          if (zero < first) {
            first = zero;
            flip_t = t;
          }
        }
        if (flip_t < 0) return stuck("no warp event found before a warp triangle degenerates");
        // The vertex in the middle of the collinear triple at the event; the edge opposite it is flipped.
        const Vec2 xe = point_at(hi);
        const int lw = warp_.local(flip_t, w);
        const Vec2& pa = warp_.pos[warp_.tri[flip_t][(lw + 1) % 3]];
        const Vec2& pb = warp_.pos[warp_.tri[flip_t][(lw + 2) % 3]];
        const double s = (xe - pa).dot(pb - pa) / (pb - pa).squaredNorm();
        flip_i = s <= 0 ? (lw + 1) % 3 : s >= 1 ? (lw + 2) % 3 : lw;
        int m, p, qq, r;
        if (!warp_.flip_quad(flip_t, flip_i, m, p, qq, r)) return stuck("a warp event on the square's side");
        // Both new triangles have an area linear in t; flip halfway between where they become valid and lo.
        double lower = 0;
        for (const Tri& n : {Tri{m, p, r}, Tri{m, r, qq}}) {
          auto a = [&](const Vec2& x) { return signed_double_area(warp_.at(n[0], w, x), warp_.at(n[1], w, x), warp_.at(n[2], w, x)); };
          const double g0 = a(x0), g1 = a(q);
          if (g0 <= 0 && g1 > g0) lower = std::max(lower, g0 / (g0 - g1));
        }
        auto flip_valid = [&](const Vec2& x) {
          return warp_valid(x) && orient2d(warp_.at(m, w, x), warp_.at(p, w, x), warp_.at(r, w, x)) > 0 &&
                 orient2d(warp_.at(m, w, x), warp_.at(r, w, x), warp_.at(qq, w, x)) > 0;
        };
        double ts = lower < lo ? lower + 0.5 * (lo - lower) : lo;
        int tries = 0;
        while (!flip_valid(point_at(ts)) && tries++ < 64) ts = 0.5 * (ts + lo);
        if (!flip_valid(point_at(ts))) {
          if (!flip_valid(point_at(lo))) return stuck("no valid warp edge flip at an event");
          ts = lo;
        }
        if (ts < t_candidate) {
          t_candidate = ts;
        } else {
          flip_t = -1;  // the step ends before the event anyway
        }
      }

      // 2. Base triangles: every point bound to an incident warp triangle moves linearly with the feature
      // (x_p(t) = x_p + mu_p t d), so each base triangle's area is linear in t too. Stop before the first one
      // that would invert and repair it.
      std::vector<int> moving{features_[k]};
      mu_[features_[k]] = 1;
      for (int t : inc) {
        const int lw = warp_.local(t, w);
        for (int pt : warp_.members[t]) {
          mu_[pt] = warp_.bary[pt][lw];
          moving.push_back(pt);
        }
      }
      ++epoch_;
      std::vector<int> affected;
      for (int v : moving) {
        for (int t : star_[v]) {
          if (stamp_[t] != epoch_) {
            stamp_[t] = epoch_;
            affected.push_back(t);
          }
        }
      }
      int offending = -1;
      double t_stop = t_candidate;
      if (options_.keep_base_mesh_valid) {
        double first = std::numeric_limits<double>::infinity();
        for (int t : affected) {
          const Tri& T = triangles_[t];
          const Vec2 e1 = uv_[T[1]] - uv_[T[0]], e2 = uv_[T[2]] - uv_[T[0]];
          const double a = mu_[T[1]] - mu_[T[0]], b = mu_[T[2]] - mu_[T[0]];
          const double a0 = e1.x() * e2.y() - e1.y() * e2.x();
          const double rate = b * (e1.x() * d.y() - e1.y() * d.x()) + a * (d.x() * e2.y() - d.y() * e2.x());
          if (rate < 0 && a0 <= -rate * t_candidate && a0 / -rate < first) {
            first = a0 / -rate;
            offending = t;
          }
        }
        if (offending >= 0) {
          t_stop = first * options_.repair_stop_fraction;
          flip_t = -1;
        }
      }
      for (int v : moving) mu_[v] = 0;

      // 3. Move there; if rounding inverted something after all, halve the step.
      std::vector<Vec2> saved(moving.size());
      for (std::size_t i = 0; i < moving.size(); ++i) saved[i] = uv_[moving[i]];
      bool moved = false;
      for (int halvings = 0; halvings < 64 && t_stop > 0; ++halvings) {
        set_feature(k, inc, point_at(t_stop));
        if (!options_.keep_base_mesh_valid || base_valid(affected)) {
          moved = true;
          break;
        }
        warp_.pos[w] = x0;
        for (std::size_t i = 0; i < moving.size(); ++i) uv_[moving[i]] = saved[i];
        t_stop *= 0.5;
        flip_t = -1;
      }
      if (moved) {
        ++result_.steps;
        for (int t : inc) note_area(t);
        notify();
      }

      // 4. The event: flip before the degeneration.
      if (flip_t >= 0 && moved) {
        if (result_.events >= options_.max_events) return stuck("the warp used up max_events");
        for (int t : warp_.flip(flip_t, flip_i)) note_area(t);
        ++result_.events;
        notify();
      }
      if (moved && options_.keep_delaunay) {
        const std::size_t flips = warp_.make_delaunay([&](int t) { note_area(t); });
        result_.events += flips;
        if (flips > 0) notify();
      }
      // 5. The repair: relax the free vertices around the base triangle about to invert (kernel centroids; then
      // the max-min-area point; then centroids over a wider region).
      if (offending >= 0 && !repair(offending, false, options_.repair_rings) &&
          !repair(offending, true, options_.repair_rings) && !repair(offending, false, 4 * options_.repair_rings)) {
        return stuck("a base triangle ahead of it could not be repaired");
      }
    }
    return stuck("it used up max_steps_per_feature");
  }

  /// Why the last `move` returned kStuck.
  const std::string& stuck_reason() const { return stuck_reason_; }

  void notify() const {
    if (options_.observer) options_.observer(warp_.pos, warp_.tri);
  }
  void note_area(int t) {
    const Tri& T = warp_.tri[t];
    result_.min_warp_triangle_area =
        std::min(result_.min_warp_triangle_area, 0.5 * signed_double_area(warp_.pos[T[0]], warp_.pos[T[1]], warp_.pos[T[2]]));
  }

 private:
  void set_feature(int k, const std::vector<int>& inc, const Vec2& x) {
    const int w = kCorners + k;
    warp_.pos[w] = x;
    uv_[features_[k]] = x;
    for (int t : inc) {
      for (int pt : warp_.members[t]) uv_[pt] = warp_.evaluate(pt);
    }
  }

  bool base_valid(const std::vector<int>& tris) const {
    for (int t : tris) {
      const Tri& T = triangles_[t];
      if (orient2d(uv_[T[0]], uv_[T[1]], uv_[T[2]]) <= 0) return false;
    }
    return true;
  }

  /// The directed link edges (a, b) of v's star: v stays in its kernel while left of all of them.
  std::vector<std::pair<Vec2, Vec2>> link(int v) const {
    std::vector<std::pair<Vec2, Vec2>> out;
    for (int t : star_[v]) {
      const Tri& T = triangles_[t];
      const int i = T[0] == v ? 0 : T[1] == v ? 1 : 2;
      out.emplace_back(uv_[T[(i + 1) % 3]], uv_[T[(i + 2) % 3]]);
    }
    return out;
  }

  /// Relaxes the free vertices around base triangle t (about to invert): Gauss–Seidel sweeps that move each
  /// one to the centroid of the kernel of its star, which keeps every triangle positive (a vertex is moved
  /// only when the exact predicates confirm it). The region grows ring by ring until t has at least doubled
  /// its area; succeeds when t grew at all.
  bool repair(int t, bool maximin, int rings) {
    const Tri& T = triangles_[t];
    auto area = [&] { return signed_double_area(uv_[T[0]], uv_[T[1]], uv_[T[2]]); };
    auto contains = [](const std::vector<int>& list, int v) {
      return std::find(list.begin(), list.end(), v) != list.end();
    };
    const double before = area();
    std::vector<int> reached(T.begin(), T.end()), frontier = reached, region, relocated;
    for (int ring = 0; ring <= rings; ++ring) {
      for (int v : frontier) {
        if (!fixed_[v]) region.push_back(v);
      }
      for (int sweep = 0; sweep < options_.repair_sweeps; ++sweep) {
        for (int v : region) {
          Vec2 c;
          const auto l = link(v);
          if (maximin ? !max_min_area_point(l, c) : !kernel_centroid(l, c)) continue;
          const Vec2 old = uv_[v];
          uv_[v] = c;
          if (!base_valid(star_[v])) {
            uv_[v] = old;
          } else if (!contains(relocated, v)) {
            relocated.push_back(v);
          }
        }
      }
      if (area() >= 2 * before) break;
      std::vector<int> next;
      for (int v : frontier) {
        for (int s : star_[v]) {
          for (int u : triangles_[s]) {
            if (!contains(reached, u)) {
              reached.push_back(u);
              next.push_back(u);
            }
          }
        }
      }
      frontier.swap(next);
    }
    for (int v : relocated) {
      warp_.unbind(v);
      warp_.bind_anywhere(v);
    }
    result_.repaired_vertices += relocated.size();
    return area() > before;
  }

  const std::vector<Tri>& triangles_;
  std::vector<Vec2>& uv_;
  const std::vector<int>& features_;
  const FeatureWarpOptions& options_;
  FeatureWarpResult& result_;
  WarpMesh& warp_;
  std::vector<std::vector<int>> star_;  // base triangles around each vertex
  std::string stuck_reason_;
  std::vector<char> fixed_;             // features and boundary vertices: never repaired
  std::vector<double> mu_;              // scratch: feature weight of each moving point
  std::vector<unsigned> stamp_;         // scratch: base triangles already collected in this step
  unsigned epoch_ = 0;
};

void check_inputs(const std::vector<Tri>& triangles, const std::vector<Vec2>& uv, const std::vector<int>& features,
                  const std::vector<Vec2>& targets, const FeatureWarpOptions& options) {
  auto fail = [](const std::string& what) { throw InvalidInput("warp_features: " + what); };
  if (targets.size() != features.size()) fail("one target per feature is required");
  if (!(options.collision_distance > 0) || !(options.event_tolerance > 0) ||
      !(options.repair_stop_fraction > 0 && options.repair_stop_fraction < 1) || options.reorder_passes < 0) {
    fail("invalid options");
  }
  for (const Vec2& p : uv) {
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || p.x() < 0 || p.y() < 0 || p.x() > 1 || p.y() > 1) {
      fail("uv outside the unit square");
    }
  }
  for (const Tri& t : triangles) {
    for (int v : t) {
      if (v < 0 || v >= int(uv.size())) fail("triangle index out of range");
    }
    if (orient2d(uv[t[0]], uv[t[1]], uv[t[2]]) <= 0) fail("the input embedding has a flipped or degenerate triangle");
  }
  std::vector<char> seen(uv.size(), 0);
  for (int f : features) {
    if (f < 0 || f >= int(uv.size())) fail("feature index out of range");
    if (seen[f]++) fail("a vertex is listed twice as a feature");
    if (!strictly_inside(uv[f], 0.0)) fail("a feature is not an interior vertex");
  }
  const double cd = options.collision_distance;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    if (!std::isfinite(targets[k].x()) || !std::isfinite(targets[k].y()) || !strictly_inside(targets[k], cd)) {
      fail("target " + std::to_string(k) + " is not strictly inside the unit square");
    }
    for (std::size_t l = 0; l < k; ++l) {
      if ((targets[k] - targets[l]).norm() <= cd) fail("targets " + std::to_string(l) + " and " + std::to_string(k) + " coincide");
    }
  }
}

}  // namespace

std::vector<std::array<int, 3>> feature_warp_triangulation(const std::vector<Eigen::Vector2d>& feature_uv) {
  return delaunay(warp_points(feature_uv, "feature_warp_triangulation"), "feature_warp_triangulation");
}

std::vector<Eigen::Vector2d> average_feature_targets(
    const std::vector<std::vector<Eigen::Vector2d>>& feature_uv_per_model) {
  if (feature_uv_per_model.empty()) throw InvalidInput("average_feature_targets: no model");
  const std::size_t e = feature_uv_per_model.front().size();
  std::vector<Vec2> average(e, Vec2::Zero());
  for (const auto& model : feature_uv_per_model) {
    if (model.size() != e) throw InvalidInput("average_feature_targets: models have different feature counts");
    for (std::size_t k = 0; k < e; ++k) average[k] += model[k];
  }
  for (Vec2& a : average) a /= double(feature_uv_per_model.size());
  return average;
}

namespace {

/// True when a feature provably cannot reach its target: a triangle of its `star` whose vertices are all
/// features at their targets or boundary vertices would be flipped or flat, so no fold-free embedding has
/// it there.
bool provably_unreachable(const std::vector<Tri>& triangles, const std::vector<Vec2>& uv, const std::vector<int>& features,
                          const std::vector<Vec2>& targets, const std::vector<int>& star) {
  for (int t : star) {
    Vec2 p[3];
    bool all_fixed = true;
    for (int i = 0; i < 3 && all_fixed; ++i) {
      const int v = triangles[t][i];
      const auto it = std::find(features.begin(), features.end(), v);
      if (it != features.end()) {
        p[i] = targets[it - features.begin()];
      } else if (on_boundary(uv[v])) {
        p[i] = uv[v];
      } else {
        all_fixed = false;
      }
    }
    if (all_fixed && orient2d(p[0], p[1], p[2]) <= 0) return true;
  }
  return false;
}

/// One pass of `warp_features`: the features move in the order given. Sets `proved` to the number of
/// unreached features whose reason is a proof (no order can reach them) and lists in `failed` the others that
/// it gave up, in the order they moved. Stops early (`aborted`) once `limit` features are unreached: such
/// a pass cannot beat one that left `limit` unreached.
FeatureWarpResult warp_pass(const std::vector<Tri>& triangles, std::vector<Vec2>& uv, const std::vector<int>& features,
                            const std::vector<Vec2>& targets, const FeatureWarpOptions& options, std::size_t limit,
                            std::size_t& proved, std::vector<int>& failed, bool& aborted) {
  std::vector<Vec2> feature_uv;
  for (int f : features) feature_uv.push_back(uv[f]);
  std::vector<Vec2> points = warp_points(feature_uv, "warp_features");
  std::vector<Tri> warp_triangles = delaunay(points, "warp_features");

  FeatureWarpResult result;
  result.min_warp_triangle_area = std::numeric_limits<double>::infinity();
  WarpMesh warp(std::move(points), std::move(warp_triangles), uv);
  {
    std::vector<char> is_feature(uv.size(), 0);
    for (int f : features) is_feature[f] = 1;
    for (int p = 0; p < int(uv.size()); ++p) {
      if (!is_feature[p] && !on_boundary(uv[p])) warp.bind_anywhere(p);
    }
  }
  Warper warper(triangles, uv, features, options, result, warp);
  for (int t = 0; t < int(warp.tri.size()); ++t) warper.note_area(t);
  warper.notify();

  // Features move one at a time along straight paths. A path that passes a warp vertex is re-routed through
  // one waypoint beside it; a feature whose target is still occupied waits for the occupant to leave, and a
  // cycle of such waits (features exchanging places) is broken by parking one feature beside its path.
  const double cd = options.collision_distance;
  const int n = int(features.size());
  // Paths keep a clearance from other features proportional to the size of both features' base stars
  // (`FeatureWarpOptions::clearance`): squeezing a feature's star past another's is where the base mesh
  // folds. The hard limit is `collision_distance`.
  auto needed = [&](int w, int v, bool soft) {
    if (!soft || v < kCorners) return cd;
    return std::max(cd, options.clearance * (warper.star_radius(w - kCorners) + warper.star_radius(v - kCorners)));
  };
  auto blocker = [&](int w, const Vec2& a, const Vec2& b, bool soft) {
    int worst = -1;
    double ratio = 1;
    for (int v = 0; v < int(warp.pos.size()); ++v) {
      if (v == w) continue;
      const double r = distance_to_segment(warp.pos[v], a, b) / needed(w, v, soft);
      if (r < ratio) {
        ratio = r;
        worst = v;
      }
    }
    return worst;
  };
  // A point beside warp vertex `around` (or beside `a` when `around` < 0), off the line a→b, such that a→point
  // (and point→b when `through`) is clear.
  auto waypoint = [&](int w, const Vec2& a, const Vec2& b, int around, bool through, Vec2& out) {
    const Vec2 dir = (b - a).norm() > 0 ? Vec2((b - a).normalized()) : Vec2(1, 0);
    const Vec2 perp(-dir.y(), dir.x());
    const Vec2 center = around >= 0 ? warp.pos[around] : a;
    double room = std::min({center.x(), center.y(), 1 - center.x(), 1 - center.y()});
    for (int v = 0; v < int(warp.pos.size()); ++v) {
      if (v != w && v != around) room = std::min(room, (warp.pos[v] - center).norm());
    }
    const double want = around >= 0 ? 1.5 * needed(w, around, true) : 0.0;
    for (bool soft : {true, false}) {
      for (double scale : {0.5, 0.35, 0.25, 0.125, 0.0625}) {
        const double offset = std::max(scale * room, soft ? want : 0.0);
        for (double side : {1.0, -1.0}) {
          const Vec2 c = center + side * offset * perp;
          if (!strictly_inside(c, cd) || offset <= 2 * cd || offset >= room) continue;
          if (blocker(w, a, c, soft) >= 0 || (through && blocker(w, c, b, soft) >= 0)) continue;
          out = c;
          return true;
        }
      }
    }
    return false;
  };

  std::vector<std::string> reason(n);
  auto give_up = [&](int k, const std::string& why) {
    if (!reason[k].empty()) return;
    char at[96];
    const Vec2& x = warp.pos[kCorners + k];
    std::snprintf(at, sizeof at, " (stopped at (%.4f, %.4f), %.3g short of the target)", x.x(), x.y(),
                  (x - targets[k]).norm());
    reason[k] = why + at;
    failed.push_back(k);
  };
  // Targets that no embedding can reach: a base triangle whose three vertices are all fixed (features at their
  // targets, boundary vertices where they are) and that would not be positive there. The features of such a
  // triangle that have to move are reported and do not move.
  std::vector<int> pending;
  for (int k = 0; k < n; ++k) {
    if (uv[features[k]] == targets[k]) continue;  // a feature already there is not to blame
    if (provably_unreachable(triangles, uv, features, targets, warper.star_of(features[k]))) {
      ++proved;
      reason[k] = "a base triangle of it and other features or boundary vertices would be flipped or flat with "
                  "every feature at its target, so no fold-free embedding reaches it";
    }
    if (reason[k].empty() && uv[features[k]] != targets[k]) pending.push_back(k);
  }
  std::vector<int> legs(n, 0);
  int parks = 0, rounds = 0;
  bool force = false;  // after a round without progress: accept paths that only miss the soft clearance
  // A feature that stalls steps aside (back and to the left or right of its way, alternately, a little farther
  // each time) and then heads for its target again from there; after `options.sidesteps` of them it is given up.
  std::vector<int> sidesteps(n, 0);
  auto stalled = [&](int k, std::vector<int>& waiting) {
    const int w = kCorners + k;
    const Vec2 x = warp.pos[w];
    const Vec2 dir = (targets[k] - x).normalized(), perp(-dir.y(), dir.x());
    while (sidesteps[k] < options.sidesteps) {
      const double side = sidesteps[k] % 2 == 0 ? 1.0 : -1.0;
      const double length = options.sidestep_length * (1 + sidesteps[k] / 2);
      const Vec2 via = x + side * length * perp - 0.5 * options.sidestep_length * dir;
      ++sidesteps[k];
      if (!strictly_inside(via, options.sidestep_length) || blocker(w, x, via, false) >= 0) continue;
      ++result.detours;
      if (warper.move(k, via) == Warper::Outcome::kArrived) {
        legs[k] = 0;
        waiting.push_back(k);  // on from there in the next round
        return;
      }
    }
    give_up(k, "the warp " + warper.stuck_reason() +
                   (sidesteps[k] > 0 ? ", also after " + std::to_string(sidesteps[k]) + " steps aside" : ""));
  };
  auto over_limit = [&] { return (aborted = aborted || proved + failed.size() >= limit); };
  while (!pending.empty() && !over_limit()) {
    if (rounds++ > 8 * n + 8) {
      for (int k : pending) give_up(k, "features waiting for each other's places could not be untangled");
      break;
    }
    std::vector<int> waiting;
    bool progress = false;
    const bool was_forced = force;
    for (int k : pending) {
      if (over_limit()) break;
      const int w = kCorners + k;
      const Vec2 x0 = warp.pos[w];
      const int hard = blocker(w, x0, targets[k], false);
      const int soft = hard >= 0 ? hard : blocker(w, x0, targets[k], true);
      auto go = [&](const Vec2& to) {
        progress = true;
        return warper.move(k, to) == Warper::Outcome::kArrived;
      };
      if (soft < 0 || (hard < 0 && (force || legs[k] >= 2))) {
        if (!go(targets[k])) stalled(k, waiting);
        continue;
      }
      // Wait while the target is still taken (or crowded) by a feature that has yet to move.
      const bool occupant_pending =
          soft >= kCorners && std::find(pending.begin(), pending.end(), soft - kCorners) != pending.end();
      if ((warp.pos[soft] - targets[k]).norm() < needed(w, soft, hard < 0) && (hard >= 0 || (occupant_pending && !force))) {
        waiting.push_back(k);
        continue;
      }
      Vec2 via;
      if (legs[k] < 2 && waypoint(w, x0, targets[k], soft, true, via)) {
        ++result.detours;
        ++legs[k];
        if (!go(via)) {
          stalled(k, waiting);
          continue;
        }
        waiting.push_back(k);  // the second leg is checked in the next round
        continue;
      }
      if (hard < 0) {
        if (!go(targets[k])) stalled(k, waiting);
        continue;
      }
      waiting.push_back(k);
    }
    force = !progress;
    if (!progress && !waiting.empty() && was_forced) {  // a cycle of features waiting on each other
      const int k = waiting.front();
      const int w = kCorners + k;
      const Vec2 x0 = warp.pos[w];
      Vec2 park;
      if (parks++ > 2 * n || !waypoint(w, x0, targets[k], -1, false, park)) {
        for (int l : waiting) give_up(l, "features waiting for each other's places found no parking spot");
        break;
      }
      ++result.detours;
      if (warper.move(k, park) != Warper::Outcome::kArrived) {
        give_up(k, "the warp " + warper.stuck_reason() + " on the way to a parking spot");
        waiting.erase(waiting.begin());
      }
    }
    pending.swap(waiting);
  }
  for (int k = 0; k < n; ++k) {
    if (reason[k].empty() && uv[features[k]] != targets[k]) {
      if (aborted) {
        reason[k] = "not moved: the pass stopped early";
      } else {
        give_up(k, "the warp stopped short");
      }
    }
    if (reason[k].empty()) continue;
    result.unreached.push_back(k);
    result.unreached_reasons.push_back(reason[k]);
  }

  for (int k = 0; k < n; ++k) {
    result.max_feature_error = std::max(result.max_feature_error, (uv[features[k]] - targets[k]).norm());
  }
  return result;
}

// ---- Fallback: barrier relaxation (features a pass left short) -------------------------------------------
// The warp mesh moves every free vertex with the PL map of the moving feature's warp triangles, and a PL map
// of the vertices cannot undo the fans it squeezes: the features it gives up sit at the tip of long thin
// fans (docs/measurements.md, "Feature warp stress test"). Here the embedding is moved by an energy that is
// infinite at a flat triangle instead: the symmetric Dirichlet energy of the map from the input embedding
// (the rest shape) to the current one, E = Σ_t A_t (‖J_t‖² + ‖J_t⁻¹‖²), minimized by projected Newton steps
// over all free vertices at once (each step scaled to keep every triangle positive, then halved until E
// decreases and the exact predicate finds every triangle positive). The 24 rings around the short feature
// relax first; then the feature becomes a variable too, drawn to its target by a quadratic term whose weight doubles while
// it gains less than a tenth of its remaining way per round (so it moves together with the vertices around
// it), and it is placed exactly on its target once its star is positive there. Nothing ever flips, whatever
// the outcome.

/// Per base triangle: the rest shape's inverse edge matrix S (J = [x1 − x0, x2 − x0]·S) and area.
struct RestTriangle {
  Eigen::Matrix2d s;
  double area = 0;
};

/// d vec(J) / d(x0, y0, x1, y1, x2, y2) for J = [x1 − x0, x2 − x0]·S, vec(J) = (J00, J01, J10, J11):
/// J(r, c) = Σ_k X(r, k)·S(k, c) with X(r, 0) = p1_r − p0_r, X(r, 1) = p2_r − p0_r.
Eigen::Matrix<double, 4, 6> jacobian_derivative(const Eigen::Matrix2d& s) {
  Eigen::Matrix<double, 4, 6> dj = Eigen::Matrix<double, 4, 6>::Zero();
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) {
      const int row = 2 * r + c;
      dj(row, 2 * 1 + r) += s(0, c);
      dj(row, 2 * 2 + r) += s(1, c);
      dj(row, 2 * 0 + r) -= s(0, c) + s(1, c);
    }
  }
  return dj;
}

/// The rest shape of triangle `tr` at positions `rest`.
RestTriangle rest_triangle(const Tri& tr, const std::vector<Vec2>& rest) {
  Eigen::Matrix2d r;
  r.col(0) = rest[tr[1]] - rest[tr[0]];
  r.col(1) = rest[tr[2]] - rest[tr[0]];
  return {r.inverse(), 0.5 * r.determinant()};
}

/// J of a triangle at positions x: [x1 − x0, x2 − x0]·S.
Eigen::Matrix2d jacobian(const Tri& tr, const RestTriangle& rt, const std::vector<Vec2>& x) {
  Eigen::Matrix2d xm;
  xm.col(0) = x[tr[1]] - x[tr[0]];
  xm.col(1) = x[tr[2]] - x[tr[0]];
  return xm * rt.s;
}

/// One triangle's share of a projected Newton system: its gradient `gj` and Hessian `hj` in vec(J), the
/// Hessian's negative eigenvalues clamped to 0, chained to the triangle's vertices by `dj`
/// (jacobian_derivative) and added at the variables `dof` gives them (-1: held).
void add_triangle_terms(const Tri& tr, const Eigen::Vector4d& gj, const Eigen::Matrix4d& hj,
                        const Eigen::Matrix<double, 4, 6>& dj, const std::vector<int>& dof,
                        Eigen::VectorXd& grad, std::vector<Eigen::Triplet<double>>& entries) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(hj);
  const Eigen::Matrix4d psd =
      eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Matrix<double, 6, 1> gt = dj.transpose() * gj;
  const Eigen::Matrix<double, 6, 6> ht = dj.transpose() * psd * dj;
  for (int p = 0; p < 3; ++p) {
    const int vp = dof[tr[p]];
    if (vp < 0) continue;
    grad.segment<2>(2 * vp) += gt.segment<2>(2 * p);
    for (int q = 0; q < 3; ++q) {
      const int vq = dof[tr[q]];
      if (vq < 0) continue;
      for (int r = 0; r < 2; ++r) {
        for (int c = 0; c < 2; ++c) entries.emplace_back(2 * vp + r, 2 * vq + c, ht(2 * p + r, 2 * q + c));
      }
    }
  }
}

/// Solves H·step = −grad for the Newton system of `entries` (n variables, 2 coordinates each), its diagonal
/// raised by 10⁻⁹ of its largest entry so that a singular (projected) Hessian still factors. False when the
/// factorization or the solve fails or the step is not finite.
bool newton_step(const std::vector<Eigen::Triplet<double>>& entries, int n, const Eigen::VectorXd& grad,
                 Eigen::VectorXd& step) {
  Eigen::SparseMatrix<double> h(2 * n, 2 * n);
  h.setFromTriplets(entries.begin(), entries.end());
  double scale = 0;
  for (int k = 0; k < 2 * n; ++k) scale = std::max(scale, h.coeff(k, k));
  for (int k = 0; k < 2 * n; ++k) h.coeffRef(k, k) += 1e-9 * scale + 1e-300;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(h);
  if (solver.info() != Eigen::Success) return false;
  step = -solver.solve(grad);
  return solver.info() == Eigen::Success && step.allFinite();
}

class BarrierRelaxer {
 public:
  /// `budget`: Newton iterations left for all relaxers of one warp_features call (shared, decremented; at 0
  /// newton_region() does nothing, so walks stall and the features stay short).
  BarrierRelaxer(const std::vector<Tri>& triangles, const std::vector<Vec2>& rest, std::vector<Vec2>& uv,
                 const std::vector<int>& features, std::size_t& budget)
      : triangles_(triangles), uv_(uv), budget_(budget), free_(uv.size(), 1), star_(uv.size()) {
    for (int f : features) free_[f] = 0;
    for (std::size_t v = 0; v < uv.size(); ++v) {
      if (on_boundary(uv[v])) free_[v] = 0;
    }
    rest_.reserve(triangles.size());
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      rest_.push_back(rest_triangle(triangles[t], rest));
      for (int v : triangles[t]) star_[v].push_back(int(t));
    }
  }

  /// Rings around the moving feature that the walks relax.
  static constexpr int kRings = 24;
  const std::vector<int>& star(int v) const { return star_[v]; }

  /// A (feature) vertex that is a variable too, drawn toward `to` by weight·|x − to|².
  struct Pull {
    int v = -1;
    Vec2 to;
    double weight = 0;
  };
  /// Projected Newton iterations on E (plus the pulls' terms) over the free vertices within `rings` rings of
  /// `center` and the pulled vertices (the others held): per triangle the Hessian of A·(‖J‖² + ‖J⁻¹‖²) in J,
  /// its negative eigenvalues clamped to 0, chained to the triangle's vertices; one sparse solve for all; the
  /// step scaled to 0.8 of the largest one that keeps every triangle positive, then halved until the energy
  /// decreases and every triangle is positive by the exact predicate. Stops early when an iteration gains
  /// less than 10⁻⁹ of the energy or finds no step. Squeezed fans are chains of vertices that only move
  /// together: vertex-by-vertex steps creep, a joint step opens them.
  void newton_region(int center, int rings, int iterations, const std::vector<Pull>& pulls = {}) {
    std::vector<int> region = ring_region(center, rings);
    for (const Pull& p : pulls) {
      if (std::find(region.begin(), region.end(), p.v) == region.end()) region.push_back(p.v);
    }
    std::vector<int> dof(uv_.size(), -1);
    int n = 0;
    for (int v : region) {
      if (free_[v]) dof[v] = n++;
    }
    for (const Pull& p : pulls) {
      if (dof[p.v] < 0) dof[p.v] = n++;
    }
    if (n == 0) return;
    std::vector<int> tris;  // triangles with a free vertex of the region
    {
      std::vector<char> in(triangles_.size(), 0);
      for (int v : region) {
        if (dof[v] < 0) continue;
        for (int t : star_[v]) {
          if (!in[t]) {
            in[t] = 1;
            tris.push_back(t);
          }
        }
      }
    }
    const auto energy = [&](const std::vector<Vec2>& x) {
      double e = 0;
      for (const Pull& p : pulls) e += p.weight * (x[p.v] - p.to).squaredNorm();
      for (int t : tris) {
        const double te = triangle_energy(t, x);
        if (!std::isfinite(te)) return te;
        e += te;
      }
      return e;
    };
    for (int it = 0; it < iterations && budget_ > 0; ++it, --budget_) {
      std::vector<Eigen::Triplet<double>> entries;
      Eigen::VectorXd grad = Eigen::VectorXd::Zero(2 * n);
      for (int t : tris) {
        const Tri& tr = triangles_[t];
        const Eigen::Matrix2d j = jacobian(t, uv_);
        const double d = j.determinant();
        if (!(d > 0)) return;  // not expected: every accepted state is positive
        const double a = rest_[t].area, f = j.squaredNorm();
        // vec(J) = (J00, J01, J10, J11); derivatives in it.
        const Eigen::Vector4d vj(j(0, 0), j(0, 1), j(1, 0), j(1, 1));
        const Eigen::Vector4d df = 2 * vj, dd(j(1, 1), -j(1, 0), -j(0, 1), j(0, 0));
        Eigen::Matrix4d d2d = Eigen::Matrix4d::Zero();
        d2d(0, 3) = d2d(3, 0) = 1;
        d2d(1, 2) = d2d(2, 1) = -1;
        const double id = 1 / d, id2 = id * id;
        const Eigen::Vector4d gj = a * (df * (1 + id2) - 2 * f * id2 * id * dd);
        const Eigen::Matrix4d hj = a * (2 * (1 + id2) * Eigen::Matrix4d::Identity() -
                                        2 * id2 * id * (df * dd.transpose() + dd * df.transpose()) +
                                        6 * f * id2 * id2 * dd * dd.transpose() - 2 * f * id2 * id * d2d);
        add_triangle_terms(tr, gj, hj, jacobian_derivative(rest_[t].s), dof, grad, entries);
      }
      for (const Pull& pl : pulls) {
        const int p = dof[pl.v];
        grad.segment<2>(2 * p) += 2 * pl.weight * (uv_[pl.v] - pl.to);
        entries.emplace_back(2 * p, 2 * p, 2 * pl.weight);
        entries.emplace_back(2 * p + 1, 2 * p + 1, 2 * pl.weight);
      }
      Eigen::VectorXd step;
      if (!newton_step(entries, n, grad, step)) return;
      // Largest α keeping every triangle positive: its doubled area is a quadratic in α.
      double alpha_max = 1e300;
      for (int t : tris) {
        const Tri& tr = triangles_[t];
        Vec2 p[3], q[3];
        for (int k = 0; k < 3; ++k) {
          p[k] = uv_[tr[k]];
          q[k] = dof[tr[k]] < 0 ? Vec2(0, 0) : Vec2(step[2 * dof[tr[k]]], step[2 * dof[tr[k]] + 1]);
        }
        const auto cross = [](const Vec2& u, const Vec2& w) { return u.x() * w.y() - u.y() * w.x(); };
        const Vec2 e1 = p[1] - p[0], e2 = p[2] - p[0], f1 = q[1] - q[0], f2 = q[2] - q[0];
        const double c0 = cross(e1, e2), c1 = cross(e1, f2) + cross(f1, e2), c2 = cross(f1, f2);
        // Smallest positive root of c0 + c1·α + c2·α².
        double root = 1e300;
        if (std::abs(c2) < 1e-300) {
          if (c1 < 0) root = -c0 / c1;
        } else {
          const double disc = c1 * c1 - 4 * c2 * c0;
          if (disc >= 0) {
            const double sq = std::sqrt(disc);
            for (double r : {(-c1 - sq) / (2 * c2), (-c1 + sq) / (2 * c2)}) {
              if (r > 0) root = std::min(root, r);
            }
          }
        }
        alpha_max = std::min(alpha_max, root);
      }
      double alpha = std::min(1.0, 0.8 * alpha_max);
      const double e0 = energy(uv_);
      // Trial positions are written in place (the variables' start kept to go back), not into a copy of uv.
      std::vector<Vec2> start(static_cast<std::size_t>(n));
      for (int v : region) {
        if (dof[v] >= 0) start[static_cast<std::size_t>(dof[v])] = uv_[v];
      }
      double e1 = e0;
      for (int halving = 0; halving < 40 && alpha > 0; ++halving, alpha *= 0.5) {
        for (int v : region) {
          if (dof[v] >= 0)
            uv_[v] = start[static_cast<std::size_t>(dof[v])] + alpha * Vec2(step[2 * dof[v]], step[2 * dof[v] + 1]);
        }
        const double e = energy(uv_);
        if (e < e0 && positive(tris, uv_)) {
          e1 = e;
          break;
        }
      }
      if (e1 == e0) {  // no step accepted: back to the start
        for (int v : region) {
          if (dof[v] >= 0) uv_[v] = start[static_cast<std::size_t>(dof[v])];
        }
        return;
      }
      if (e0 - e1 < 1e-9 * e0) return;
    }
  }

  /// E over the triangles of the free vertices within `rings` rings of `center`.
  double region_energy(int center, int rings) const {
    double e = 0;
    std::vector<char> in(triangles_.size(), 0);
    for (int v : ring_region(center, rings)) {
      for (int t : star_[v]) {
        if (!in[t]) {
          in[t] = 1;
          e += triangle_energy(t, uv_);
        }
      }
    }
    return e;
  }

 private:
  std::vector<int> ring_region(int center, int rings) const {
    std::vector<int> region{center};
    std::vector<char> seen(uv_.size(), 0);
    seen[center] = 1;
    for (std::size_t begin = 0, ring = 0; ring < std::size_t(rings); ++ring) {
      const std::size_t end = region.size();
      for (std::size_t i = begin; i < end; ++i) {
        for (int t : star_[region[i]]) {
          for (int w : triangles_[t]) {
            if (!seen[w]) {
              seen[w] = 1;
              region.push_back(w);
            }
          }
        }
      }
      begin = end;
    }
    return region;
  }

  /// J of triangle t at positions x.
  Eigen::Matrix2d jacobian(int t, const std::vector<Vec2>& x) const {
    return geomip::jacobian(triangles_[t], rest_[t], x);
  }

  double triangle_energy(int t, const std::vector<Vec2>& x) const {
    const Eigen::Matrix2d j = jacobian(t, x);
    const double d = j.determinant();
    if (!(d > 0)) return std::numeric_limits<double>::infinity();
    return rest_[t].area * j.squaredNorm() * (1 + 1 / (d * d));
  }

  bool positive(const std::vector<int>& tris, const std::vector<Vec2>& x) const {
    for (int t : tris) {
      const Tri& tr = triangles_[t];
      if (orient2d(x[tr[0]], x[tr[1]], x[tr[2]]) <= 0) return false;
    }
    return true;
  }

  const std::vector<Tri>& triangles_;
  std::vector<Vec2>& uv_;
  std::size_t& budget_;
  std::vector<char> free_;
  std::vector<std::vector<int>> star_;
  std::vector<RestTriangle> rest_;
};

/// Draws feature f to `to` with the barrier relaxation (above): f is a variable of the Newton iterations,
/// with a quadratic term toward `to` whose weight doubles while it gains less than a tenth of its remaining
/// way per round, and is placed exactly on `to` once its star is positive there (true). False when it
/// stalled.
bool pull_feature(const std::vector<Tri>& triangles, std::vector<Vec2>& uv, BarrierRelaxer& relaxer, int f,
                  const Vec2& to) {
  constexpr int kRounds = 200, kIterations = 3, kMaxDoublings = 60;
  const int rings = BarrierRelaxer::kRings;
  const auto star_positive_at = [&](const Vec2& y) {
    for (int t : relaxer.star(f)) {
      const Tri& tr = triangles[t];
      Vec2 q[3] = {uv[tr[0]], uv[tr[1]], uv[tr[2]]};
      q[tr[0] == f ? 0 : tr[1] == f ? 1 : 2] = y;
      if (orient2d(q[0], q[1], q[2]) <= 0) return false;
    }
    return true;
  };
  double weight = 0;
  int doublings = 0;
  for (int round = 0; round < kRounds; ++round) {
    if (star_positive_at(to)) {
      uv[f] = to;
      relaxer.newton_region(f, rings, kIterations);
      return true;
    }
    const double before = (to - uv[f]).norm();
    if (weight == 0) weight = relaxer.region_energy(f, rings) / (before * before);
    relaxer.newton_region(f, rings, kIterations, {{f, to, weight}});
    const double after = (to - uv[f]).norm();
    if (after > 0.9 * before) {
      if (++doublings > kMaxDoublings) return false;
      weight *= 2;
    }
  }
  return false;
}

/// Walks feature k straight to its target with pull_feature(), after the region has relaxed (the warp may
/// have left it strained). True when it arrived exactly. (Routing around other features through a waypoint
/// beside them, as the warp does, left more features short here: 19 → 23 of 285 on the stress test's seeds
/// 77–79, measured with one order of the walk from the input.)
bool relax_walk(const std::vector<Tri>& triangles, std::vector<Vec2>& uv, BarrierRelaxer& relaxer,
                const std::vector<int>& features, int k, const Vec2& target) {
  constexpr int kFirstIterations = 50;
  const int f = features[k];
  relaxer.newton_region(f, BarrierRelaxer::kRings, kFirstIterations);
  return pull_feature(triangles, uv, relaxer, f, target);
}

/// relax_walk() for each feature of `short_ones` (indices into `features`) in turn, again over those that
/// stalled as long as some feature arrives (one may get through once others did); leaves the ones that did
/// not arrive in `short_ones`.
void walk_all(const std::vector<Tri>& triangles, std::vector<Vec2>& uv, BarrierRelaxer& relaxer,
              const std::vector<int>& features, const std::vector<Vec2>& targets, std::vector<int>& short_ones) {
  for (bool progress = true; progress && !short_ones.empty();) {
    progress = false;
    for (std::size_t i = 0; i < short_ones.size();) {
      if (relax_walk(triangles, uv, relaxer, features, short_ones[i], targets[short_ones[i]])) {
        progress = true;
        short_ones.erase(short_ones.begin() + std::ptrdiff_t(i));
      } else {
        ++i;
      }
    }
  }
}

/// Moves the vertices not `fixed` to the Tutte embedding (uniform weights) of x's fixed vertices; leaves x as
/// it is when the solve fails.
void tutte(const std::vector<Tri>& triangles, const std::vector<char>& fixed, std::vector<Vec2>& x) {
  std::vector<int> dof(x.size(), -1);
  int n = 0;
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (!fixed[v]) dof[v] = n++;
  }
  if (n == 0) return;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 2);
  for (const Tri& t : triangles) {
    // Each triangle adds its edges in both directions; a free vertex's edges are all interior (two triangles),
    // so each gets weight 2: uniform weights.
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, a}}) {
        if (dof[p] < 0) continue;
        entries.emplace_back(dof[p], dof[p], 1.0);
        if (dof[q] >= 0) {
          entries.emplace_back(dof[p], dof[q], -1.0);
        } else {
          rhs.row(dof[p]) += x[q].transpose();
        }
      }
    }
  }
  Eigen::SparseMatrix<double> l(n, n);
  l.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(l);
  if (solver.info() != Eigen::Success) return;
  const Eigen::MatrixXd y = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !y.allFinite()) return;
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (dof[v] >= 0) x[v] = y.row(dof[v]).transpose();
  }
}

/// Untangles x (Garanzha, Kaporin, Kudryavtseva, Protais, Ray, Sokolov 2021, "Foldover-free maps in 50
/// lines of code"): the vertices not `fixed` minimize F_ε = Σ_t A_t ((1 − θ)‖J_t‖² + θ(det J_t² + 1)) / χ(det
/// J_t, ε), χ(D, ε) = (D + √(ε² + D²)) / 2, J_t the map from `rest` (the input embedding), θ = 1/128, which
/// is finite for flipped triangles too, so the walk may pass through folded states that no barrier method can
/// cross; ε shrinks after every minimization as the paper's rule sets it (the worst triangle's χ falls by the
/// energy's relative decrease, at least a tenth), and F_ε tends to the barrier energy as ε → 0. Minimized
/// here by projected Newton steps (per-triangle Hessians in J with negative eigenvalues clamped, one sparse
/// solve over every free vertex, backtracking until F_ε falls). True as soon as the exact predicate finds
/// every triangle positive; false when the Newton iterations (`budget`, shared, decremented) or the rounds
/// run out first (x is then folded: the caller works on a copy).
bool untangle(const std::vector<Tri>& triangles, const std::vector<Vec2>& rest, std::vector<Vec2>& x,
              const std::vector<char>& fixed, std::size_t& budget) {
  constexpr double kTheta = 1.0 / 128;
  // Rounds (one ε each), Newton iterations per round, and rounds without fewer folded triangles before giving
  // up (the folded triangles went flat instead of unfolding: a local minimum). Stress test: successes after
  // 102–200 rounds; 30 Newton iterations per round or θ = 1/8 rescued none of the failures.
  constexpr int kRounds = 400, kNewton = 8, kStagnant = 60;
  const std::size_t nt = triangles.size();
  const auto all_positive = [&]() {
    for (const Tri& t : triangles) {
      if (orient2d(x[t[0]], x[t[1]], x[t[2]]) <= 0) return false;
    }
    return true;
  };
  if (all_positive()) return true;
  std::vector<RestTriangle> rt(nt);
  std::vector<Eigen::Matrix<double, 4, 6>> dj(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    rt[t] = rest_triangle(triangles[t], rest);
    dj[t] = jacobian_derivative(rt[t].s);
  }
  std::vector<int> dof(x.size(), -1);
  int n = 0;
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (!fixed[v]) dof[v] = n++;
  }
  if (n == 0) return false;
  const auto jac = [&](std::size_t t, const std::vector<Vec2>& y) {
    return jacobian(triangles[t], rt[t], y);
  };
  // χ in a form without cancellation for D < 0 (its derivatives in D below likewise).
  const auto chi = [](double eps, double d) {
    const double r = std::sqrt(eps * eps + d * d);
    return d > 0 ? 0.5 * (d + r) : 0.5 * eps * eps / (r - d);
  };
  const auto energy = [&](const std::vector<Vec2>& y, double eps, double& detmin) {
    double e = 0;
    detmin = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < nt; ++t) {
      const Eigen::Matrix2d j = jac(t, y);
      const double d = j.determinant();
      detmin = std::min(detmin, d);
      e += rt[t].area * ((1 - kTheta) * j.squaredNorm() + kTheta * (d * d + 1)) / chi(eps, d);
    }
    return e;
  };
  double detmin = 0;
  energy(x, 1, detmin);
  double eps = std::sqrt(1e-6 + 0.04 * std::min(detmin, 0.0) * std::min(detmin, 0.0));
  Eigen::Matrix4d d2d = Eigen::Matrix4d::Zero();
  d2d(0, 3) = d2d(3, 0) = 1;
  d2d(1, 2) = d2d(2, 1) = -1;
  std::size_t fewest_folded = triangles.size() + 1;
  int stagnant = 0;
  for (int round = 0; round < kRounds && budget > 0; ++round) {
    const double e_before = energy(x, eps, detmin);
    double e = e_before;
    for (int it = 0; it < kNewton && budget > 0; ++it, --budget) {
      std::vector<Eigen::Triplet<double>> entries;
      Eigen::VectorXd grad = Eigen::VectorXd::Zero(2 * n);
      for (std::size_t t = 0; t < nt; ++t) {
        const Tri& tr = triangles[t];
        if (dof[tr[0]] < 0 && dof[tr[1]] < 0 && dof[tr[2]] < 0) continue;
        const Eigen::Matrix2d j = jac(t, x);
        const double d = j.determinant(), tj = j.squaredNorm(), a = rt[t].area;
        const double r = std::sqrt(eps * eps + d * d), c = chi(eps, d);
        const double c1 = d > 0 ? 0.5 * (1 + d / r) : 0.5 * eps * eps / (r * (r - d)),
                     c2 = 0.5 * eps * eps / (r * r * r);
        const double h = 1 / c, h1 = -c1 / (c * c), h2 = -c2 / (c * c) + 2 * c1 * c1 / (c * c * c);
        const Eigen::Vector4d vj(j(0, 0), j(0, 1), j(1, 0), j(1, 1)),
            dd(j(1, 1), -j(1, 0), -j(0, 1), j(0, 0));
        const double nn = (1 - kTheta) * tj + kTheta * (d * d + 1);
        const Eigen::Vector4d gn = 2 * (1 - kTheta) * vj + 2 * kTheta * d * dd;
        const Eigen::Matrix4d hn =
            2 * (1 - kTheta) * Eigen::Matrix4d::Identity() + kTheta * (2 * dd * dd.transpose() + 2 * d * d2d);
        const Eigen::Vector4d gj = a * (h * gn + nn * h1 * dd);
        const Eigen::Matrix4d hj = a * (h * hn + h1 * (gn * dd.transpose() + dd * gn.transpose()) +
                                        nn * h2 * dd * dd.transpose() + nn * h1 * d2d);
        add_triangle_terms(tr, gj, hj, dj[t], dof, grad, entries);
      }
      Eigen::VectorXd step;
      if (!newton_step(entries, n, grad, step)) break;
      const double slope = grad.dot(step);
      if (!(slope < 0)) break;
      std::vector<Vec2> start = x;
      double accepted = e;
      for (double alpha = 1; alpha > 1e-12; alpha *= 0.5) {
        for (std::size_t v = 0; v < x.size(); ++v) {
          if (dof[v] >= 0) x[v] = start[v] + alpha * Vec2(step[2 * dof[v]], step[2 * dof[v] + 1]);
        }
        double dm = 0;
        const double trial = energy(x, eps, dm);
        if (trial <= e + 1e-4 * alpha * slope) {
          accepted = trial;
          break;
        }
      }
      if (accepted == e) {
        x.swap(start);
        break;
      }
      const bool small = e - accepted < 1e-9 * e;
      e = accepted;
      if (small) break;
    }
    std::size_t folded = 0;
    for (const Tri& t : triangles) folded += orient2d(x[t[0]], x[t[1]], x[t[2]]) <= 0;
    if (folded == 0) return true;
    energy(x, eps, detmin);
    if (folded < fewest_folded) {
      fewest_folded = folded;
      stagnant = 0;
    } else if (++stagnant > kStagnant) {
      return false;
    }
    const double sigma = std::max(1 - e / e_before, 0.1);
    const double mu = (1 - sigma) * chi(eps, detmin);
    eps = detmin < mu ? 2 * std::sqrt(mu * (mu - detmin)) : 1e-10;
    if (eps < 1e-9) return false;  // the folded triangles went flat instead of unfolding: a local minimum
  }
  return all_positive();
}

}  // namespace

FeatureWarpResult warp_features(const std::vector<std::array<int, 3>>& triangles, std::vector<Eigen::Vector2d>& uv,
                                const std::vector<int>& features, const std::vector<Eigen::Vector2d>& targets,
                                const FeatureWarpOptions& options) {
  check_inputs(triangles, uv, features, targets, options);
  // Passes: each starts again from the input uv and moves first the features the previous pass left unreached
  // (in the order they moved), then the others in the previous pass's order; only the last pass steps aside.
  const int n = int(features.size());
  const int passes = 1 + options.reorder_passes;
  std::vector<int> order(n);
  for (int k = 0; k < n; ++k) order[k] = k;
  FeatureWarpResult best, effort;
  effort.min_warp_triangle_area = std::numeric_limits<double>::infinity();
  std::vector<Vec2> best_uv;
  std::vector<int> failed;  // indices into `features` the last pass gave up, in the order they moved
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<int> next = failed;
    for (int k : order) {
      if (std::find(next.begin(), next.end(), k) == next.end()) next.push_back(k);
    }
    order.swap(next);
    std::vector<int> pass_features;
    std::vector<Vec2> pass_targets;
    for (int k : order) {
      pass_features.push_back(features[k]);
      pass_targets.push_back(targets[k]);
    }
    FeatureWarpOptions pass_options = options;
    if (pass + 1 < passes) pass_options.sidesteps = 0;
    std::vector<Vec2> trial = uv;
    std::size_t proved = 0;
    bool aborted = false;
    std::vector<int> pass_failed;
    FeatureWarpResult r = warp_pass(triangles, trial, pass_features, pass_targets, pass_options,
                                    pass == 0 ? features.size() + 1 : best.unreached.size(), proved, pass_failed,
                                    aborted);
    effort.events += r.events;
    effort.repaired_vertices += r.repaired_vertices;
    effort.steps += r.steps;
    effort.detours += r.detours;
    effort.min_warp_triangle_area = std::min(effort.min_warp_triangle_area, r.min_warp_triangle_area);
    failed.clear();
    std::sort(pass_failed.begin(), pass_failed.end());
    for (int i : pass_failed) failed.push_back(order[i]);
    std::vector<std::pair<int, std::string>> unreached;  // back to indices into `features`
    for (std::size_t i = 0; i < r.unreached.size(); ++i) unreached.emplace_back(order[r.unreached[i]], r.unreached_reasons[i]);
    std::sort(unreached.begin(), unreached.end());
    r.unreached.clear();
    r.unreached_reasons.clear();
    for (auto& [k, why] : unreached) {
      r.unreached.push_back(k);
      r.unreached_reasons.push_back(std::move(why));
    }
    if (pass == 0 || (!aborted && r.unreached.size() < best.unreached.size())) {
      best = std::move(r);
      best_uv.swap(trial);
    }
    effort.passes = pass + 1;
    if (best.unreached.size() == proved) break;  // every target reached, or no order can do better
  }
  if (options.relax_unreached && !best.unreached.empty()) {
    // The features the passes left short (and no proof rules out) walk on with the barrier relaxation, from
    // the best pass's embedding; the input embedding is the rest shape.
    std::size_t budget = options.relax_iterations;
    BarrierRelaxer relaxer(triangles, uv, best_uv, features, budget);
    std::vector<int> left;
    for (int k : best.unreached) {
      if (!provably_unreachable(triangles, uv, features, targets, relaxer.star(features[k]))) left.push_back(k);
    }
    walk_all(triangles, best_uv, relaxer, features, targets, left);
    // Features still short: every feature is placed on its target (the provably unreachable ones stay where
    // they are) and the free vertices are untangled, from the best embedding so far, then (with `starts` = 3)
    // from the input embedding and from the Tutte embedding of the pinned vertices; the first fold-free result is
    // kept and relaxed around the features it brought in. (Stress test, seeds 77 / 78 / 79: 1 / 5 / 4 short →
    // 0 / 2 / 0; each start succeeds where the others fail. Untangling before the walks from the input, which
    // then run only when it fails, leaves the same features short in 0.6× / 0.8× / 0.4× the time.)
    std::vector<char> fixed(uv.size(), 0);
    for (std::size_t v = 0; v < uv.size(); ++v) fixed[v] = on_boundary(uv[v]);
    for (int f : features) fixed[f] = 1;
    const auto untangle_short = [&](int starts) {
      for (int from = 0; from < starts && !left.empty(); ++from) {
        std::vector<Vec2> x = from == 0 ? best_uv : uv;
        for (std::size_t k = 0; k < features.size(); ++k) {
          const bool stays =
              best_uv[features[k]] != targets[k] && std::find(left.begin(), left.end(), int(k)) == left.end();
          x[features[k]] = stays ? best_uv[features[k]] : targets[k];
        }
        if (from == 2) tutte(triangles, fixed, x);
        if (!untangle(triangles, uv, x, fixed, budget)) continue;
        best_uv.swap(x);
        BarrierRelaxer polish(triangles, uv, best_uv, features, budget);
        for (int k : left) polish.newton_region(features[k], BarrierRelaxer::kRings, 50);
        best.untangled = left.size();
        left.clear();
        return;
      }
    };
    untangle_short(3);
    if (!left.empty()) {
      // Still short: every feature walks again from the input embedding (no squeezed fans to undo), in up to
      // kOrders orders (the ones still short first, then last, then everything reversed, then the first order
      // rotated by 1, 2, 3); the order that leaves the fewest features short is kept when that is fewer than
      // before. (Measured on the stress test's seeds 78 / 79: 1 order 10 / 8 short, 3 orders 7 / 6, 6 orders
      // 5 / 4, 12 orders 5 / 4.)
      constexpr int kOrders = 6;
      std::vector<int> first = left, rest;
      for (int k = 0; k < int(features.size()); ++k) {
        if (std::find(first.begin(), first.end(), k) == first.end() && uv[features[k]] != targets[k] &&
            !provably_unreachable(triangles, uv, features, targets, relaxer.star(features[k])))
          rest.push_back(k);
      }
      std::size_t fewest = 0;
      for (std::size_t k = 0; k < features.size(); ++k) fewest += best_uv[features[k]] != targets[k];
      std::vector<std::vector<int>> tried;
      bool adopted = false;
      for (int o = 0; o < kOrders && !left.empty(); ++o) {
        std::vector<int> queue = o == 1 ? rest : first;
        queue.insert(queue.end(), (o == 1 ? first : rest).begin(), (o == 1 ? first : rest).end());
        if (o == 2) std::reverse(queue.begin(), queue.end());
        if (o >= 3) std::rotate(queue.begin(), queue.begin() + std::ptrdiff_t((o - 2) % queue.size()), queue.end());
        if (std::find(tried.begin(), tried.end(), queue) != tried.end()) continue;  // a few features: repeats
        tried.push_back(queue);
        std::vector<Vec2> fresh = uv;
        BarrierRelaxer from_input(triangles, uv, fresh, features, budget);
        walk_all(triangles, fresh, from_input, features, targets, queue);
        std::size_t short_now = 0;
        for (std::size_t k = 0; k < features.size(); ++k) short_now += fresh[features[k]] != targets[k];
        if (short_now < fewest) {
          fewest = short_now;
          best_uv.swap(fresh);
          left = queue;
          adopted = true;
        }
      }
      if (adopted) untangle_short(1);  // from the order's embedding; the other starts failed already
    }
    best.relax_iterations = options.relax_iterations - budget;
    // Every feature short now (the route from the input may leave short one that the warp had brought in).
    std::vector<int> unreached;
    std::vector<std::string> reasons;
    best.relaxed = 0;
    for (int k = 0; k < int(features.size()); ++k) {
      const auto was = std::find(best.unreached.begin(), best.unreached.end(), k);
      const bool passes_left_it = was != best.unreached.end();
      if (best_uv[features[k]] == targets[k]) {
        best.relaxed += passes_left_it;
        continue;
      }
      unreached.push_back(k);
      std::string why = passes_left_it ? best.unreached_reasons[std::size_t(was - best.unreached.begin())]
                                       : std::string("the warp's passes brought it in, but not in the relaxation "
                                                     "from the input embedding that brought in more features");
      if (std::find(left.begin(), left.end(), k) != left.end()) {
        char at[256];
        const Vec2& x = best_uv[features[k]];
        std::snprintf(at, sizeof at,
                      "; the barrier relaxation stalled too, at (%.4f, %.4f), %.3g short of the target, and untangling "
                      "found no fold-free embedding with the features on their targets",
                      x.x(), x.y(), (x - targets[k]).norm());
        why += at;
      }
      reasons.push_back(std::move(why));
    }
    best.unreached.swap(unreached);
    best.unreached_reasons.swap(reasons);
    best.max_feature_error = 0;
    for (std::size_t k = 0; k < features.size(); ++k)
      best.max_feature_error = std::max(best.max_feature_error, (best_uv[features[k]] - targets[k]).norm());
  }
  uv.swap(best_uv);
  best.events = effort.events;
  best.repaired_vertices = effort.repaired_vertices;
  best.steps = effort.steps;
  best.detours = effort.detours;
  best.min_warp_triangle_area = effort.min_warp_triangle_area;
  best.passes = effort.passes;
  for (const Tri& t : triangles) {
    if (orient2d(uv[t[0]], uv[t[1]], uv[t[2]]) <= 0) ++best.flipped_triangles;
  }
  if (options.keep_base_mesh_valid && best.flipped_triangles > 0) {
    throw SolverFailure("warp_features: " + std::to_string(best.flipped_triangles) +
                        " base triangles flipped despite repair");
  }
  return best;
}

}  // namespace geomip
