// Curvature sampling weights (param/sampling_weights.h) and the weighted stretch optimization they drive:
// flat and uniformly curved surfaces get uniform weights, bent regions get more, and the optimizer then gives
// the weighted triangles more parameter area without flipping any.
#include "param/sampling_weights.h"
#include "mesh/errors.h"
#include "param/stretch.h"
#include "param/stretch_optimization.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace geomip {
namespace {

TEST(SamplingWeights, FlatAndSphereAreUniform) {
  const TriMesh flat = test::grid(12);
  for (double w : curvature_sampling_weights(flat.positions, flat.triangles)) EXPECT_NEAR(w, 1.0, 1e-9);
  // On a sphere |II|² = 2/r² everywhere: the weights agree up to the discretization (the icosphere's 12
  // valence-5 vertices carry more angle defect than the rest: within about 20 %).
  const TriMesh sphere = test::sphere(4);
  const auto w = curvature_sampling_weights(sphere.positions, sphere.triangles);
  const auto [lo, hi] = std::minmax_element(w.begin(), w.end());
  EXPECT_GT(*lo, 0.8);
  EXPECT_LT(*hi, 1.25);
  std::vector<double> sorted = w;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_LT(sorted[sorted.size() * 9 / 10] / sorted[sorted.size() / 10], 1.1) << "80 % of them within 10 %";
  // Exponent 0: every weight 1 whatever the shape.
  SamplingWeightOptions off;
  off.exponent = 0;
  for (double x : curvature_sampling_weights(sphere.positions, sphere.triangles, off)) EXPECT_EQ(x, 1.0);
}

TEST(SamplingWeights, BentRegionsWeighMoreAndTheAreaMeanIsOne) {
  // An ellipsoid with semi-axes 1, 1, 3: |II|² is largest at the poles (z = ±3) and smallest at the equator.
  TriMesh e = test::sphere(4);
  for (auto& p : e.positions) p.z() *= 3;
  const auto w = curvature_sampling_weights(e.positions, e.triangles);
  double pole = 0, equator = 1e9;
  for (std::size_t v = 0; v < e.positions.size(); ++v) {
    if (std::abs(e.positions[v].z()) > 2.9) pole = std::max(pole, w[v]);
    if (std::abs(e.positions[v].z()) < 0.3) equator = std::min(equator, w[v]);
  }
  EXPECT_GT(pole, 1.5 * equator);
  // Stronger exponent, stronger contrast.
  SamplingWeightOptions strong;
  strong.exponent = 2.0 / 3.0;
  const auto w2 = curvature_sampling_weights(e.positions, e.triangles, strong);
  double pole2 = 0, equator2 = 1e9;
  for (std::size_t v = 0; v < e.positions.size(); ++v) {
    if (std::abs(e.positions[v].z()) > 2.9) pole2 = std::max(pole2, w2[v]);
    if (std::abs(e.positions[v].z()) < 0.3) equator2 = std::min(equator2, w2[v]);
  }
  EXPECT_GT(pole2 / equator2, pole / equator);
  // Area-weighted mean 1 (barycentric vertex areas).
  std::vector<double> area(e.positions.size(), 0);
  for (const auto& t : e.triangles) {
    const double a =
        0.5 * (e.positions[t[1]] - e.positions[t[0]]).cross(e.positions[t[2]] - e.positions[t[0]]).norm();
    for (int v : t) area[v] += a / 3;
  }
  double sum = 0, total = 0;
  for (std::size_t v = 0; v < w.size(); ++v) sum += area[v] * w[v], total += area[v];
  EXPECT_NEAR(sum / total, 1.0, 1e-9);
}

TEST(SamplingWeights, BadInputThrows) {
  const TriMesh flat = test::grid(2);
  SamplingWeightOptions bad;
  bad.floor = 0;
  EXPECT_THROW(curvature_sampling_weights(flat.positions, flat.triangles, bad), InvalidInput);
  EXPECT_THROW(curvature_sampling_weights(flat.positions, {{0, 1, 99}}), InvalidInput);
}

TEST(WeightedStretch, WeightedTrianglesGetMoreParameterAreaAndNothingFlips) {
  // A flat grid with the identity embedding (the unweighted optimum): weight 4 on the half x < ½ pulls uv
  // area into that half; the boundary is locked, so the total stays 1.
  const TriMesh m = test::grid(16);
  std::vector<Eigen::Vector2d> uv;
  std::vector<char> locked;
  std::vector<double> weights;
  for (const auto& p : m.positions) {
    uv.emplace_back(p.x(), p.y());
    locked.push_back(p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1);
    weights.push_back(p.x() < 0.5 ? 4.0 : 1.0);
  }
  auto left_area = [&](const std::vector<Eigen::Vector2d>& at) {
    double a = 0;
    for (const auto& t : m.triangles) {
      const double cx = (m.positions[t[0]].x() + m.positions[t[1]].x() + m.positions[t[2]].x()) / 3;
      if (cx < 0.5) a += 0.5 * signed_double_area(at[t[0]], at[t[1]], at[t[2]]);
    }
    return a;
  };
  StretchOptimizationOptions options;
  options.max_sweeps = 100;
  options.threshold = 1e-5;
  std::vector<Eigen::Vector2d> plain = uv;
  optimize_stretch(m.positions, m.triangles, plain, locked, options);
  EXPECT_NEAR(left_area(plain), 0.5, 1e-3) << "unweighted: the identity stays optimal";
  options.vertex.vertex_weights = &weights;
  std::vector<Eigen::Vector2d> weighted = uv;
  optimize_stretch(m.positions, m.triangles, weighted, locked, options);
  EXPECT_GT(left_area(weighted), 0.55) << "weighted half gets more of the square";
  EXPECT_EQ(count_flipped(m.triangles, weighted), 0u);
  for (std::size_t v = 0; v < uv.size(); ++v)
    if (locked[v]) {
      EXPECT_EQ(weighted[v], uv[v]);
    }
  // Weights of the wrong size are refused.
  std::vector<double> short_weights(3, 1.0);
  options.vertex.vertex_weights = &short_weights;
  EXPECT_THROW(optimize_stretch(m.positions, m.triangles, weighted, locked, options), InvalidInput);
}

// The anisotropic metric M = I + λ·D·|S|: Euclidean on a plane, λ·D/r more along both tangent directions
// of a sphere of radius r, and on a cylinder only around it (its generators are straight); λ = 0 is the
// identity everywhere, and the normal direction never changes.
TEST(CurvatureMetric, FlatIsEuclideanSphereIsotropicCylinderOnlyAround) {
  const TriMesh flat = test::grid(12);
  for (const auto& m : curvature_metric_tensors(flat.positions, flat.triangles, 0.1))
    EXPECT_LT((m - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  const double lambda = 0.05;
  const TriMesh sphere = test::sphere(4);  // unit sphere: D = 2√3, |S| = I on the tangent plane
  const double d_sphere = 2 * std::sqrt(3.0);
  // the discrete estimate (vertex normals' differences along edges) is within 20 % everywhere, 10 % on most
  const auto ms = curvature_metric_tensors(sphere.positions, sphere.triangles, lambda);
  std::size_t within_10 = 0;
  for (std::size_t v = 0; v < sphere.positions.size(); ++v) {
    const Eigen::Vector3d n = sphere.positions[v].normalized();
    const Eigen::Vector3d t = n.unitOrthogonal(), b = n.cross(t);
    EXPECT_NEAR(n.dot(ms[v] * n), 1.0, 0.02 * lambda * d_sphere);
    for (const Eigen::Vector3d& dir : {t, b}) {
      const double excess = (dir.dot(ms[v] * dir) - 1) / (lambda * d_sphere);  // the estimated curvature
      EXPECT_NEAR(excess, 1.0, 0.2) << "vertex " << v;
      within_10 += std::abs(excess - 1) < 0.1;
    }
  }
  EXPECT_GT(within_10, 2 * sphere.positions.size() * 9 / 10);
  const TriMesh cyl = test::open_cylinder(48, 24);  // radius 1, height 2: D = √12
  const auto mc = curvature_metric_tensors(cyl.positions, cyl.triangles, lambda);
  const double d_cyl = std::sqrt(12.0);
  for (std::size_t v = 0; v < cyl.positions.size(); ++v) {
    const Eigen::Vector3d& p = cyl.positions[v];
    if (p.z() < 0.2 || p.z() > 1.8) continue;  // away from the boundary loops
    const Eigen::Vector3d around(-p.y(), p.x(), 0), along(0, 0, 1);
    EXPECT_NEAR(along.dot(mc[v] * along), 1.0, 0.02 * lambda * d_cyl) << "vertex " << v;
    EXPECT_NEAR(around.dot(mc[v] * around), 1 + lambda * d_cyl, 0.1 * lambda * d_cyl) << "vertex " << v;
  }
  for (const auto& m : curvature_metric_tensors(cyl.positions, cyl.triangles, 0.0))
    EXPECT_EQ(m, Eigen::Matrix3d::Identity());
  EXPECT_THROW(curvature_metric_tensors(cyl.positions, cyl.triangles, -0.1), InvalidInput);
  EXPECT_THROW(curvature_metric_tensors(cyl.positions, cyl.triangles, std::nan("")), InvalidInput);
  EXPECT_THROW(curvature_metric_tensors(cyl.positions, {{0, 1, 99999}}, lambda), InvalidInput);
}

// The metric drives the optimizer: identity tensors leave the Euclidean result (to rounding), and a half of a
// flat grid that the metric makes twice as long along x gets more of the square along u, not along v;
// nothing flips and locked vertices stay.
TEST(CurvatureMetric, TheOptimizerGivesALongerDirectionMoreParameterLength) {
  const TriMesh m = test::grid(16);
  std::vector<Eigen::Vector2d> uv;
  std::vector<char> locked;
  std::vector<Eigen::Matrix3d> identity(m.positions.size(), Eigen::Matrix3d::Identity()), metric;
  for (const auto& p : m.positions) {
    uv.emplace_back(p.x() + 0.02 * std::sin(9 * p.y()) * p.x() * (1 - p.x()), p.y());  // off the optimum
    locked.push_back(p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1);
    Eigen::Matrix3d t = Eigen::Matrix3d::Identity();
    if (p.x() < 0.5) t(0, 0) = 4;  // |e|² = 4·dx² + dy²: the left half twice as long along x
    metric.push_back(t);
  }
  StretchOptimizationOptions options;
  options.max_sweeps = 100;
  options.threshold = 1e-6;
  std::vector<Eigen::Vector2d> plain = uv, with_identity = uv, with_metric = uv;
  optimize_stretch(m.positions, m.triangles, plain, locked, options);
  options.vertex.vertex_metrics = &identity;
  optimize_stretch(m.positions, m.triangles, with_identity, locked, options);
  double worst = 0;
  for (std::size_t v = 0; v < uv.size(); ++v) worst = std::max(worst, (plain[v] - with_identity[v]).norm());
  EXPECT_LT(worst, 1e-4) << "identity tensors: the Euclidean optimum";
  options.vertex.vertex_metrics = &metric;
  optimize_stretch(m.positions, m.triangles, with_metric, locked, options);
  EXPECT_EQ(count_flipped(m.triangles, with_metric), 0u);
  double u_mid = 0, v_shift = 0;
  int n_mid = 0;
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (locked[v]) {
      EXPECT_EQ(with_metric[v], uv[v]);
    }
    if (std::abs(m.positions[v].x() - 0.5) < 1e-9 && !locked[v]) u_mid += with_metric[v].x(), ++n_mid;
    v_shift = std::max(v_shift, std::abs(with_metric[v].y() - m.positions[v].y()));
  }
  ASSERT_GT(n_mid, 0);
  EXPECT_GT(u_mid / n_mid, 0.58) << "the longer half takes more than half of u";
  EXPECT_LT(v_shift, 0.05) << "and v stays as it was";
  std::vector<Eigen::Matrix3d> short_metrics(3, Eigen::Matrix3d::Identity());
  options.vertex.vertex_metrics = &short_metrics;
  EXPECT_THROW(optimize_stretch(m.positions, m.triangles, with_metric, locked, options), InvalidInput);
}

}  // namespace
}  // namespace geomip
