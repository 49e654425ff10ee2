#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

// Signed volume (positive for an outward-oriented closed surface).
double signed_volume(const TriMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) {
    v += m.positions[t[0]].dot(m.positions[t[1]].cross(m.positions[t[2]])) / 6.0;
  }
  return v;
}

void expect_closed_genus0_manifold(const TriMesh& m) {
  const TopologyReport r = analyze_topology(m);
  EXPECT_EQ(r.boundary_loops, 0u);
  EXPECT_EQ(r.genus, 0);
  EXPECT_TRUE(r.manifold);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(r.unreferenced_vertices, 0u);
  EXPECT_GT(signed_volume(m), 0.0);
}

TEST(MeshRepair, ClosesAnOpenTubeKeepingOriginalVerticesInOrder) {
  const TriMesh tube = test::open_cylinder(24, 6);
  const RepairResult r = repair_mesh(tube);
  expect_closed_genus0_manifold(r.mesh);
  EXPECT_EQ(r.filled_holes, 2u);
  ASSERT_GE(r.mesh.positions.size(), tube.positions.size());
  for (std::size_t v = 0; v < tube.positions.size(); ++v) {
    ASSERT_EQ(r.mesh.positions[v], tube.positions[v]) << "original vertex " << v << " moved";
  }
  EXPECT_EQ(r.mesh.positions.size(), tube.positions.size() + r.added_vertices);
  // Every original triangle survives unchanged.
  for (std::size_t f = 0; f < tube.triangles.size(); ++f) {
    EXPECT_NE(std::find(r.mesh.triangles.begin(), r.mesh.triangles.end(), tube.triangles[f]), r.mesh.triangles.end());
  }
}

TEST(MeshRepair, SplitsPinchVertexAndCleansJunk) {
  TriMesh m = test::pinched_tetrahedra();
  m.positions.push_back(m.positions[1]);      // a duplicate of vertex 1 ...
  m.triangles.push_back({0, 2, 8});           // ... used by a duplicate of face {0,1,2} -> merged and dropped
  m.triangles.push_back({1, 1, 2});           // repeated index
  const TopologyReport before = analyze_topology(m);
  ASSERT_EQ(before.non_manifold_vertices, 1u);

  const RepairResult r = repair_mesh(m);
  const TopologyReport after = analyze_topology(r.mesh);
  EXPECT_TRUE(after.manifold);
  EXPECT_EQ(after.components, 2u);
  EXPECT_EQ(after.genus, 0);
  EXPECT_EQ(after.faces, 8u);
  EXPECT_EQ(r.split_non_manifold_vertices, 1u);
  EXPECT_EQ(r.removed_unreferenced_vertices, 1u);  // b's vertex 0
  EXPECT_EQ(r.merged_duplicate_vertices, 1u);
  EXPECT_EQ(r.removed_degenerate_faces, 2u);
}

TEST(MeshRepair, OrientsAnInwardClosedMeshOutward) {
  TriMesh m = test::cube();
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  ASSERT_LT(signed_volume(m), 0);
  const RepairResult r = repair_mesh(m);
  EXPECT_TRUE(r.reoriented);
  expect_closed_genus0_manifold(r.mesh);
}

TEST(MeshRepair, LargestComponentOnlyKeepsTheBiggerPieceAndItsVertexOrder) {
  // A sphere (48 faces) and, after it in the file, a small tetrahedron (4 faces) away from it.
  const TriMesh sphere = test::sphere(1);
  TriMesh tet = test::tetrahedron();
  for (auto& p : tet.positions) p += Eigen::Vector3d(5, 0, 0);
  for (const TriMesh& m : {test::join(sphere, tet), test::join(tet, sphere)}) {
    ASSERT_EQ(analyze_topology(m).components, 2u);
    EXPECT_EQ(analyze_topology(repair_mesh(m).mesh).components, 2u) << "off by default";
    RepairOptions options;
    options.largest_component_only = true;
    const RepairResult r = repair_mesh(m, options);
    EXPECT_EQ(r.removed_components, 1u);
    EXPECT_EQ(r.removed_component_faces, 4u);
    expect_closed_genus0_manifold(r.mesh);
    EXPECT_EQ(analyze_topology(r.mesh).components, 1u);
    EXPECT_EQ(r.mesh.triangles.size(), sphere.triangles.size());
    ASSERT_EQ(r.mesh.positions.size(), sphere.positions.size());
    for (std::size_t v = 0; v < sphere.positions.size(); ++v) {
      ASSERT_EQ(r.mesh.positions[v], sphere.positions[v]) << "vertex " << v << " moved or reordered";
    }
  }
  // One component: nothing to drop.
  RepairOptions options;
  options.largest_component_only = true;
  EXPECT_EQ(repair_mesh(sphere, options).removed_components, 0u);
}

