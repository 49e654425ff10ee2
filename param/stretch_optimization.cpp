#include "param/stretch_optimization.h"

#include "mesh/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace geomip {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

inline double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// The 3D data of one triangle that stretch needs, independent of which corner moves: squared edge lengths
/// opposite each corner and the 3D area. Γ²+γ² and Γγ depend on the 3D triangle only through these (the Gram
/// matrix of its edges), so no local frame is needed.
struct TriangleMetric {
  std::array<double, 3> opposite_sq;  ///< |q_{i+1} − q_{i+2}|²
  double area3;
};

TriangleMetric triangle_metric(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                               const Eigen::Vector3d& q2) {
  return {{(q2 - q1).squaredNorm(), (q2 - q0).squaredNorm(), (q1 - q0).squaredNorm()},
          0.5 * (q1 - q0).cross(q2 - q0).norm()};
}

/// The same in the metric M (lengths eᵀMe, area from the Gram matrix of two edges in M).
TriangleMetric triangle_metric(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                               const Eigen::Vector3d& q2, const Eigen::Matrix3d& m) {
  const Eigen::Vector3d e0 = q2 - q1, e1 = q2 - q0, e2 = q1 - q0;
  const double g11 = e2.dot(m * e2), g22 = e1.dot(m * e1), g12 = e2.dot(m * e1);
  return {{e0.dot(m * e0), g22, g11}, 0.5 * std::sqrt(std::max(0.0, g11 * g22 - g12 * g12))};
}

TriangleMetric triangle_metric(const std::vector<Eigen::Vector3d>& positions,
                               const std::vector<Eigen::Matrix3d>* metrics, int a, int b, int c) {
  if (!metrics) return triangle_metric(positions[a], positions[b], positions[c]);
  const Eigen::Matrix3d m = ((*metrics)[a] + (*metrics)[b] + (*metrics)[c]) / 3.0;
  return triangle_metric(positions[a], positions[b], positions[c], m);
}

/// One ring triangle seen from the moving vertex v: v is corner 0, corners 1 and 2 follow counter-clockwise.
struct RingTriangle {
  Eigen::Vector2d p1, p2;
  double len0_sq, len1_sq, len2_sq;  ///< 3D squared lengths opposite corners 0 (v), 1, 2
  double area3;
  double weight = 1;  ///< sampling weight of the triangle in the L2 term (VertexOptimizationOptions)
};

/// Coefficients of one ring triangle along the line p + t·d:
///   2·A2(t) = c0 + c1·t,   N(t) = n0 + n1·t + n2·t²,   Γ²+γ² = N / (2·A2)²,   Γ·γ = 2·A3 / (2·A2).
/// N is the cotangent form Σ_i L_i² (d_ij·d_ik) of 4·A2²·‖J‖_F² (L_i: 3D length opposite corner i, d_ij: uv
/// edge vectors leaving corner i).
struct LineTerm {
  double n0, n1, n2, c0, c1, area3;
  double weighted_area3;  ///< area3 · weight (the product accumulate() forms first)
};

struct Weights {
  double l2;    ///< (1−w) / Σ_ring A3, multiplies Σ A3·(Γ²+γ²)/2
  double linf;  ///< w, multiplies max Γ²
};

double blend_weight(const VertexOptimizationOptions& options) {
  switch (options.norm) {
    case StretchNorm::kL2:
      return 0.0;
    case StretchNorm::kLinf:
      return 1.0;
    case StretchNorm::kBlend:
      return options.linf_weight;
  }
  return 0.0;
}

Weights ring_weights(const RingTriangle* ring, std::size_t n, double w) {
  double sum_a3 = 0;
  for (std::size_t i = 0; i < n; ++i) sum_a3 += ring[i].area3 * ring[i].weight;
  return {sum_a3 > 0 ? (1 - w) / sum_a3 : 0.0, w};
}

/// E(v) from per-triangle (Γ²+γ², 2·A2) values; adds one triangle to running sums. `weighted_area3` is
/// area3 · weight.
inline void accumulate(double trace, double twice_a2, double area3, double weighted_area3, const Weights& w,
                       double& sum, double& max_sq) {
  sum += weighted_area3 * trace;
  if (w.linf > 0) {
    const double det = 2 * area3 / twice_a2;  // Γγ = A3 / A2
    const double big_sq = 0.5 * (trace + std::sqrt(std::max(0.0, trace * trace - 4 * det * det)));
    max_sq = std::max(max_sq, big_sq);
  }
}

