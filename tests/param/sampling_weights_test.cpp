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

}  // namespace
}  // namespace geomip
