#include "param/sampling_weights.h"

#include "mesh/errors.h"
#include "param/stretch_optimization.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
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

std::vector<Eigen::Matrix3d> curvature_metric_tensors(const std::vector<Eigen::Vector3d>& positions,
                                                      const std::vector<std::array<int, 3>>& triangles,
                                                      double lambda, double max_curvature) {
  if (!(lambda >= 0) || !std::isfinite(lambda) || !(max_curvature > 0) || !std::isfinite(max_curvature))
    throw InvalidInput(
        "curvature_metric_tensors: lambda must be finite and >= 0, max_curvature finite and > 0");
  const std::size_t nv = positions.size();
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        throw InvalidInput("curvature_metric_tensors: vertex index " + std::to_string(v) + " out of range");
  std::vector<Eigen::Matrix3d> out(nv, Eigen::Matrix3d::Identity());
  if (nv == 0 || triangles.empty() || lambda == 0) return out;
  std::vector<Eigen::Vector3d> normal(nv, Eigen::Vector3d::Zero());
  for (const auto& t : triangles) {
    const Eigen::Vector3d n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
    for (int i : t) normal[i] += n;
  }
  for (auto& n : normal)
    if (n.norm() > 0) n.normalize();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (const auto& t : triangles)
    for (int i : t) lo = lo.cwiseMin(positions[i]), hi = hi.cwiseMax(positions[i]);
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) return out;  // a point, or positions that are not finite
  std::vector<Eigen::Matrix3d> face_k(triangles.size(), Eigen::Matrix3d::Zero());
  std::vector<double> face_area(triangles.size(), 0);
  std::vector<Eigen::Matrix3d> vk(nv, Eigen::Matrix3d::Zero());
  std::vector<double> va(nv, 0);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    const Eigen::Vector3d e2 = positions[t[1]] - positions[t[0]];
    Eigen::Vector3d nf = e2.cross(positions[t[2]] - positions[t[0]]);
    const double a = 0.5 * nf.norm();
    if (!(a > 0) || !(e2.norm() > 0)) continue;
    nf.normalize();
    const Eigen::Vector3d t1 = e2.normalized(), t2 = nf.cross(t1);
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Vector3d atb = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      const int p = t[(i + 1) % 3], q = t[(i + 2) % 3];
      const Eigen::Vector3d e = positions[q] - positions[p], dn = normal[q] - normal[p];
      const double u1 = e.dot(t1), u2 = e.dot(t2), w1 = dn.dot(t1), w2 = dn.dot(t2);
      // a·u1 + b·u2 = w1, b·u1 + c·u2 = w2 for S = [[a, b], [b, c]]
      const Eigen::Vector3d r1(u1, u2, 0), r2(0, u1, u2);
      ata += r1 * r1.transpose() + r2 * r2.transpose();
      atb += r1 * w1 + r2 * w2;
    }
    const Eigen::Vector3d abc = ata.ldlt().solve(atb);
    if (!abc.allFinite()) continue;
    Eigen::Matrix2d s;
    s << abc[0], abc[1], abc[1], abc[2];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(s);
    Eigen::Vector2d ev = es.eigenvalues().cwiseAbs();
    for (int i = 0; i < 2; ++i) ev[i] = lambda * diagonal * std::min(ev[i], max_curvature / diagonal);
    const Eigen::Matrix2d abs_s = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
    Eigen::Matrix<double, 3, 2> frame;
    frame.col(0) = t1, frame.col(1) = t2;
    face_k[f] = frame * abs_s * frame.transpose();
    face_area[f] = a;
    for (int i : t) vk[i] += a * face_k[f], va[i] += a;
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (va[v] > 0) vk[v] /= va[v];
  // one smoothing pass: faces take their corners' mean, vertices the area-weighted mean of their faces
  std::vector<Eigen::Matrix3d> sk(nv, Eigen::Matrix3d::Zero());
  std::vector<double> sa(nv, 0);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    if (!(face_area[f] > 0)) continue;
    const auto& t = triangles[f];
    const Eigen::Matrix3d k = (vk[t[0]] + vk[t[1]] + vk[t[2]]) / 3.0;
    for (int i : t) sk[i] += face_area[f] * k, sa[i] += face_area[f];
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (sa[v] > 0) out[v] = Eigen::Matrix3d::Identity() + sk[v] / sa[v];
  return out;
}

}  // namespace geomip
