#include "param/progressive_mesh.h"

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>

namespace geomip {
namespace {

/// The (n+1)×(n+1) grid lifted to a bump of height `height` plus low waves, with interior vertices jittered
/// in the plane so that collapses are not all ties.
TriMesh bump(int n, double height, unsigned seed = 1) {
  TriMesh m = test::grid(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.25 / n, 0.25 / n);
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      auto& p = m.positions[j * (n + 1) + i];
      if (i > 0 && i < n && j > 0 && j < n) p += Eigen::Vector3d(jitter(rng), jitter(rng), 0);
      const double r2 = (p.x() - 0.5) * (p.x() - 0.5) + (p.y() - 0.45) * (p.y() - 0.45);
      // The waves make the sides curved in 3D, so that flat (collinear) triangles do not shield the locks.
      p.z() = height * std::exp(-r2 / 0.04) + 0.05 * (std::sin(7 * p.x()) + std::cos(5 * p.y()));
    }
  }
  return m;
}

std::array<int, 4> grid_corners(int n) {
  return {0, n, (n + 1) * (n + 1) - 1, n * (n + 1)};
}

std::array<int, 3> canonical(std::array<int, 3> t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

/// Directed boundary edges a→b (patch on the left) of a triangle set: next[a] = b.
std::map<int, int> boundary_next(const std::vector<std::array<int, 3>>& triangles) {
  std::set<std::pair<int, int>> directed;
  for (const auto& t : triangles) {
    if (t[0] < 0) continue;
    for (int i = 0; i < 3; ++i) directed.insert({t[i], t[(i + 1) % 3]});
  }
  std::map<int, int> next;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) next[a] = b;
  }
  return next;
}

/// Side bit masks of the full patch (corners carry two bits).
std::vector<int> side_masks(std::size_t n, const PatchSides& sides) {
  std::vector<int> mask(n, 0);
  for (int k = 0; k < 4; ++k) {
    for (int v : sides[k]) mask[v] |= 1 << k;
  }
  return mask;
}

struct Fixture {
  TriMesh patch;
  PatchSides sides;
  std::vector<int> features;
  ProgressiveMesh pm;
};

Fixture make_bump(int n, std::size_t target = 0, double max_normal_deviation = 90.0) {
  Fixture f;
  f.patch = bump(n, 0.35);
  f.sides = patch_sides(f.patch, grid_corners(n));
  f.features = {(n / 2) * (n + 1) + n / 2, (n / 4) * (n + 1) + 3 * n / 4, (3 * n / 4) * (n + 1) + n / 3};
  ProgressiveMeshOptions options;
  options.target_vertices = target;
  options.max_normal_deviation_degrees = max_normal_deviation;
  f.pm = progressive_mesh(f.patch, f.sides, f.features, options);
  return f;
}

