#include "param/mean_value_embedding.h"

#include "mesh/errors.h"
#include "param/progressive_mesh.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace geomip {
namespace {

std::array<int, 4> grid_corners(int n) {
  return {0, n, (n + 1) * (n + 1) - 1, n * (n + 1)};
}

/// The grid with its interior vertices moved randomly in the plane (still a valid planar triangulation).
TriMesh jittered_grid(int n, unsigned seed) {
  TriMesh m = test::grid(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3 / n, 0.3 / n);
  for (int j = 1; j < n; ++j) {
    for (int i = 1; i < n; ++i) m.positions[j * (n + 1) + i] += Eigen::Vector3d(jitter(rng), jitter(rng), 0);
  }
  return m;
}

/// A strongly curved patch: the jittered grid lifted onto a saddle plus a narrow bump.
TriMesh curved(int n) {
  TriMesh m = jittered_grid(n, 7);
  for (auto& p : m.positions) {
    const double r2 = (p.x() - 0.3) * (p.x() - 0.3) + (p.y() - 0.6) * (p.y() - 0.6);
    p.z() = 0.8 * (p.x() - 0.5) * (p.y() - 0.5) + 0.5 * std::exp(-r2 / 0.01);
  }
  return m;
}

TEST(SquareBoundaryUv, CornersOnCornersAndChordLengthAlongSides) {
  const int n = 8;
  TriMesh g = test::grid(n);
  // Uneven spacing on the bottom side: chord length must follow it.
  g.positions[1].x() = 0.02;
  const PatchSides sides = patch_sides(g, grid_corners(n));
  const auto uv = square_boundary_uv(g.positions, sides);
  EXPECT_EQ(uv.size(), 4u * n);
  std::set<int> seen;
  for (const auto& [v, p] : uv) {
    EXPECT_TRUE(seen.insert(v).second) << "vertex " << v << " twice";
    EXPECT_TRUE(p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1) << "vertex " << v << " not on a side";
    EXPECT_NEAR(p.x(), g.positions[v].x(), 1e-15);  // the grid is the unit square: chord length is exact
    EXPECT_NEAR(p.y(), g.positions[v].y(), 1e-15);
  }
  const TriMesh empty;
  EXPECT_THROW(square_boundary_uv(empty.positions, sides), InvalidInput);
}

// With metric tensors the chord lengths are measured in them (the mean of an edge's ends): a metric that
// makes the left half of the grid twice as long along x moves the bottom side's vertices right, in closed
// form, and leaves the left side (whose edges run along y) where it was. Tensors of the wrong count are
// refused.
TEST(SquareBoundaryUv, ChordLengthInAMetric) {
  const int n = 8;
  const TriMesh g = test::grid(n);
  const PatchSides sides = patch_sides(g, grid_corners(n));
  std::vector<Eigen::Matrix3d> metrics;
  for (const auto& p : g.positions) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    if (p.x() < 0.5) m(0, 0) = 4;
    metrics.push_back(m);
  }
  const auto uv = square_boundary_uv(g.positions, sides, &metrics);
  // bottom side: three edges of length 2/8, one of √2.5/8 (its ends' mean is 2.5), four of 1/8
  const double total = 6 + std::sqrt(2.5) + 4;
  for (const auto& [v, p] : uv) {
    const Eigen::Vector3d& q = g.positions[v];
    if (q.y() == 0 && q.x() > 0 && q.x() < 1) {
      const int i = static_cast<int>(std::lround(q.x() * n));
      const double s = i <= 3 ? 2.0 * i : i == 4 ? 6 + std::sqrt(2.5) : 6 + std::sqrt(2.5) + (i - 4);
      EXPECT_NEAR(p.x(), s / total, 1e-14) << "vertex " << v;
      EXPECT_EQ(p.y(), 0.0);
    }
    if (q.x() == 0) {
      EXPECT_NEAR(p.y(), q.y(), 1e-15) << "left side, vertex " << v;
    }
  }
  std::vector<Eigen::Matrix3d> short_metrics(3, Eigen::Matrix3d::Identity());
  EXPECT_THROW(square_boundary_uv(g.positions, sides, &short_metrics), InvalidInput);
}

TEST(MeanValueEmbedding, ReproducesAPlanarTriangulationOfTheSquare) {
  // Mean value coordinates reproduce linear functions: with the boundary at its true place, a planar mesh
  // is its own parameterization, however irregular.
  for (const TriMesh& g : {test::grid(20), jittered_grid(20, 3)}) {
    const PatchSides sides = patch_sides(g, grid_corners(20));
    const auto result =
        mean_value_embedding(g.positions, g.triangles, square_boundary_uv(g.positions, sides));
    EXPECT_EQ(result.free_vertices, 19u * 19u);
    EXPECT_LT(result.residual, 1e-12);
    for (std::size_t v = 0; v < g.positions.size(); ++v) {
      EXPECT_NEAR(result.uv[v].x(), g.positions[v].x(), 1e-12) << v;
      EXPECT_NEAR(result.uv[v].y(), g.positions[v].y(), 1e-12) << v;
    }
  }
}

