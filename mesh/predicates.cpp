#include "mesh/predicates.h"

#include <cmath>

namespace geomip {
namespace {

// ---- exact orientation (Shewchuk's adaptive idea: a filtered fast path, an exact expansion fallback) ----

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

// Sign of Σ a_k·b_k, exactly: each product as a two-term expansion (fma), summed by grow-expansion.
int exact_sign_of_products(const double (&a)[6], const double (&b)[6]) {
  double e[12];
  int len = 0;
  for (int k = 0; k < 6; ++k) {
    const double p = a[k] * b[k];
    const double err = std::fma(a[k], b[k], -p);
    for (double term : {err, p}) {
      // grow_expansion(e, term): components stay nonoverlapping and increasing in magnitude.
      double q = term;
      for (int m = 0; m < len; ++m) {
        double hi, lo;
        two_sum(q, e[m], hi, lo);
        e[m] = lo;
        q = hi;
      }
      e[len++] = q;
    }
  }
  for (int m = len - 1; m >= 0; --m) {
    if (e[m] > 0) return 1;
    if (e[m] < 0) return -1;
  }
  return 0;
}

}  // namespace

int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const double left = (a.x() - c.x()) * (b.y() - c.y());
  const double right = (a.y() - c.y()) * (b.x() - c.x());
  const double det = left - right;
  const double bound =
      (3.0 + 16.0 * 1.1102230246251565e-16) * 1.1102230246251565e-16 * (std::abs(left) + std::abs(right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  // ax·by − ax·cy − cx·by − ay·bx + ay·cx + cy·bx
  const double fa[6] = {a.x(), -a.x(), -c.x(), -a.y(), a.y(), c.y()};
  const double fb[6] = {b.y(), c.y(), b.y(), b.x(), c.x(), b.x()};
  return exact_sign_of_products(fa, fb);
}

std::size_t count_flipped_triangles(const std::vector<Eigen::Vector2d>& uv,
                                    const std::vector<std::array<int, 3>>& triangles) {
  std::size_t flipped = 0;
  for (const auto& t : triangles) {
    if (t[0] < 0) continue;
    if (orient2d(uv[t[0]], uv[t[1]], uv[t[2]]) <= 0) ++flipped;
  }
  return flipped;
}

}  // namespace geomip
