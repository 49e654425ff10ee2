#include "param/sampling_weights.h"

#include "mesh/errors.h"
#include "param/stretch_optimization.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

namespace geomip {

std::vector<double> curvature_sampling_weights(const std::vector<Eigen::Vector3d>& positions,
                                               const std::vector<std::array<int, 3>>& triangles,
                                               const SamplingWeightOptions& options) {
  if (!(options.exponent >= 0) || !(options.floor > 0) || options.smoothing_iterations < 0 ||
      !(options.max_ratio >= 1))
    throw InvalidInput("curvature_sampling_weights: invalid SamplingWeightOptions");
  const std::size_t nv = positions.size();
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        throw InvalidInput("curvature_sampling_weights: vertex index " + std::to_string(v) + " out of range");

  constexpr double kPi = 3.14159265358979323846;
  std::vector<Eigen::Vector3d> laplace(nv, Eigen::Vector3d::Zero());
  std::vector<double> area(nv, 0), angle(nv, 0);
  std::vector<int> referenced(nv, 0);
  // Unique edges, for the one-rings of the smoothing below.
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    const double a3 =
        0.5 * (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).norm();
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3], o = t[(k + 2) % 3];
      referenced[i] = 1;
      area[i] += a3 / 3;
      const Eigen::Vector3d u = positions[i] - positions[o], w = positions[j] - positions[o];
      const double cross = u.cross(w).norm();
      const double cot = cross > 0 ? u.dot(w) / cross : 0.0;  // cotangent of the angle at o, opposite i–j
      laplace[i] += 0.5 * cot * (positions[j] - positions[i]);
      laplace[j] += 0.5 * cot * (positions[i] - positions[j]);
      const Eigen::Vector3d a = positions[j] - positions[i], b = positions[o] - positions[i];
      angle[i] += std::atan2(a.cross(b).norm(), a.dot(b));
      edges.emplace_back(std::min(i, j), std::max(i, j));
    }
  }
  const std::vector<char> boundary = boundary_vertex_mask(nv, triangles);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  std::vector<double> ii(nv, 0);  // |II|² = 4H² − 2K
  for (std::size_t v = 0; v < nv; ++v) {
    if (!referenced[v] || boundary[v] || !(area[v] > 0)) continue;
    const double h = laplace[v].norm() / (2 * area[v]);  // |Δx| = 2H
    const double k = (2 * kPi - angle[v]) / area[v];
    ii[v] = std::max(0.0, 4 * h * h - 2 * k);
  }
  // One-ring averaging (boundary vertices start from their interior neighbours' mean).
  std::vector<std::vector<int>> ring(nv);
  for (const auto& [a, b] : edges) {
    ring[a].push_back(b);
    ring[b].push_back(a);
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (!boundary[v]) continue;
    double sum = 0;
    int count = 0;
    for (int u : ring[v])
      if (!boundary[u]) sum += ii[u], ++count;
    ii[v] = count ? sum / count : 0.0;
  }
  for (int it = 0; it < options.smoothing_iterations; ++it) {
    std::vector<double> next(nv, 0);
    for (std::size_t v = 0; v < nv; ++v) {
      double sum = ii[v];
      for (int u : ring[v]) sum += ii[u];
      next[v] = sum / static_cast<double>(ring[v].size() + 1);
    }
    ii.swap(next);
  }
  std::vector<double> sorted;
  for (std::size_t v = 0; v < nv; ++v)
    if (referenced[v]) sorted.push_back(ii[v]);
  std::vector<double> weights(nv, 1.0);
  if (sorted.empty() || options.exponent == 0) return weights;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                   sorted.end());
  const double median = sorted[sorted.size() / 2];
  // ε: the median's fraction, but never below the curvature of a sphere as large as the mesh (|II|² = 2/r²
  // with r = the bounding-box diagonal), so that rounding noise on flat regions is not taken for shape.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (std::size_t v = 0; v < nv; ++v)
    if (referenced[v]) lo = lo.cwiseMin(positions[v]), hi = hi.cwiseMax(positions[v]);
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) return weights;
  const double eps = std::max(options.floor * median, 2 / (diagonal * diagonal));
  double weighted = 0, total = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!referenced[v]) continue;
    weights[v] = std::min(options.max_ratio, std::pow((eps + ii[v]) / eps, options.exponent));
    weighted += area[v] * weights[v];
    total += area[v];
  }
  if (weighted > 0 && total > 0)
    for (std::size_t v = 0; v < nv; ++v)
      if (referenced[v]) weights[v] *= total / weighted;
  return weights;
}

}  // namespace geomip