/// N = 4·A2²·(Γ²+γ²) in the cotangent form, from the 3D squared lengths opposite corners 0, 1, 2 and the uv
/// edges u1, u2 leaving corner 0.
inline double cotangent_numerator(double len0_sq, double len1_sq, double len2_sq, const Eigen::Vector2d& u1,
                                  const Eigen::Vector2d& u2) {
  return len0_sq * u1.dot(u2) - len1_sq * u1.dot(u2 - u1) - len2_sq * u2.dot(u1 - u2);
}

/// E(v) with v at `p` (direct formula; +inf if a ring triangle has uv area <= 0).
double ring_energy(const Eigen::Vector2d& p, const RingTriangle* ring, std::size_t n, const Weights& w) {
  double sum = 0, max_sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const RingTriangle& r = ring[i];
    const Eigen::Vector2d u1 = r.p1 - p, u2 = r.p2 - p;
    const double c = cross2(u1, u2);
    if (!(c > 0)) return kInf;
    const double num = cotangent_numerator(r.len0_sq, r.len1_sq, r.len2_sq, u1, u2);
    accumulate(num / (c * c), c, r.area3, r.area3 * r.weight, w, sum, max_sq);
  }
  return 0.5 * w.l2 * sum + w.linf * max_sq;
}

/// E(v) at p + t·d from the line coefficients (+inf outside the no-flip interval).
double line_energy(double t, const LineTerm* terms, std::size_t n, const Weights& w) {
  double sum = 0, max_sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const LineTerm& l = terms[i];
    const double c = l.c0 + l.c1 * t;
    if (!(c > 0)) return kInf;
    accumulate((l.n0 + t * (l.n1 + t * l.n2)) / (c * c), c, l.area3, l.weighted_area3, w, sum, max_sq);
  }
  return 0.5 * w.l2 * sum + w.linf * max_sq;
}

/// Brent's bracketed parabolic minimization (Brent 1973, "localmin") of f on [a, b] starting from x0 ∈ (a, b)
/// with f(x0) = f0. Returns the best (x, f(x)) seen, so f(x) <= f0.
template <typename F>
std::pair<double, double> brent_minimize(const F& f, double a, double b, double x0, double f0, double tol,
                                         int max_evaluations) {
  constexpr double kGolden = 0.3819660112501051;  // (3 − √5) / 2
  double x = x0, w = x0, v = x0, fx = f0, fw = f0, fv = f0;
  double d = 0, e = 0;
  for (int evaluation = 0; evaluation < max_evaluations; ++evaluation) {
    const double m = 0.5 * (a + b);
    const double tol1 = 1e-10 * std::abs(x) + tol, tol2 = 2 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {  // try a parabola through (v, w, x)
      double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0)
        p = -p;
      else
        q = -q;
      const double e_prev = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m ? b : a) - x;
      d = kGolden * e;
    }
    const double u = x + (std::abs(d) >= tol1 ? d : (d > 0 ? tol1 : -tol1));
    const double fu = f(u);
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w, fv = fw;
      w = x, fw = fx;
      x = u, fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw;
        w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  return {x, fx};
}

/// The core of optimize_vertex on prepared ring data: moves p, returns E at the final p (no sqrt).
/// `terms` is scratch space of at least n entries (no allocation here).
double optimize_point(Eigen::Vector2d& p, const RingTriangle* ring, std::size_t n,
                      const VertexOptimizationOptions& options, std::mt19937& rng, LineTerm* terms) {
  const Weights weights = ring_weights(ring, n, blend_weight(options));
  double energy = ring_energy(p, ring, n, weights);
  if (n == 0 || !std::isfinite(energy)) return energy;

  std::uniform_real_distribution<double> angle_distribution(0.0, 2 * kPi);
  const double angle0 = angle_distribution(rng);
  for (int k = 0; k < options.num_directions; ++k) {
    const double angle = angle0 + k * kPi / options.num_directions;
    const Eigen::Vector2d d(std::cos(angle), std::sin(angle));

    // Line coefficients and the interval (lo, hi) of t in which every ring triangle keeps positive area.
    double lo = -kInf, hi = kInf, reach = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const RingTriangle& r = ring[i];
      const Eigen::Vector2d u1 = r.p1 - p, u2 = r.p2 - p, u21 = u2 - u1;
      LineTerm& l = terms[i];
      l.c0 = cross2(u1, u2);
      l.c1 = cross2(u21, d);
      l.n0 = r.len0_sq * u1.dot(u2) - r.len1_sq * u1.dot(u21) + r.len2_sq * u2.dot(u21);
      l.n1 = -r.len0_sq * d.dot(u1 + u2) + (r.len1_sq - r.len2_sq) * d.dot(u21);
      l.n2 = r.len0_sq;
      l.area3 = r.area3;
      l.weighted_area3 = r.area3 * r.weight;
      if (l.c1 < 0) hi = std::min(hi, -l.c0 / l.c1);
      if (l.c1 > 0) lo = std::max(lo, -l.c0 / l.c1);
      reach = std::max(reach, std::max(u1.squaredNorm(), u2.squaredNorm()));
    }
    const double cap = options.max_step * std::sqrt(reach);
    lo = std::max(lo, -cap) * options.bracket_fraction;
    hi = std::min(hi, cap) * options.bracket_fraction;
    if (!(lo < 0 && hi > 0)) continue;

    const auto f = [&](double t) { return line_energy(t, terms, n, weights); };
    const auto [t, f_t] =
        brent_minimize(f, lo, hi, 0.0, f(0.0), options.tolerance * (hi - lo), options.max_evaluations);
    if (!(f_t < energy) || t == 0) continue;
    // Accept only what the direct formula confirms: positive areas (ring_energy is +inf otherwise) and a
    // lower E.
    const Eigen::Vector2d candidate = p + t * d;
    const double candidate_energy = ring_energy(candidate, ring, n, weights);
    if (candidate_energy < energy) {
      p = candidate;
      energy = candidate_energy;
    }
  }
  return energy;
}