TEST(PatchSides, GridSidesFollowTheBoundaryCounterClockwise) {
  const int n = 4;
  const PatchSides sides = patch_sides(test::grid(n), grid_corners(n));
  EXPECT_EQ(sides[0], (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(sides[1], (std::vector<int>{4, 9, 14, 19, 24}));
  EXPECT_EQ(sides[2], (std::vector<int>{24, 23, 22, 21, 20}));
  EXPECT_EQ(sides[3], (std::vector<int>{20, 15, 10, 5, 0}));
}

TEST(PatchSides, RejectsCornersOutOfLoopOrderOrInside) {
  const int n = 4;
  EXPECT_THROW(patch_sides(test::grid(n), {0, 24, 4, 20}), InvalidInput);            // clockwise
  EXPECT_THROW(patch_sides(test::grid(n), {0, 4, 24, 12}), InvalidInput);            // 12 is interior
  EXPECT_THROW(patch_sides(test::grid(n), {0, 4, 24, 4}), InvalidInput);             // repeated
  EXPECT_THROW(patch_sides(test::open_cylinder(8, 3), {0, 2, 4, 6}), InvalidInput);  // not a disk
}

TEST(ProgressiveMesh, ReachesTheTargetAndKeepsCornersAndFeatures) {
  const Fixture f = make_bump(30);
  EXPECT_EQ(f.pm.base_vertices.size(), 100u);
  EXPECT_EQ(f.pm.collapses.size(), f.patch.num_vertices() - 100);
  const std::set<int> base(f.pm.base_vertices.begin(), f.pm.base_vertices.end());
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(base.count(f.sides[k].front())) << "corner " << k;
  for (int v : f.features) EXPECT_TRUE(base.count(v)) << "feature " << v;
  std::set<int> removed;
  for (const auto& c : f.pm.collapses) {
    EXPECT_TRUE(removed.insert(c.removed).second) << "vertex removed twice";
    EXPECT_FALSE(base.count(c.removed));
  }
  EXPECT_EQ(removed.size() + base.size(), f.patch.num_vertices());
}

TEST(ProgressiveMesh, BoundaryCollapsesStayOnTheirSideAlongBoundaryEdges) {
  const Fixture f = make_bump(30);
  const std::vector<int> mask = side_masks(f.patch.num_vertices(), f.sides);
  std::size_t boundary_collapses = 0;
  for (const auto& c : f.pm.collapses) {
    if (mask[c.removed] == 0) {
      EXPECT_EQ(c.boundary_neighbor, -1);
      continue;
    }
    ++boundary_collapses;
    EXPECT_NE(mask[c.removed] & mask[c.kept], 0) << "vertex " << c.removed << " left its side";
    EXPECT_NE(mask[c.removed] & mask[c.boundary_neighbor], 0);
    EXPECT_TRUE(c.left < 0 || c.right < 0) << "boundary vertex collapsed along an interior edge";
  }
  EXPECT_GT(boundary_collapses, 50u);  // 116 boundary vertices, most of them go
}

TEST(ProgressiveMesh, BaseBoundaryVisitsEachSideInOrder) {
  const Fixture f = make_bump(30);
  const std::map<int, int> next = boundary_next(f.pm.base_triangles);
  // Position of each boundary vertex along the original loop.
  std::map<int, std::pair<int, int>> where;  // vertex → (side, index in side), corners as the start of a side
  for (int k = 0; k < 4; ++k) {
    for (std::size_t i = 0; i + 1 < f.sides[k].size(); ++i) where[f.sides[k][i]] = {k, static_cast<int>(i)};
  }
  int v = f.sides[0].front();
  std::pair<int, int> previous = where.at(v);
  std::size_t steps = 0;
  do {
    ASSERT_TRUE(next.count(v)) << "base boundary loop is broken at " << v;
    v = next.at(v);
    ASSERT_TRUE(where.count(v)) << "vertex " << v << " is on the base boundary but not on the patch boundary";
    const auto here = where.at(v);
    if (v != f.sides[0].front()) {
      EXPECT_LT(previous, here) << "base boundary goes backwards at " << v;
    }
    previous = here;
    ++steps;
  } while (v != f.sides[0].front() && steps <= next.size());
  EXPECT_EQ(steps, next.size()) << "the base mesh has more than one boundary loop";
}

/// The base mesh is a disk with no triangle and no interior edge on one side.
void expect_disk_without_flat_triangles(const Fixture& f) {
  TriMesh base{f.patch.positions, f.pm.base_triangles};
  const TopologyReport topo = analyze_topology(base);
  EXPECT_TRUE(topo.manifold);
  EXPECT_EQ(topo.components, 1u);
  EXPECT_EQ(topo.boundary_loops, 1u);
  EXPECT_EQ(topo.vertices, f.pm.base_vertices.size());
  EXPECT_EQ(static_cast<long>(topo.vertices) - static_cast<long>(topo.edges) + static_cast<long>(topo.faces),
            1);
  // No interior edge between two vertices of one side (it would be flat on the square's side).
  const std::vector<int> mask = side_masks(f.patch.num_vertices(), f.sides);
  const std::map<int, int> next = boundary_next(f.pm.base_triangles);
  for (const auto& t : f.pm.base_triangles) {
    EXPECT_EQ(mask[t[0]] & mask[t[1]] & mask[t[2]], 0) << "triangle on one side";
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      const bool boundary_edge = (next.count(a) && next.at(a) == b) || (next.count(b) && next.at(b) == a);
      if (!boundary_edge) {
        EXPECT_EQ(mask[a] & mask[b], 0) << "interior edge " << a << "-" << b << " on one side";
      }
    }
  }
}

TEST(ProgressiveMesh, BaseMeshIsADiskWithoutFlatTriangles) {
  // Down to 100 vertices, to 5 (as far as the locks allow), and without the normal test (only the locks keep
  // the sides straight and chord-free then).
  for (const auto& [n, target, normals] :
       {std::tuple<int, std::size_t, double>{30, 0, 90.0}, {16, 5, 90.0}, {24, 12, 180.0}, {24, 40, 180.0}}) {
    SCOPED_TRACE("n " + std::to_string(n) + ", target " + std::to_string(target));
    expect_disk_without_flat_triangles(make_bump(n, target, normals));
  }
}

TEST(ProgressiveMesh, NoLevelHasAnInteriorEdgeOnOneSide) {
  // Replays the collapses fine to coarse and checks every edge each collapse creates: an interior edge
  // between two vertices of one side would make a flat triangle at that level of the coarse-to-fine pass.
  for (const auto& [n, target, normals] :
       {std::tuple<int, std::size_t, double>{30, 0, 90.0}, {16, 5, 90.0}, {24, 12, 180.0}}) {
    SCOPED_TRACE("n " + std::to_string(n) + ", target " + std::to_string(target));
    const Fixture f = make_bump(n, target, normals);
    const std::vector<int> mask = side_masks(f.patch.num_vertices(), f.sides);
    std::vector<std::array<int, 3>> tris = f.patch.triangles;
    std::map<std::pair<int, int>, int> faces_on_edge;
    auto count_edges = [&](const std::array<int, 3>& t, int delta) {
      for (int i = 0; i < 3; ++i) {
        faces_on_edge[{std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])}] += delta;
      }
    };
    for (const auto& t : tris) count_edges(t, 1);
    std::size_t violations = 0;
    for (const auto& c : f.pm.collapses) {
      for (int id : {c.left_triangle, c.right_triangle}) {
        if (id >= 0) count_edges(tris[id], -1);
      }
      for (int id : c.moved_triangles) {
        count_edges(tris[id], -1);
        std::replace(tris[id].begin(), tris[id].end(), c.removed, c.kept);
        count_edges(tris[id], 1);
      }
      for (int id : c.moved_triangles) {
        for (int i = 0; i < 3; ++i) {
          const int a = tris[id][i], b = tris[id][(i + 1) % 3];
          if ((mask[a] & mask[b]) != 0 && faces_on_edge[{std::min(a, b), std::max(a, b)}] == 2) ++violations;
        }
      }
    }
    EXPECT_EQ(violations, 0u);
  }
}