TEST(MeanValueEmbedding, CurvedPatchIsAnEmbeddingOfTheSquare) {
  const int n = 40;
  const TriMesh m = curved(n);
  const PatchSides sides = patch_sides(m, grid_corners(n));
  const auto boundary = square_boundary_uv(m.positions, sides);
  const auto result = mean_value_embedding(m.positions, m.triangles, boundary);
  EXPECT_EQ(count_flipped_triangles(result.uv, m.triangles), 0u);
  std::vector<char> on_boundary(m.positions.size(), 0);
  for (const auto& [v, p] : boundary) {
    on_boundary[v] = 1;
    EXPECT_EQ(result.uv[v], p);
  }
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    if (on_boundary[v]) continue;
    EXPECT_GT(result.uv[v].minCoeff(), 0.0) << v;
    EXPECT_LT(result.uv[v].maxCoeff(), 1.0) << v;
  }
  // Not the identity: the bump pulls parameters towards it (the map is not the planar projection).
  double moved = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    moved = std::max(moved, (result.uv[v] - m.positions[v].head<2>()).norm());
  }
  EXPECT_GT(moved, 1e-3);
  // Eq. (1): each free vertex is a convex combination of its neighbours.
  EXPECT_LT(result.residual, 1e-10);
}

TEST(MeanValueEmbedding, EmbedsABaseMeshInThePatchIdSpace) {
  const int n = 30;
  const TriMesh m = curved(n);
  const PatchSides sides = patch_sides(m, grid_corners(n));
  const ProgressiveMesh pm = progressive_mesh(m, sides, {});
  const auto result =
      mean_value_embedding(m.positions, pm.base_triangles, square_boundary_uv(m.positions, sides));
  EXPECT_EQ(count_flipped_triangles(result.uv, pm.base_triangles), 0u);
  const std::set<int> base(pm.base_vertices.begin(), pm.base_vertices.end());
  std::size_t interior = 0;
  for (int v : pm.base_vertices) {
    ASSERT_TRUE(result.uv[v].allFinite());
    interior += result.uv[v].minCoeff() > 0 && result.uv[v].maxCoeff() < 1 ? 1 : 0;
  }
  EXPECT_EQ(result.free_vertices, interior);
  for (const auto& c : pm.collapses) {
    // Removed interior vertices have no parameter; removed boundary vertices keep their fixed one.
    if (c.boundary_neighbor < 0) {
      EXPECT_TRUE(std::isnan(result.uv[c.removed].x()));
    }
  }
}

TEST(MeanValueEmbedding, RejectsAFreeBoundaryVertexAndBadIds) {
  const TriMesh g = test::grid(4);
  auto boundary = square_boundary_uv(g.positions, patch_sides(g, grid_corners(4)));
  auto missing = boundary;
  missing.pop_back();
  EXPECT_THROW(mean_value_embedding(g.positions, g.triangles, missing), InvalidInput);
  auto twice = boundary;
  twice.push_back(boundary.front());
  EXPECT_THROW(mean_value_embedding(g.positions, g.triangles, twice), InvalidInput);
  auto out_of_range = boundary;
  out_of_range.emplace_back(1000, Eigen::Vector2d(0.5, 0.5));
  EXPECT_THROW(mean_value_embedding(g.positions, g.triangles, out_of_range), InvalidInput);
  TriMesh collapsed = g;
  collapsed.positions[6] = collapsed.positions[7];  // two interior vertices on top of each other
  EXPECT_THROW(mean_value_embedding(collapsed.positions, collapsed.triangles, boundary), InvalidInput);
}

TEST(CountFlippedTriangles, CountsClockwiseAndDegenerateAndSkipsAbsent) {
  const std::vector<Eigen::Vector2d> uv = {{0, 0}, {1, 0}, {0, 1}, {2, 0}};
  EXPECT_EQ(count_flipped_triangles(uv, {{0, 1, 2}}), 0u);
  EXPECT_EQ(count_flipped_triangles(uv, {{0, 2, 1}}), 1u);
  EXPECT_EQ(count_flipped_triangles(uv, {{0, 1, 3}}), 1u);
  EXPECT_EQ(count_flipped_triangles(uv, {{-1, -1, -1}, {0, 1, 2}}), 0u);
  EXPECT_DOUBLE_EQ(signed_uv_area2(uv, {0, 1, 2}), 1.0);
}

}  // namespace
}  // namespace geomip