void check_vertex_options(const char* function, const VertexOptimizationOptions& o) {
  const bool ok = o.linf_weight >= 0 && o.linf_weight <= 1 && o.num_directions >= 1 &&
                  o.bracket_fraction > 0 && o.bracket_fraction < 1 && o.max_step > 0 && o.tolerance > 0 &&
                  o.max_evaluations >= 1 && (o.vertex_weights == nullptr || !o.vertex_weights->empty());
  if (!ok) throw InvalidInput(std::string(function) + ": invalid VertexOptimizationOptions");
}

/// Ring of v in RingTriangle form, from raw positions (optimize_vertex, local_stretch), into `out`.
void build_ring(const char* function, int v, const std::vector<int>& ring,
                const std::vector<Eigen::Vector3d>& positions,
                const std::vector<std::array<int, 3>>& triangles, const std::vector<Eigen::Vector2d>& uv,
                const std::vector<double>* vertex_weights, const std::vector<Eigen::Matrix3d>* vertex_metrics,
                std::vector<RingTriangle>& out) {
  const auto fail = [function](const std::string& what) {
    throw InvalidInput(std::string(function) + ": " + what);
  };
  if (vertex_weights && vertex_weights->size() != positions.size()) {
    fail(std::to_string(vertex_weights->size()) + " vertex weights for " + std::to_string(positions.size()) +
         " vertices");
  }
  if (vertex_metrics && vertex_metrics->size() != positions.size()) {
    fail(std::to_string(vertex_metrics->size()) + " metric tensors for " + std::to_string(positions.size()) +
         " vertices");
  }
  if (uv.size() != positions.size()) {
    fail(std::to_string(uv.size()) + " uv coordinates for " + std::to_string(positions.size()) + " vertices");
  }
  if (v < 0 || static_cast<std::size_t>(v) >= uv.size()) fail("vertex " + std::to_string(v) + " out of range");
  out.clear();
  for (int f : ring) {
    if (f < 0 || static_cast<std::size_t>(f) >= triangles.size())
      fail("ring triangle " + std::to_string(f) + " out of range");
    const auto& t = triangles[f];
    for (int i : t) {
      if (i < 0 || static_cast<std::size_t>(i) >= uv.size())
        fail("triangle " + std::to_string(f) + " has a vertex index out of range");
    }
    const int corner = t[0] == v ? 0 : t[1] == v ? 1 : t[2] == v ? 2 : -1;
    if (corner < 0)
      fail("ring triangle " + std::to_string(f) + " does not contain vertex " + std::to_string(v));
    const int a = t[(corner + 1) % 3], b = t[(corner + 2) % 3];
    const TriangleMetric m = triangle_metric(positions, vertex_metrics, v, a, b);
    const double weight =
        vertex_weights ? ((*vertex_weights)[v] + (*vertex_weights)[a] + (*vertex_weights)[b]) / 3 : 1.0;
    out.push_back({uv[a], uv[b], m.opposite_sq[0], m.opposite_sq[1], m.opposite_sq[2], m.area3, weight});
  }
}

/// Per-thread scratch of optimize_vertex() and local_stretch(), so that the per-vertex calls of
/// coarse-to-fine allocate nothing once the largest ring has been seen.
struct RingScratch {
  std::vector<RingTriangle> ring;
  std::vector<LineTerm> terms;
};
RingScratch& ring_scratch() {
  thread_local RingScratch scratch;
  return scratch;
}

}  // namespace

