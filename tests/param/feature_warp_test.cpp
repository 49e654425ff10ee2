// Property tests of the foldover-free feature alignment warp (paper §3.4).
#include "param/feature_warp.h"

#include "mesh/errors.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <map>
#include <string>
#include <random>

namespace geomip {
namespace {

using Vec2 = Eigen::Vector2d;
using Tris = std::vector<std::array<int, 3>>;

struct Embedding {
  Tris triangles;
  std::vector<Vec2> uv;
};

/// The (n+1)² grid of test::grid(n) as an embedding in the unit square.
Embedding grid_embedding(int n) {
  const TriMesh g = test::grid(n);
  Embedding e;
  e.triangles = g.triangles;
  for (const auto& p : g.positions) e.uv.emplace_back(p.x(), p.y());
  return e;
}
int grid_id(int n, int i, int j) { return j * (n + 1) + i; }

double signed_area(const Vec2& a, const Vec2& b, const Vec2& c) {
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}
std::size_t count_flipped(const Tris& triangles, const std::vector<Vec2>& uv) {
  std::size_t flipped = 0;
  for (const auto& t : triangles) flipped += signed_area(uv[t[0]], uv[t[1]], uv[t[2]]) <= 0;
  return flipped;
}
bool on_side(const Vec2& p) { return p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1; }

/// Checks what every warp must preserve: features exactly at their targets (unless reported unreached),
/// boundary vertices (corners included) bit-identical, nothing flipped, everything inside the square.
void expect_warp_properties(const Embedding& before, const std::vector<Vec2>& after, const std::vector<int>& features,
                            const std::vector<Vec2>& targets, const FeatureWarpResult& result) {
  EXPECT_EQ(result.flipped_triangles, 0u);
  EXPECT_EQ(count_flipped(before.triangles, after), 0u);
  EXPECT_GT(result.min_warp_triangle_area, 0.0);
  for (std::size_t v = 0; v < after.size(); ++v) {
    if (on_side(before.uv[v])) {
      EXPECT_EQ(after[v], before.uv[v]) << "boundary vertex " << v << " moved";
    } else {
      EXPECT_TRUE(after[v].x() > 0 && after[v].x() < 1 && after[v].y() > 0 && after[v].y() < 1) << v;
    }
  }
  for (std::size_t k = 0; k < features.size(); ++k) {
    if (std::find(result.unreached.begin(), result.unreached.end(), int(k)) != result.unreached.end()) continue;
    EXPECT_LE((after[features[k]] - targets[k]).norm(), 1e-12) << "feature " << k;
  }
}

TEST(AverageFeatureTargets, IsTheMeanOverModels) {
  const std::vector<std::vector<Vec2>> models = {
      {Vec2(0.2, 0.3), Vec2(0.6, 0.6)}, {Vec2(0.4, 0.1), Vec2(0.5, 0.9)}, {Vec2(0.3, 0.2), Vec2(0.7, 0.3)}};
  const std::vector<Vec2> avg = average_feature_targets(models);
  ASSERT_EQ(avg.size(), 2u);
  EXPECT_NEAR(avg[0].x(), 0.3, 1e-15);
  EXPECT_NEAR(avg[0].y(), 0.2, 1e-15);
  EXPECT_NEAR(avg[1].x(), 0.6, 1e-15);
  EXPECT_NEAR(avg[1].y(), 0.6, 1e-15);
  EXPECT_THROW(average_feature_targets({}), InvalidInput);
  EXPECT_THROW(average_feature_targets({{Vec2(0.5, 0.5)}, {}}), InvalidInput);
}

TEST(FeatureWarpTriangulation, IsADelaunayTriangulationOfCornersAndFeatures) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  std::vector<Vec2> features;
  for (int k = 0; k < 12; ++k) features.emplace_back(u(rng), u(rng));
  const Tris tris = feature_warp_triangulation(features);
  std::vector<Vec2> points = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  points.insert(points.end(), features.begin(), features.end());
  EXPECT_EQ(tris.size(), 2 * features.size() + 2);  // Euler: 2n - h - 2 with n = e + 4, h = 4
  double total = 0;
  for (const auto& t : tris) {
    const double a = signed_area(points[t[0]], points[t[1]], points[t[2]]);
    EXPECT_GT(a, 0);
    total += a;
    // Empty circumcircle (with a tolerance for round-off).
    const Vec2 &p = points[t[0]], &q = points[t[1]], &r = points[t[2]];
    const double d = 2 * (p.x() * (q.y() - r.y()) + q.x() * (r.y() - p.y()) + r.x() * (p.y() - q.y()));
    const Vec2 c((p.squaredNorm() * (q.y() - r.y()) + q.squaredNorm() * (r.y() - p.y()) + r.squaredNorm() * (p.y() - q.y())) / d,
                 (p.squaredNorm() * (r.x() - q.x()) + q.squaredNorm() * (p.x() - r.x()) + r.squaredNorm() * (q.x() - p.x())) / d);
    for (const Vec2& s : points) EXPECT_GE((s - c).norm(), (p - c).norm() - 1e-9);
  }
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_THROW(feature_warp_triangulation({Vec2(0.5, 0.5), Vec2(0.5, 0.5)}), InvalidInput);
  EXPECT_THROW(feature_warp_triangulation({Vec2(0.0, 0.5)}), InvalidInput);
}

TEST(WarpFeatures, SingleFeatureReachesItsTargetExactly) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::vector<Vec2> uv = e.uv;
  const std::vector<int> features = {grid_id(n, 6, 7)};
  const std::vector<Vec2> targets = {Vec2(0.62, 0.41)};
  const FeatureWarpResult r = warp_features(e.triangles, uv, features, targets);
  EXPECT_TRUE(r.unreached.empty());
  EXPECT_EQ(r.max_feature_error, 0.0);
  EXPECT_EQ(uv[features[0]], targets[0]);
  expect_warp_properties(e, uv, features, targets, r);
}

