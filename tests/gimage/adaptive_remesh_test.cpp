// Properties of adaptive remeshing (gimage/adaptive_remesh.h): crack-free and restricted also where levels
// differ across seams, flat regions never split, one face list for a consistent set, ε → 0 gives the uniform
// level-n mesh, fewer faces for larger ε.
#include "gimage/adaptive_remesh.h"
#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/gimage/remesh_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

namespace geomip {
namespace {

constexpr int kLevel = 6;

/// The unit sphere with a narrow bump (height 0.4) centred on a vertex of the partition cut — a seam — so the
/// bump's quads are deep on both sides of the seam while the rest of the sphere stays coarse.
const ModelParameterization& bumped_sphere() {
  static ModelParameterization model;
  static bool done = false;
  if (done) return model;
  TriMesh mesh = test::sphere(4);
  const ParameterizationInput plain = test::automatic_input(mesh, "plain");
  // Bump the midpoint of the first two partition points' chord, projected to the sphere: near the cut.
  const Eigen::Vector3d a = mesh.positions[plain.partition_points[0]];
  const Eigen::Vector3d b = mesh.positions[plain.partition_points[1]];
  const Eigen::Vector3d c = (a + b).normalized();
  for (auto& p : mesh.positions) p *= 1.0 + 0.4 * std::exp(-(p - c).squaredNorm() / 0.02);
  ParameterizationInput in = plain;
  in.mesh = mesh;
  in.name = "bumped";
  model = parameterize_consistently({in}, test::quick_options())[0];
  done = true;
  return model;
}

/// Every finest boundary segment of every leaf, keyed by its two welded level-n samples: each segment must be
/// on exactly two leaves (the leaves tile the closed surface), and those two differ by at most one level.
/// Independent of the implementation's seam mapping: it welds with uniform_remesh_connectivity().
/// Returns the number of seam segments (leaves of different patches) whose leaves differ in depth.
std::size_t expect_tiling_and_restricted(const AdaptiveQuadtree& tree) {
  const int n = tree.max_depth;
  const int size = (1 << n) + 1;
  const UniformRemeshResult grid = uniform_remesh_connectivity(tree.depth.size(), tree.adjacency, n);
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> segments;  // → (patch, depth) per leaf
  for (const auto& leaf : tree.leaves()) {
    const int span = 1 << (n - leaf.depth);
    const int x0 = leaf.i * span, y0 = leaf.j * span;
    auto id = [&](int x, int y) { return grid.grid_vertex[leaf.patch][y * size + x]; };
    for (int k = 0; k < span; ++k) {
      const std::pair<int, int> segs[4][2] = {{{x0 + k, y0}, {x0 + k + 1, y0}},
                                              {{x0 + span, y0 + k}, {x0 + span, y0 + k + 1}},
                                              {{x0 + k, y0 + span}, {x0 + k + 1, y0 + span}},
                                              {{x0, y0 + k}, {x0, y0 + k + 1}}};
      for (const auto& s : segs) {
        const int u = id(s[0].first, s[0].second), v = id(s[1].first, s[1].second);
        segments[{std::min(u, v), std::max(u, v)}].push_back({leaf.patch, leaf.depth});
      }
    }
  }
  std::size_t bad_count = 0, unbalanced = 0, seam_differences = 0;
  for (const auto& [key, owners] : segments) {
    if (owners.size() != 2) {
      ++bad_count;
      continue;
    }
    if (std::abs(owners[0].second - owners[1].second) > 1) ++unbalanced;
    if (owners[0].first != owners[1].first && owners[0].second != owners[1].second) ++seam_differences;
  }
  EXPECT_EQ(bad_count, 0u) << "segments not on exactly two leaves";
  EXPECT_EQ(unbalanced, 0u) << "edge-adjacent leaves more than one level apart";
  return seam_differences;
}

std::size_t max_leaf_depth(const AdaptiveQuadtree& tree) {
  int d = 0;
  for (const auto& leaf : tree.leaves()) d = std::max(d, leaf.depth);
  return d;
}

TEST(AdaptiveRemesh, BumpAcrossASeamIsCrackFreeAndRestricted) {
  const ModelParameterization& m = bumped_sphere();
  const GeometryImages g = resample_geometry(m, kLevel, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(m, g);
  AdaptiveRemeshOptions options;
  options.epsilon = 0.004;
  // Unrestricted, the bump makes levels jump by more than one somewhere (else the test would prove nothing).
  options.restrict_levels = false;
  AdaptiveQuadtree raw = adaptive_quadtree({e}, g.adjacency, options);
  const std::size_t splits = restrict_quadtree(raw);
  EXPECT_GT(splits, 0u);
  options.restrict_levels = true;
  const AdaptiveQuadtree tree = adaptive_quadtree({e}, g.adjacency, options);
  EXPECT_EQ(tree.depth, raw.depth);
  EXPECT_EQ(max_leaf_depth(tree), static_cast<std::size_t>(kLevel));
  EXPECT_GT(expect_tiling_and_restricted(tree), 0u) << "no level difference across a seam";
  const TriMesh mesh = adaptive_remesh(g, tree);
  test::expect_watertight_oriented(mesh, 0, "bumped sphere, eps 0.004");
  // Far fewer faces than the uniform level-n mesh.
  EXPECT_LT(mesh.triangles.size(), uniform_remesh(g, kLevel).mesh.triangles.size() / 4);
}

TEST(AdaptiveRemesh, TorusIsCrackFreeAndGenusOne) {
  const ModelParameterization& m = test::parameterized("torus");
  const GeometryImages g = resample_geometry(m, kLevel, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(m, g);
  for (double eps : {0.05, 0.01, 0.003}) {
    AdaptiveRemeshOptions options;
    options.epsilon = eps;
    const AdaptiveQuadtree tree = adaptive_quadtree({e}, g.adjacency, options);
    expect_tiling_and_restricted(tree);
    test::expect_watertight_oriented(adaptive_remesh(g, tree), 1, "torus eps " + std::to_string(eps));
  }
}

TEST(AdaptiveRemesh, FlatRegionNeverSplits) {
  // A sphere whose bottom is cut flat at z = −0.5: a quad whose vertices all lie on the flat disk has error 0
  // and is never split by its error (only restriction may refine it).
  TriMesh mesh = test::sphere(4);
  for (auto& p : mesh.positions) p.z() = std::max(p.z(), -0.5);
  const ModelParameterization m =
      parameterize_consistently({test::automatic_input(mesh, "flat")}, test::quick_options())[0];
  const GeometryImages g = resample_geometry(m, kLevel, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(m, g);
  AdaptiveRemeshOptions options;
  options.epsilon = 1e-6;
  options.restrict_levels = false;
  const AdaptiveQuadtree tree = adaptive_quadtree({e}, g.adjacency, options);
  // Every quad with ≥ 4 vertices (fewer are measured with the samples), all on the flat disk: error ~0, and
  // it is a leaf or inside one.
  std::size_t flat_quads = 0;
  const int cells = 1 << kLevel;
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    const auto& patch = m.patches[p];
    for (int d = 1; d < kLevel; ++d) {
      const int side = 1 << d;
      std::vector<int> count(side * side, 0), flat(side * side, 0);
      for (std::size_t v = 0; v < patch.vertices.size(); ++v) {
        const int i = std::clamp(static_cast<int>(std::floor(patch.uv[v].x() * side)), 0, side - 1);
        const int j = std::clamp(static_cast<int>(std::floor(patch.uv[v].y() * side)), 0, side - 1);
        ++count[j * side + i];
        if (m.mesh.positions[patch.vertices[v]].z() == -0.5) ++flat[j * side + i];
      }
      for (int q = 0; q < side * side; ++q) {
        if (count[q] < 4 || flat[q] != count[q]) continue;
        ++flat_quads;
        EXPECT_LT(e.errors[p][d][q], 1e-12);
        const int span = cells >> d;
        const int ci = (q % side) * span, cj = (q / side) * span;
        EXPECT_LE(tree.depth[p][cj * cells + ci], d) << "flat quad split, patch " << p << " depth " << d;
      }
    }
  }
  EXPECT_GT(flat_quads, 0u);
  // While a curved quad with ≥ 3 vertices has a positive error.
  EXPECT_GT(e.errors[0][0][0], 0.01);
}

// Two patches, and the cube layout's six (a K-patch layout): crack-free, one face list.
TEST(AdaptiveRemesh, ConsistentPairSharesOneFaceList) {
  for (const auto* pair : {&test::deformed_sphere_pair(), &test::cube_layout_pair()}) {
    SCOPED_TRACE(std::to_string((*pair)[0].patches.size()) + " patches");
    std::vector<GeometryImages> images;
    std::vector<AdaptiveQuadErrors> errors;
    for (const auto& m : *pair) {
      images.push_back(resample_geometry(m, kLevel, {false, -1}));
      errors.push_back(adaptive_quad_errors(m, images.back()));
    }
    for (double eps : {0.02, 0.005}) {
      AdaptiveRemeshOptions options;
      options.epsilon = eps;
      const AdaptiveQuadtree tree = adaptive_quadtree(errors, images[0].adjacency, options);
      expect_tiling_and_restricted(tree);
      EXPECT_EQ(tree.depth.size(), (*pair)[0].patches.size());
      // The shared tree is at least as deep as each model's own (eq. 6: the maximum error).
      for (std::size_t k = 0; k < 2; ++k) {
        const AdaptiveQuadtree own = adaptive_quadtree({errors[k]}, images[k].adjacency, options);
        for (std::size_t p = 0; p < tree.depth.size(); ++p) {
          for (std::size_t c = 0; c < tree.depth[p].size(); ++c) ASSERT_GE(tree.depth[p][c], own.depth[p][c]);
        }
      }
      const TriMesh a = adaptive_remesh(images[0], tree);
      const TriMesh b = adaptive_remesh(images[1], tree);
      EXPECT_EQ(a.triangles, b.triangles);
      EXPECT_EQ(a.positions.size(), b.positions.size());
      EXPECT_NE(a.positions, b.positions);
      test::expect_watertight_oriented(a, 0, "a");
      test::expect_watertight_oriented(b, 0, "b");
    }
  }
}

TEST(AdaptiveRemesh, EpsilonZeroIsUniformAndLargerEpsilonHasFewerFaces) {
  const ModelParameterization& m = test::parameterized("sphere");
  // ε = 0 at a level where every quad above it holds several vertices of the curved sphere: all split. (At
  // finer levels a quad inside one mesh triangle is exactly flat, error 0, and rightly stays whole.)
  const GeometryImages coarse = resample_geometry(m, 3, {false, -1});
  AdaptiveRemeshOptions options;
  options.epsilon = 0;
  const TriMesh zero = adaptive_remesh(
      coarse, adaptive_quadtree({adaptive_quad_errors(m, coarse)}, coarse.adjacency, options));
  const UniformRemeshResult uniform = uniform_remesh(coarse, 3);
  EXPECT_EQ(zero.triangles.size(), uniform.mesh.triangles.size());
  EXPECT_EQ(zero.positions.size(), uniform.mesh.positions.size());

  const GeometryImages g = resample_geometry(m, kLevel, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(m, g);
  const TriMesh finest = adaptive_remesh(g, adaptive_quadtree({e}, g.adjacency, options));
  EXPECT_LE(finest.triangles.size(), uniform_remesh(g, kLevel).mesh.triangles.size());
  std::size_t previous = finest.triangles.size();
  for (double eps : {1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 1.0}) {
    options.epsilon = eps;
    const AdaptiveQuadtree tree = adaptive_quadtree({e}, g.adjacency, options);
    const TriMesh mesh = adaptive_remesh(g, tree);
    EXPECT_LE(mesh.triangles.size(), previous) << "eps " << eps;
    previous = mesh.triangles.size();
    test::expect_watertight_oriented(mesh, 0, "sphere eps " + std::to_string(eps), eps < 0.5);
  }
  EXPECT_LT(previous, finest.triangles.size());
}

TEST(AdaptiveRemesh, MeasuringSamplesNeverLowersTheError) {
  const ModelParameterization& m = bumped_sphere();
  const GeometryImages g = resample_geometry(m, 5, {false, -1});
  const AdaptiveQuadErrors vertices = adaptive_quad_errors(m, g);
  AdaptiveErrorOptions strict;
  strict.measure_samples = true;
  const AdaptiveQuadErrors samples = adaptive_quad_errors(m, g, strict);
  std::size_t higher = 0;
  for (std::size_t p = 0; p < 2; ++p) {
    for (int d = 0; d <= 5; ++d) {
      for (std::size_t q = 0; q < vertices.errors[p][d].size(); ++q) {
        ASSERT_GE(samples.errors[p][d][q], vertices.errors[p][d][q]);
        higher += samples.errors[p][d][q] > vertices.errors[p][d][q];
      }
    }
  }
  EXPECT_GT(higher, 0u);
  AdaptiveRemeshOptions options;
  options.epsilon = 0.004;
  const AdaptiveQuadtree tree = adaptive_quadtree({samples}, g.adjacency, options);
  expect_tiling_and_restricted(tree);
  test::expect_watertight_oriented(adaptive_remesh(g, tree), 0, "bumped sphere, samples measured");
}

TEST(AdaptiveRemesh, RejectsMismatchedInputs) {
  const ModelParameterization& m = test::parameterized("sphere");
  const GeometryImages g = resample_geometry(m, 3, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(m, g);
  EXPECT_THROW(adaptive_quadtree({}, g.adjacency), InvalidInput);
  AdaptiveRemeshOptions negative;
  negative.epsilon = -1;
  EXPECT_THROW(adaptive_quadtree({e}, g.adjacency, negative), InvalidInput);
  std::vector<SideLink> bad = g.adjacency;
  bad.pop_back();
  EXPECT_THROW(adaptive_quadtree({e}, bad), InvalidInput);
  const AdaptiveQuadtree tree = adaptive_quadtree({e}, g.adjacency);
  EXPECT_THROW(adaptive_remesh(resample_geometry(m, 4, {false, -1}), tree), InvalidInput);
  AdaptiveRemeshOptions unrestricted;
  unrestricted.epsilon = 0;
  unrestricted.restrict_levels = false;
  AdaptiveQuadtree lopsided = adaptive_quadtree({e}, g.adjacency, unrestricted);
  // Make one patch entirely coarse: its neighbour across the seam is now 3 levels finer.
  std::fill(lopsided.depth[0].begin(), lopsided.depth[0].end(), 0);
  EXPECT_THROW(adaptive_remesh(g, lopsided), InvalidInput);
  GeometryImages empty;
  EXPECT_THROW(adaptive_quad_errors(m, empty), InvalidInput);
}

}  // namespace
}  // namespace geomip