double triangle_l2_energy(const Eigen::Vector3d q[3], const Eigen::Vector2d uv[3],
                          const Eigen::Matrix3d& metric) {
  const TriangleMetric t = triangle_metric(q[0], q[1], q[2], metric);
  const Eigen::Vector2d u1 = uv[1] - uv[0], u2 = uv[2] - uv[0];
  const double c = cross2(u1, u2);
  if (!(c > 0)) return kInf;
  return t.area3 * 0.5 * cotangent_numerator(t.opposite_sq[0], t.opposite_sq[1], t.opposite_sq[2], u1, u2) /
         (c * c);
}

double optimize_vertex(int v, const std::vector<int>& ring, const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<std::array<int, 3>>& triangles, std::vector<Eigen::Vector2d>& uv,
                       const VertexOptimizationOptions& options, std::mt19937& rng) {
  check_vertex_options("optimize_vertex", options);
  RingScratch& scratch = ring_scratch();
  const std::vector<RingTriangle>& r = scratch.ring;
  build_ring("optimize_vertex", v, ring, positions, triangles, uv, options.vertex_weights,
             options.vertex_metrics, scratch.ring);
  if (!uv[v].allFinite())
    throw InvalidInput("optimize_vertex: uv of vertex " + std::to_string(v) + " not finite");
  if (scratch.terms.size() < r.size()) scratch.terms.resize(r.size());
  Eigen::Vector2d p = uv[v];
  const double energy = optimize_point(p, r.data(), r.size(), options, rng, scratch.terms.data());
  uv[v] = p;
  return std::sqrt(energy);
}

double local_stretch(int v, const std::vector<int>& ring, const std::vector<Eigen::Vector3d>& positions,
                     const std::vector<std::array<int, 3>>& triangles, const std::vector<Eigen::Vector2d>& uv,
                     const VertexOptimizationOptions& options) {
  check_vertex_options("local_stretch", options);
  std::vector<RingTriangle>& r = ring_scratch().ring;
  build_ring("local_stretch", v, ring, positions, triangles, uv, options.vertex_weights,
             options.vertex_metrics, r);
  return std::sqrt(
      ring_energy(uv[v], r.data(), r.size(), ring_weights(r.data(), r.size(), blend_weight(options))));
}