// A long move past a neighbouring feature crosses its Delaunay edges: events must happen, and the warp mesh
// must stay a triangulation of the square with positive triangles after every move and every flip. Run with
// the defaults (bounded steps + Delaunay flips) and as in the paper (flips only at degeneracy events).
void check_long_move(bool paper_mode) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::vector<Vec2> uv = e.uv;
  const std::vector<int> features = {grid_id(n, 4, 10), grid_id(n, 10, 10), grid_id(n, 10, 5), grid_id(n, 10, 15)};
  std::vector<Vec2> targets;
  for (int f : features) targets.push_back(uv[f]);
  targets[0] = Vec2(0.8, 0.53);  // passes 0.015 above feature 1
  std::size_t calls = 0;
  FeatureWarpOptions options;
  if (paper_mode) {
    options.keep_delaunay = false;
    options.max_step_fraction = 0;
  }
  options.observer = [&](const std::vector<Vec2>& points, const Tris& tris) {
    ++calls;
    ASSERT_EQ(points.size(), features.size() + 4);
    ASSERT_EQ(tris.size(), 2 * features.size() + 2);
    double total = 0;
    for (const auto& t : tris) {
      const double a = signed_area(points[t[0]], points[t[1]], points[t[2]]);
      ASSERT_GT(a, 0) << "warp triangle folded after call " << calls;
      total += a;
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
    EXPECT_EQ(points[0], Vec2(0, 0));
    EXPECT_EQ(points[1], Vec2(1, 0));
    EXPECT_EQ(points[2], Vec2(1, 1));
    EXPECT_EQ(points[3], Vec2(0, 1));
  };
  const FeatureWarpResult r = warp_features(e.triangles, uv, features, targets, options);
  EXPECT_GT(r.events, 0u);
  EXPECT_GT(calls, r.events / 8);
  EXPECT_TRUE(r.unreached.empty());
  expect_warp_properties(e, uv, features, targets, r);
  std::cout << "[ figures  ] long move" << (paper_mode ? " (paper mode)" : "") << ": events " << r.events
            << ", steps " << r.steps << ", repaired vertices " << r.repaired_vertices << ", unreached "
            << r.unreached.size() << "\n";
}

