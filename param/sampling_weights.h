// Per-vertex sampling weights from curvature, for a signal-specialized stretch optimization (in the spirit of
// Sander, Gortler, Snyder, Hoppe 2002, "Signal-specialized parametrization"): a geometry image samples the
// surface uniformly in (u,v), and the piecewise-linear resampling error per unit area grows with the squared
// curvature times the fourth power of the sample spacing. With n samples per unit area, the squared error
// density is ∝ |II|²/n², and the n that minimizes its integral for a fixed sample count is n ∝ |II|^(2/3)
// (|II|² = κ₁² + κ₂², the squared norm of the second fundamental form). Sander's L2 energy Σ A3·w·L2² with
// triangle weight w gives n ∝ √w, hence w = |II|^(4/3); a floor ε keeps flat regions sampled.
#pragma once

#include "mesh/mesh.h"

#include <cmath>
#include <vector>

namespace geomip {

struct SamplingWeightOptions {
  /// Exponent γ of w = ((ε + |II|²) / ε)^γ; 2/3 is the optimum above for a fixed sample count, 0 gives
  /// every weight 1. The default 1/3 is half-way between the remeshes' gain and the codec's low
  /// rates, which denser sampling of curved regions costs (README, "Curvature sampling", has the figures).
  double exponent = 1.0 / 3.0;
  /// ε as a multiple of the median (over vertices) of the smoothed |II|²: the curvature below which a region
  /// counts as flat. > 0.
  double floor = 0.3;
  /// One-ring averaging passes of |II|² before the weights are formed (scanned meshes are noisy).
  int smoothing_iterations = 1;
  /// Largest weight relative to a flat region's (creases of CAD models have unbounded discrete curvature).
  double max_ratio = 16;
};

/// |II|² per vertex (4H² − 2K from the cotangent Laplacian and the angle defect over the barycentric area,
/// clamped at 0; boundary vertices take the mean of their interior neighbours), smoothed, turned into
/// weights min(max_ratio, ((ε + |II|²)/ε)^γ), ε = max(floor · median |II|², 2/diagonal²), normalized to an
/// area-weighted mean of 1. Unreferenced vertices get 1; a flat mesh gets 1 everywhere.
/// \throw InvalidInput for an index out of range or options out of range.
std::vector<double> curvature_sampling_weights(const std::vector<Eigen::Vector3d>& positions,
                                               const std::vector<std::array<int, 3>>& triangles,
                                               const SamplingWeightOptions& options = {});

/// Length of the edge a→b in the mean of its ends' metric tensors (`metrics` indexed like `positions`;
/// null = Euclidean): the chord lengths that place a patch's side vertices when its interior is
/// parameterized in that metric (square_boundary_uv(), CoarseToFineOptions::side_metrics).
inline double metric_edge_length(const std::vector<Eigen::Vector3d>& positions,
                                 const std::vector<Eigen::Matrix3d>* metrics, int a, int b) {
  const Eigen::Vector3d e = positions[static_cast<std::size_t>(b)] - positions[static_cast<std::size_t>(a)];
  if (!metrics) return e.norm();
  const Eigen::Matrix3d m =
      0.5 * ((*metrics)[static_cast<std::size_t>(a)] + (*metrics)[static_cast<std::size_t>(b)]);
  return std::sqrt(e.dot(m * e));
}

/// Per-vertex metric tensors for an anisotropic, curvature-adapted stretch (VertexOptimizationOptions::
/// vertex_metrics): M = I + λ·D·|S|, S the shape operator (per face from the vertex normals' differences
/// along its edges, least squares; |S| its eigenvalues made positive; area-weighted to the vertices and
/// averaged over one ring once), D the bounding-box diagonal, κ·D clamped at `max_curvature`. Linear
/// interpolation error along a direction of curvature κ grows as κ·h², so uniform samples in the metric |S|
/// spread the error evenly; λ blends it with the Euclidean metric. λ = 0, no triangles, a zero or non-finite
/// bounding box: identity tensors.
/// \throw InvalidInput for λ < 0 or non-finite, max_curvature ≤ 0, or an index out of range.
std::vector<Eigen::Matrix3d> curvature_metric_tensors(const std::vector<Eigen::Vector3d>& positions,
                                                      const std::vector<std::array<int, 3>>& triangles,
                                                      double lambda, double max_curvature = 200);

}  // namespace geomip