StretchOptimizationResult optimize_stretch(const std::vector<Eigen::Vector3d>& positions,
                                           const std::vector<std::array<int, 3>>& triangles,
                                           std::vector<Eigen::Vector2d>& uv, const std::vector<char>& locked,
                                           const StretchOptimizationOptions& options) {
  const std::size_t nv = positions.size();
  if (locked.size() != nv) {
    throw InvalidInput("optimize_stretch: locked has " + std::to_string(locked.size()) + " entries for " +
                       std::to_string(nv) + " vertices");
  }
  if (!(options.threshold >= 0)) throw InvalidInput("optimize_stretch: threshold must be >= 0");
  if (!(options.min_local_stretch >= 0) || !std::isfinite(options.min_local_stretch))
    throw InvalidInput("optimize_stretch: min_local_stretch must be finite and >= 0");
  check_vertex_options("optimize_stretch", options.vertex);
  if (uv.size() != nv) {
    throw InvalidInput("optimize_stretch: " + std::to_string(uv.size()) + " uv coordinates for " +
                       std::to_string(nv) + " vertices");
  }
  for (std::size_t i = 0; i < nv; ++i) {
    if (!uv[i].allFinite()) {
      throw InvalidInput("optimize_stretch: uv of vertex " + std::to_string(i) + " not finite");
    }
  }
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (int v : triangles[f]) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        throw InvalidInput("optimize_stretch: triangle " + std::to_string(f) + " has vertex index " +
                           std::to_string(v) + " out of range");
      }
    }
  }

  StretchOptimizationResult result;
  result.before = mesh_stretch(positions, triangles, uv);  // also rejects no triangles and zero 3D area

  // Vertex → incident triangles (CSR), and the per-triangle 3D metric, computed once.
  std::vector<int> offsets(nv + 1, 0);
  for (const auto& t : triangles) {
    for (int i : t) ++offsets[i + 1];
  }
  for (std::size_t i = 0; i < nv; ++i) offsets[i + 1] += offsets[i];
  std::vector<int> incident(offsets[nv]);
  {
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      for (int i : triangles[f]) incident[fill[i]++] = static_cast<int>(f);
    }
  }
  const std::vector<double>* vertex_weights = options.vertex.vertex_weights;
  if (vertex_weights && vertex_weights->size() != nv) {
    throw InvalidInput("optimize_stretch: " + std::to_string(vertex_weights->size()) + " vertex weights for " +
                       std::to_string(nv) + " vertices");
  }
  if (options.vertex.vertex_metrics && options.vertex.vertex_metrics->size() != nv) {
    throw InvalidInput("optimize_stretch: " + std::to_string(options.vertex.vertex_metrics->size()) +
                       " metric tensors for " + std::to_string(nv) + " vertices");
  }
  std::vector<TriangleMetric> metrics(triangles.size());
  std::vector<double> face_weight(triangles.size(), 1.0);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    metrics[f] = triangle_metric(positions, options.vertex.vertex_metrics, t[0], t[1], t[2]);
    if (vertex_weights)
      face_weight[f] = ((*vertex_weights)[t[0]] + (*vertex_weights)[t[1]] + (*vertex_weights)[t[2]]) / 3;
  }

  std::size_t max_ring = 0;
  for (std::size_t i = 0; i < nv; ++i)
    max_ring = std::max<std::size_t>(max_ring, offsets[i + 1] - offsets[i]);
  std::vector<RingTriangle> ring(max_ring);
  std::vector<LineTerm> terms(max_ring);
  const double w = blend_weight(options.vertex);

  // Gathers v's ring from the current uv into `ring`; returns its size.
  const auto gather = [&](int v) {
    std::size_t n = 0;
    for (int k = offsets[v]; k < offsets[v + 1]; ++k) {
      const int f = incident[k];
      const auto& t = triangles[f];
      const int corner = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      const TriangleMetric& m = metrics[f];
      ring[n++] = {uv[t[(corner + 1) % 3]],         uv[t[(corner + 2) % 3]],
                   m.opposite_sq[corner],           m.opposite_sq[(corner + 1) % 3],
                   m.opposite_sq[(corner + 2) % 3], m.area3,
                   face_weight[f]};
    }
    return n;
  };

  std::vector<int> movable;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!locked[v] && offsets[v + 1] > offsets[v]) movable.push_back(static_cast<int>(v));
  }
  std::vector<std::pair<double, int>> queue;
  queue.reserve(movable.size());
  std::vector<char> ever_moved(nv, 0);
  std::mt19937 rng(options.seed);

  for (std::size_t sweep = 0; sweep < options.max_sweeps && !movable.empty(); ++sweep) {
    // Priority queue by local stretch, largest first (ties by index, so the order is deterministic).
    queue.clear();
    const double min_energy = options.min_local_stretch * options.min_local_stretch;
    for (int v : movable) {
      const std::size_t n = gather(v);
      const double energy = ring_energy(uv[v], ring.data(), n, ring_weights(ring.data(), n, w));
      if (!(energy < min_energy)) queue.emplace_back(energy, v);
    }
    std::sort(queue.begin(), queue.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });

    double max_displacement = 0;
    for (const auto& [priority, v] : queue) {
      if (!std::isfinite(priority)) continue;  // ring already flipped/degenerate: leave it
      const std::size_t n = gather(v);
      Eigen::Vector2d p = uv[v];
      optimize_point(p, ring.data(), n, options.vertex, rng, terms.data());
      if (p != uv[v]) {
        max_displacement = std::max(max_displacement, (p - uv[v]).norm());
        uv[v] = p;
        ++result.vertex_moves;
        ever_moved[v] = 1;
      }
    }
    ++result.sweeps;
    result.last_max_displacement = max_displacement;
    if (options.record_sweeps) result.per_sweep.push_back(mesh_stretch(positions, triangles, uv));
    if (max_displacement < options.threshold) break;
  }

  for (int v : movable) {
    if (ever_moved[v]) continue;
    const std::size_t n = gather(v);
    if (!std::isfinite(ring_energy(uv[v], ring.data(), n, ring_weights(ring.data(), n, w)))) {
      ++result.skipped_vertices;
    }
  }
  result.after = mesh_stretch(positions, triangles, uv);
  return result;
}

std::vector<char> boundary_vertex_mask(std::size_t num_vertices,
                                       const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if (a < 0 || b < 0 || static_cast<std::size_t>(a) >= num_vertices ||
          static_cast<std::size_t>(b) >= num_vertices) {
        throw InvalidInput("boundary_vertex_mask: triangle " + std::to_string(f) +
                           " has an index out of range");
      }
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<char> mask(num_vertices, 0);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) mask[edges[i].first] = mask[edges[i].second] = 1;
    i = j;
  }
  return mask;
}

}  // namespace geomip