TEST(WarpFeatures, EventsKeepEveryWarpTrianglePositive) { check_long_move(false); }
TEST(WarpFeatures, DegeneracyEventsAloneKeepEveryWarpTrianglePositive) { check_long_move(true); }

struct RandomCase {
  std::vector<int> features;
  std::vector<Vec2> targets;
};

/// 3–6 interior features of the n-grid, pairwise non-adjacent and off the boundary ring, with random
/// targets in [0.1, 0.9]² at least 0.05 apart, each at most `reach` from its feature (reach >= 1.2: anywhere).
RandomCase random_case(int n, std::mt19937& rng, double reach) {
  RandomCase c;
  std::uniform_int_distribution<int> count(3, 6), cell(2, n - 2);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  const int e = count(rng);
  std::vector<std::pair<int, int>> ij;
  while (int(ij.size()) < e) {
    const int i = cell(rng), j = cell(rng);
    bool ok = true;
    for (const auto& [a, b] : ij) ok = ok && std::max(std::abs(a - i), std::abs(b - j)) >= 2;
    if (ok) ij.emplace_back(i, j);
  }
  for (const auto& [i, j] : ij) c.features.push_back(grid_id(n, i, j));
  while (int(c.targets.size()) < e) {
    const Vec2 t(u(rng), u(rng));
    const Vec2 from(double(ij[c.targets.size()].first) / n, double(ij[c.targets.size()].second) / n);
    bool ok = (t - from).norm() <= reach;
    for (const Vec2& s : c.targets) ok = ok && (s - t).norm() >= 0.05;
    if (ok) c.targets.push_back(t);
  }
  return c;
}

struct TrialFigures {
  std::size_t features = 0, unreached = 0, events = 0, repaired = 0, max_events = 0, max_repaired = 0;
  std::size_t reordered = 0, rescued = 0;  // warps that needed more than one pass; of those, reaching every target
  std::size_t relaxed = 0;  // features the barrier relaxation brought in after the passes
  std::size_t untangled = 0;  // of those and of the walks' leftovers, the features brought in by untangling
  std::size_t max_relax_iterations = 0;  // the relaxation's Newton iterations in one warp, at most
  std::map<std::string, std::size_t> reasons;  // why features stopped short: the reason up to its position
  double seconds = 0;
};