TEST(MeshRepair, RejectsEmptyMesh) { EXPECT_THROW(repair_mesh(TriMesh{}), InvalidInput); }

TEST(SelfIntersections, CountsCrossingTrianglesAndNothingOnACleanSurface) {
  const TriMesh ball = test::sphere(3);
  const auto clean = count_self_intersections(ball);
  ASSERT_TRUE(clean.has_value());
  EXPECT_EQ(clean->pairs, 0u);
  EXPECT_EQ(clean->faces, 0u);

  // One vertex pushed through the surface to the far side: its umbrella crosses the triangles there.
  TriMesh folded = ball;
  folded.positions[0] = -1.5 * folded.positions[0];
  const auto fold = count_self_intersections(folded);
  ASSERT_TRUE(fold.has_value());
  EXPECT_GT(fold->pairs, 0u);
  EXPECT_GE(fold->faces, 2u);
  EXPECT_LE(fold->faces, 2 * fold->pairs);

  // Two overlapping balls in one mesh: the crossing runs along a circle, on both of them.
  TriMesh two = ball;
  for (std::size_t v = 0; v < ball.positions.size(); ++v)
    two.positions.push_back(ball.positions[v] + Eigen::Vector3d(0.5, 0, 0));
  const int n = static_cast<int>(ball.positions.size());
  for (const auto& t : ball.triangles) two.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  const auto overlap = count_self_intersections(two);
  ASSERT_TRUE(overlap.has_value());
  EXPECT_GT(overlap->faces, 20u);

  // A pinch (two tetrahedra sharing one vertex) is no polygon mesh: not counted rather than guessed.
  EXPECT_FALSE(count_self_intersections(test::pinched_tetrahedra()).has_value());
  TriMesh bad = ball;
  bad.triangles[0][1] = 1 << 30;
  EXPECT_THROW(count_self_intersections(bad), InvalidInput);
}

TEST(MeshRepairReal, BunnyBecomesClosedGenusZeroOfAboutThePapersSize) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "bunny.obj");
  const TriMesh bunny = read_mesh(path);
  const RepairResult r = repair_mesh(bunny);
  expect_closed_genus0_manifold(r.mesh);
  EXPECT_EQ(r.filled_holes, 5u);
  EXPECT_EQ(r.removed_unreferenced_vertices, 1113u);
  // The paper's closed bunny has 69,642 faces; the open one 69,451.
  EXPECT_GE(r.mesh.triangles.size(), 69600u);
  EXPECT_LE(r.mesh.triangles.size(), 69800u);
  // Surviving originals keep position and relative order.
  std::size_t next = 0;
  std::vector<char> referenced(bunny.positions.size(), 0);
  for (const auto& t : bunny.triangles) referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  for (std::size_t v = 0; v < bunny.positions.size(); ++v) {
    if (!referenced[v]) continue;
    ASSERT_EQ(r.mesh.positions[next++], bunny.positions[v]) << "original vertex " << v;
  }
}

TEST(MeshRepairReal, CowPinchIsSplit) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "cow.obj");
  const RepairResult r = repair_mesh(read_mesh(path));
  expect_closed_genus0_manifold(r.mesh);
  EXPECT_EQ(r.split_non_manifold_vertices, 1u);
}

}  // namespace
}  // namespace geomip
