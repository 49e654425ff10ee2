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
    for (int t : warper.star_of(features[k])) {
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
      if (all_fixed && orient2d(p[0], p[1], p[2]) <= 0) {
        ++proved;
        reason[k] = "a base triangle of it and other features or boundary vertices would be flipped or flat with "
                    "every feature at its target, so no fold-free embedding reaches it";
        break;
      }
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