/// Warps the 20-grid to `trials` random cases; checks the properties every warp must have.
TrialFigures run_random_trials(int trials, double reach, unsigned seed) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::mt19937 rng(seed);
  TrialFigures fig;
  for (int trial = 0; trial < trials; ++trial) {
    const RandomCase c = random_case(n, rng, reach);
    std::vector<Vec2> uv = e.uv;
    const auto start = std::chrono::steady_clock::now();
    const FeatureWarpResult r = warp_features(e.triangles, uv, c.features, c.targets);
    fig.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_warp_properties(e, uv, c.features, c.targets, r);
    for (int k : r.unreached) EXPECT_GT((uv[c.features[k]] - c.targets[k]).norm(), 0.0);
    EXPECT_TRUE(std::is_sorted(r.unreached.begin(), r.unreached.end()));
    EXPECT_EQ(r.unreached_reasons.size(), r.unreached.size());
    for (const std::string& why : r.unreached_reasons) {
      EXPECT_FALSE(why.empty());
      EXPECT_EQ(why.find('\n'), std::string::npos) << why;
      ++fig.reasons[why.substr(0, why.find(" ("))];
    }
    EXPECT_EQ(r.max_feature_error > 0, !r.unreached.empty());
    EXPECT_GE(r.passes, 1);
    EXPECT_LE(r.passes, 1 + FeatureWarpOptions{}.reorder_passes);
    if (r.passes > 1) {
      ++fig.reordered;
      fig.rescued += r.unreached.empty();
    }
    fig.features += c.features.size();
    fig.unreached += r.unreached.size();
    fig.relaxed += r.relaxed;
    fig.untangled += r.untangled;
    fig.max_relax_iterations = std::max(fig.max_relax_iterations, r.relax_iterations);
    EXPECT_LE(r.relax_iterations, FeatureWarpOptions{}.relax_iterations);
    fig.events += r.events;
    fig.repaired += r.repaired_vertices;
    fig.max_events = std::max(fig.max_events, r.events);
    fig.max_repaired = std::max(fig.max_repaired, r.repaired_vertices);
  }
  std::cout << "[ figures  ] " << trials << " trials, 20x20 grid, 3-6 features, reach " << reach << ": unreached "
            << fig.unreached << "/" << fig.features << ", events " << fig.events << " (max " << fig.max_events
            << "), repaired vertices " << fig.repaired << " (max " << fig.max_repaired << "), warps in more than one pass "
            << fig.reordered << " (all targets reached in " << fig.rescued << "), brought in by the relaxation "
            << fig.relaxed << ", by untangling " << fig.untangled << " (Newton iterations at most " << fig.max_relax_iterations << " per warp), "
            << 1e3 * fig.seconds / trials
            << " ms per warp\n";
  for (const auto& [why, count] : fig.reasons) std::cout << "[ figures  ]   " << count << " x " << why << "\n";
  return fig;
}

// Targets within 4 grid cells of their features (what averaging corresponding features of similar models
// produces): every feature arrives and nothing folds.
TEST(WarpFeatures, RandomNearbyTargetsAreReachedWithoutFlippedTriangles) {
  const TrialFigures fig = run_random_trials(200, 0.2, 2024);
  EXPECT_EQ(fig.unreached, 0u);
  // The trials must exercise both mechanisms, or they prove nothing about them.
  EXPECT_GT(fig.events, 0u);
  EXPECT_GT(fig.repaired, 0u);
}

// Targets anywhere: features sweep past each other's stars across the grid. Nothing may fold; a feature that
// cannot get through is reported (its error is in the result), never forced. Every target here is reachable
// (no base triangle of features only; and every one of them is reached): 0 of 93 short with the untangling after
// the barrier relaxation (1 with the relaxation alone, 4 with the reordered passes alone, 14 with one pass;
// seeds 78 / 79: 2 / 0 short, 5 / 4 without the untangling; docs/measurements.md, "Feature warp stress test").
// Some warps must need the later passes and reach every target there, and some features must come in only by
// the relaxation and by the untangling, or those are untested.
TEST(WarpFeatures, RandomFarTargetsNeverFoldTheBaseMesh) {
  const TrialFigures fig = run_random_trials(20, 2.0, 77);
  EXPECT_EQ(fig.unreached, 0u);
  EXPECT_GT(fig.rescued, 0u);
  EXPECT_GE(fig.relaxed, 3u);
  EXPECT_GE(fig.untangled, 1u);
}

// The caveat of §3.4: the plain PL warp maps vertices only, and straight-edged base triangles can invert.
TEST(WarpFeatures, PlainWarpCanFoldTheBaseMeshAndTheRepairPreventsIt) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::mt19937 rng(99);
  int folding_cases = 0;
  for (int trial = 0; trial < 100 && folding_cases < 5; ++trial) {
    const RandomCase c = random_case(n, rng, 0.3);
    std::vector<Vec2> plain = e.uv;
    FeatureWarpOptions options;
    options.keep_base_mesh_valid = false;
    const FeatureWarpResult p = warp_features(e.triangles, plain, c.features, c.targets, options);
    EXPECT_EQ(p.repaired_vertices, 0u);
    EXPECT_EQ(p.flipped_triangles, count_flipped(e.triangles, plain));
    if (p.flipped_triangles == 0) continue;
    ++folding_cases;
    std::vector<Vec2> uv = e.uv;
    const FeatureWarpResult r = warp_features(e.triangles, uv, c.features, c.targets);
    EXPECT_GT(r.repaired_vertices, 0u);
    EXPECT_TRUE(r.unreached.empty());
    expect_warp_properties(e, uv, c.features, c.targets, r);
    std::cout << "[ figures  ] plain warp flipped " << p.flipped_triangles << " triangles; with repair 0 ("
              << r.repaired_vertices << " vertices repaired)\n";
  }
  EXPECT_GT(folding_cases, 0) << "no random case folded the plain warp: the repair is untested";
}