TEST(ProgressiveMesh, ReplayingTheSplitsRebuildsThePatch) {
  const Fixture f = make_bump(30);
  const auto full = triangles_after_splits(f.pm, f.pm.collapses.size());
  ASSERT_EQ(full.size(), f.patch.num_triangles());
  for (std::size_t i = 0; i < full.size(); ++i) {
    EXPECT_EQ(canonical(full[i]), canonical(f.patch.triangles[i])) << "triangle " << i;
  }
  // And the other way: the collapses, applied to the patch, give the base mesh.
  std::vector<std::array<int, 3>> tris = f.patch.triangles;
  for (const auto& c : f.pm.collapses) {
    for (int id : {c.left_triangle, c.right_triangle}) {
      if (id >= 0) tris[id] = {-1, -1, -1};
    }
    for (int id : c.moved_triangles) std::replace(tris[id].begin(), tris[id].end(), c.removed, c.kept);
  }
  std::vector<std::array<int, 3>> expected(f.patch.num_triangles(), {-1, -1, -1});
  for (std::size_t i = 0; i < f.pm.base_triangles.size(); ++i) {
    expected[f.pm.base_triangle_ids[i]] = f.pm.base_triangles[i];
  }
  for (std::size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(canonical(tris[i]), canonical(expected[i]));
  // Every intermediate level is a disk too (checked at a few levels).
  for (std::size_t s : {std::size_t{1}, f.pm.collapses.size() / 3, f.pm.collapses.size() / 2}) {
    TriMesh level{f.patch.positions, {}};
    for (const auto& t : triangles_after_splits(f.pm, s)) {
      if (t[0] >= 0) level.triangles.push_back(t);
    }
    const TopologyReport topo = analyze_topology(level);
    EXPECT_TRUE(topo.manifold && topo.components == 1 && topo.boundary_loops == 1 && topo.genus == 0)
        << "level " << s;
    EXPECT_EQ(topo.vertices, f.pm.base_vertices.size() + s);
  }
}

TEST(ProgressiveMesh, StopsWhenOnlyLockedCollapsesRemain) {
  // A tiny target: the locks (corners, sides straight, no flat triangles) decide where simplification stops.
  const Fixture f = make_bump(12, 5);
  EXPECT_GE(f.pm.base_vertices.size(), 7u);  // 4 corners + 3 features
  TriMesh base{f.patch.positions, f.pm.base_triangles};
  const TopologyReport topo = analyze_topology(base);
  EXPECT_TRUE(topo.manifold && topo.components == 1 && topo.boundary_loops == 1 && topo.genus == 0);
}

TEST(ProgressiveMesh, NeverCollapsesIntoAChordOnOneSide) {
  // A square pyramid: 12 boundary vertices (corners and two more per side, all features) around one apex.
  // Collapsing the apex into any boundary vertex would join it by an interior edge to a vertex of its own
  // side that is not its boundary neighbour, and flatten the triangles in between: no collapse is legal.
  TriMesh fan;
  const Eigen::Vector2d corner[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d q = corner[k] + (i / 3.0) * (corner[(k + 1) % 4] - corner[k]);
      fan.positions.emplace_back(q.x(), q.y(), 0.0);
    }
  }
  fan.positions.emplace_back(0.5, 0.5, 0.3);
  for (int i = 0; i < 12; ++i) fan.triangles.push_back({i, (i + 1) % 12, 12});
  const PatchSides sides = patch_sides(fan, {0, 3, 6, 9});
  std::vector<int> features;
  for (int i = 0; i < 12; ++i) {
    if (i % 3 != 0) features.push_back(i);
  }
  ProgressiveMeshOptions options;
  options.target_vertices = 5;
  options.max_normal_deviation_degrees = 180.0;  // only the locks decide
  const ProgressiveMesh pm = progressive_mesh(fan, sides, features, options);
  EXPECT_TRUE(pm.collapses.empty());
  EXPECT_EQ(pm.base_vertices.size(), 13u);
}

TEST(ProgressiveMesh, RejectsInvalidPatches) {
  const TriMesh g = test::grid(6);
  PatchSides sides = patch_sides(g, grid_corners(6));
  EXPECT_THROW(progressive_mesh(g, sides, {1000}), InvalidInput);  // feature out of range
  PatchSides broken = sides;
  std::swap(broken[0][1], broken[0][2]);
  EXPECT_THROW(progressive_mesh(g, broken, {}), InvalidInput);  // side not along the loop
  // A triangle whose three corners lie on one side (an ear) is flat in the square.
  TriMesh ear = g;
  ear.positions.emplace_back(0.5, -0.1, 0.0);
  const int e = static_cast<int>(ear.positions.size()) - 1;
  ear.triangles.push_back({1, e, 2});
  const PatchSides ear_sides = patch_sides(ear, grid_corners(6));
  EXPECT_THROW(progressive_mesh(ear, ear_sides, {}), InvalidInput);
  EXPECT_THROW(progressive_mesh(test::open_cylinder(8, 3), sides, {}), InvalidInput);
}

}  // namespace
}  // namespace geomip
