#include "param/mean_value_embedding.h"

#include "mesh/errors.h"
#include "param/sampling_weights.h"
#include "param/unit_square.h"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_set>

namespace geomip {
namespace {

[[noreturn]] void fail(const char* function, const std::string& what) {
  throw InvalidInput(std::string(function) + ": " + what);
}

}  // namespace

std::vector<FixedUv> square_boundary_uv(const std::vector<Eigen::Vector3d>& positions,
                                        const std::array<std::vector<int>, 4>& sides,
                                        const std::vector<Eigen::Matrix3d>* metrics) {
  constexpr const char* kFn = "square_boundary_uv";
  const auto& kCorner = unit_square_corners();
  const int n = static_cast<int>(positions.size());
  if (metrics && metrics->size() != positions.size())
    fail(kFn, "metric tensors and positions differ in size");
  std::vector<FixedUv> out;
  for (int k = 0; k < 4; ++k) {
    const auto& side = sides[k];
    if (side.size() < 2) fail(kFn, "side " + std::to_string(k) + " has fewer than 2 vertices");
    if (side.back() != sides[(k + 1) % 4].front()) {
      fail(kFn, "side " + std::to_string(k) + " does not end where the next side starts");
    }
    for (int v : side) {
      if (v < 0 || v >= n) fail(kFn, "vertex id out of range");
    }
    std::vector<double> s(side.size(), 0.0);
    for (std::size_t i = 1; i < side.size(); ++i)
      s[i] = s[i - 1] + metric_edge_length(positions, metrics, side[i - 1], side[i]);
    const double length = s.back();
    if (!(length > 0.0)) fail(kFn, "side " + std::to_string(k) + " has zero length");
    const Eigen::Vector2d a = kCorner[k], b = kCorner[(k + 1) % 4];
    // The last vertex is the next side's first corner: it is emitted there.
    for (std::size_t i = 0; i + 1 < side.size(); ++i) {
      const double t = s[i] / length;
      out.emplace_back(side[i], i == 0 ? a : Eigen::Vector2d(a + t * (b - a)));
    }
  }
  return out;
}

MeanValueEmbeddingResult mean_value_embedding(const std::vector<Eigen::Vector3d>& positions,
                                              const std::vector<std::array<int, 3>>& triangles,
                                              const std::vector<FixedUv>& fixed,
                                              const MeanValueEmbeddingOptions& options) {
  constexpr const char* kFn = "mean_value_embedding";
  const int n = static_cast<int>(positions.size());
  const double kNan = std::numeric_limits<double>::quiet_NaN();

  MeanValueEmbeddingResult result;
  result.uv.assign(n, Eigen::Vector2d(kNan, kNan));
  std::vector<char> is_fixed(n, 0);
  for (const auto& [v, uv] : fixed) {
    if (v < 0 || v >= n) fail(kFn, "fixed vertex id out of range");
    if (is_fixed[v]) fail(kFn, "vertex " + std::to_string(v) + " is fixed twice");
    if (!uv.allFinite()) fail(kFn, "fixed uv of vertex " + std::to_string(v) + " is not finite");
    is_fixed[v] = 1;
    result.uv[v] = uv;
  }

  // Unknown numbering, and the boundary precondition (a boundary edge is a directed edge without its twin).
  std::vector<int> unknown(n, -1);
  std::unordered_set<std::uint64_t> directed;
  directed.reserve(triangles.size() * 3);
  int m = 0;
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) {
      if (t[i] < 0 || t[i] >= n) fail(kFn, "triangle vertex id out of range");
      directed.insert(directed_edge_key(t[i], t[(i + 1) % 3]));
    }
    for (int v : t) {
      if (!is_fixed[v] && unknown[v] < 0) unknown[v] = m++;
    }
  }
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if (directed.count(directed_edge_key(b, a)) == 0 && (!is_fixed[a] || !is_fixed[b])) {
        fail(kFn, "boundary vertex " + std::to_string(is_fixed[a] ? b : a) + " has no fixed uv");
      }
    }
  }
  result.free_vertices = static_cast<std::size_t>(m);
  if (m == 0) return result;

  // Eq. (3): each triangle (i, j, k) adds tan(α_i/2)/|e_ij| to w_ij and tan(α_i/2)/|e_ik| to w_ik, so that
  // w_ik collects the half-angle tangents of both triangles on edge (i, k).
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(triangles.size() * 6 + static_cast<std::size_t>(m));
  std::vector<double> row_sum(m, 0.0);
  Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(m, 2);
  for (const auto& t : triangles) {
    for (int c = 0; c < 3; ++c) {
      const int i = t[c];
      if (unknown[i] < 0) continue;
      const int r = unknown[i];
      const int j = t[(c + 1) % 3], k = t[(c + 2) % 3];
      const Eigen::Vector3d a = positions[j] - positions[i], b = positions[k] - positions[i];
      const double la = a.norm(), lb = b.norm();
      if (!(la > 0.0) || !(lb > 0.0)) {
        fail(kFn, "triangle with a zero-length or non-finite edge at vertex " + std::to_string(i));
      }
      // tan(α/2) = |a×b| / (|a||b| + a·b), stable for every α in [0, π).
      const double denominator = la * lb + a.dot(b);
      const double numerator = a.cross(b).norm();
      double tan_half = options.max_half_angle_tangent;
      if (numerator < tan_half * denominator) tan_half = numerator / denominator;
      for (const auto& [other, length] : {std::pair<int, double>{j, la}, std::pair<int, double>{k, lb}}) {
        const double w = tan_half / length;
        row_sum[r] += w;
        if (unknown[other] >= 0) {
          entries.emplace_back(r, unknown[other], -w);
        } else {
          rhs.row(r) += w * result.uv[other].transpose();
        }
      }
    }
  }
  for (int r = 0; r < m; ++r) {
    if (!(row_sum[r] > 0.0))
      throw SolverFailure(std::string(kFn) + ": a vertex has only zero-angle triangles");
    entries.emplace_back(r, r, row_sum[r]);
  }
  Eigen::SparseMatrix<double> matrix(m, m);
  matrix.setFromTriplets(entries.begin(), entries.end());

  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> solver;
  solver.compute(matrix);
  if (solver.info() != Eigen::Success) {
    throw SolverFailure(std::string(kFn) + ": sparse LU failed (" + solver.lastErrorMessage() +
                        "); is every free vertex connected to a fixed one?");
  }
  const Eigen::MatrixX2d x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) {
    throw SolverFailure(std::string(kFn) + ": sparse LU solve failed");
  }
  const Eigen::MatrixX2d residual = matrix * x - rhs;
  for (int r = 0; r < m; ++r) {
    result.residual = std::max(result.residual, residual.row(r).lpNorm<Eigen::Infinity>() / row_sum[r]);
  }
  for (int v = 0; v < n; ++v) {
    if (unknown[v] >= 0) result.uv[v] = x.row(unknown[v]).transpose();
  }
  return result;
}

}  // namespace geomip