TEST(WarpFeatures, PointsOutsideTheMovingFeaturesStarDoNotMove) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::vector<Vec2> uv = e.uv;
  const std::vector<int> features = {grid_id(n, 5, 4), grid_id(n, 15, 6), grid_id(n, 6, 15), grid_id(n, 14, 13)};
  std::vector<Vec2> feature_uv, targets;
  for (int f : features) feature_uv.push_back(uv[f]);
  targets = feature_uv;
  targets[0] += Vec2(0.02, 0.013);
  const Tris warp = feature_warp_triangulation(feature_uv);
  std::vector<Vec2> points = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  points.insert(points.end(), feature_uv.begin(), feature_uv.end());
  auto in_star = [&](const Vec2& p) {  // closed star of warp vertex 4 (feature 0) at its initial position
    for (const auto& t : warp) {
      if (t[0] != 4 && t[1] != 4 && t[2] != 4) continue;
      if (signed_area(p, points[t[1]], points[t[2]]) >= 0 && signed_area(points[t[0]], p, points[t[2]]) >= 0 &&
          signed_area(points[t[0]], points[t[1]], p) >= 0) {
        return true;
      }
    }
    return false;
  };
  const FeatureWarpResult r = warp_features(e.triangles, uv, features, targets);
  ASSERT_EQ(r.events, 0u);
  ASSERT_EQ(r.repaired_vertices, 0u);
  expect_warp_properties(e, uv, features, targets, r);
  int moved_inside = 0, outside = 0;
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (v == std::size_t(features[0])) continue;
    if (in_star(e.uv[v])) {
      moved_inside += uv[v] != e.uv[v];
    } else {
      ++outside;
      EXPECT_EQ(uv[v], e.uv[v]) << "vertex " << v << " outside the influence region moved";
    }
  }
  EXPECT_GT(moved_inside, 10);
  EXPECT_GT(outside, 10);
}

TEST(WarpFeatures, TwoModelsEndWithIdenticalFeatureUv) {
  const Embedding a = grid_embedding(20), b = grid_embedding(16);
  const std::vector<int> fa = {grid_id(20, 4, 5), grid_id(20, 15, 4), grid_id(20, 10, 12), grid_id(20, 5, 16)};
  const std::vector<int> fb = {grid_id(16, 5, 3), grid_id(16, 11, 5), grid_id(16, 7, 8), grid_id(16, 3, 11)};
  std::vector<std::vector<Vec2>> per_model(2);
  for (int f : fa) per_model[0].push_back(a.uv[f]);
  for (int f : fb) per_model[1].push_back(b.uv[f]);
  const std::vector<Vec2> targets = average_feature_targets(per_model);
  std::vector<Vec2> ua = a.uv, ub = b.uv;
  const FeatureWarpResult ra = warp_features(a.triangles, ua, fa, targets);
  const FeatureWarpResult rb = warp_features(b.triangles, ub, fb, targets);
  expect_warp_properties(a, ua, fa, targets, ra);
  expect_warp_properties(b, ub, fb, targets, rb);
  ASSERT_TRUE(ra.unreached.empty() && rb.unreached.empty());
  for (std::size_t k = 0; k < fa.size(); ++k) EXPECT_EQ(ua[fa[k]], ub[fb[k]]) << "feature " << k;
}

// Exchanging two features: each target is occupied by the other until it moves; the warp parks one beside
// its path instead of pushing it through the other, and both arrive.
TEST(WarpFeatures, ExchangingTwoFeaturesRoutesAroundEachOther) {
  const int n = 20;
  const Embedding e = grid_embedding(n);
  std::vector<Vec2> uv = e.uv;
  const std::vector<int> features = {grid_id(n, 6, 10), grid_id(n, 14, 10)};
  const std::vector<Vec2> targets = {uv[features[1]], uv[features[0]]};
  const FeatureWarpResult r = warp_features(e.triangles, uv, features, targets);
  EXPECT_TRUE(r.unreached.empty());
  EXPECT_GT(r.detours, 0u);
  expect_warp_properties(e, uv, features, targets, r);
}

// Feature 0, feature 1 and a boundary vertex form a base triangle: no free vertex can keep it positive if
// feature 0 crosses the line through the other two. That target is reported, not folded.
TEST(WarpFeatures, ImpossibleTargetIsReportedNotFolded) {
  const int n = 4;
  const Embedding e = grid_embedding(n);
  std::vector<Vec2> uv = e.uv;
  const std::vector<int> features = {grid_id(n, 1, 1), grid_id(n, 2, 1)};
  const std::vector<Vec2> targets = {Vec2(0.75, 0.1), uv[features[1]]};
  const FeatureWarpResult r = warp_features(e.triangles, uv, features, targets);
  ASSERT_EQ(r.unreached, std::vector<int>{0});
  ASSERT_EQ(r.unreached_reasons.size(), 1u);
  // The reason is a proof (the triangle of both features and the boundary vertex), and the feature is not moved.
  EXPECT_NE(r.unreached_reasons[0].find("no fold-free embedding reaches it"), std::string::npos)
      << r.unreached_reasons[0];
  EXPECT_EQ(uv[features[0]], e.uv[features[0]]);
  EXPECT_GT(r.max_feature_error, 0.0);
  EXPECT_EQ(uv[features[1]], targets[1]);
  EXPECT_EQ(r.passes, 1);  // a proof holds in every order: no second pass
  expect_warp_properties(e, uv, features, targets, r);
}

TEST(WarpFeatures, RejectsInvalidInputWithoutTouchingUv) {
  const int n = 8;
  const Embedding e = grid_embedding(n);
  const int f = grid_id(n, 3, 3);
  auto rejects = [&](Tris tris, std::vector<int> features, std::vector<Vec2> targets) {
    std::vector<Vec2> uv = e.uv;
    EXPECT_THROW(warp_features(tris, uv, features, targets), InvalidInput);
    EXPECT_EQ(uv, e.uv);
  };
  rejects(e.triangles, {f}, {});                                          // no target
  rejects(e.triangles, {f}, {Vec2(0.0, 0.5)});                            // target on a side
  rejects(e.triangles, {grid_id(n, 0, 3)}, {Vec2(0.5, 0.5)});             // boundary vertex as feature
  rejects(e.triangles, {f, f}, {Vec2(0.5, 0.5), Vec2(0.6, 0.6)});         // feature twice
  rejects(e.triangles, {f, grid_id(n, 5, 5)}, {Vec2(0.5, 0.5), Vec2(0.5, 0.5)});  // same target
  Tris flipped = e.triangles;
  std::swap(flipped[10][1], flipped[10][2]);
  rejects(flipped, {f}, {Vec2(0.5, 0.5)});
  Tris out_of_range = e.triangles;
  out_of_range[0][0] = int(e.uv.size());
  rejects(out_of_range, {f}, {Vec2(0.5, 0.5)});
  FeatureWarpOptions negative_passes;
  negative_passes.reorder_passes = -1;
  std::vector<Vec2> uv = e.uv;
  EXPECT_THROW(warp_features(e.triangles, uv, {f}, {Vec2(0.5, 0.5)}, negative_passes), InvalidInput);
  EXPECT_EQ(uv, e.uv);
}

}  // namespace
}  // namespace geomip
