#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

TEST(MeshTopology, ClosedSurfacesOfGenusZeroAndOne) {
  const TopologyReport tet = analyze_topology(test::tetrahedron());
  EXPECT_EQ(tet.vertices, 4u);
  EXPECT_EQ(tet.faces, 4u);
  EXPECT_EQ(tet.edges, 6u);
  EXPECT_EQ(tet.genus, 0);
  EXPECT_EQ(tet.boundary_loops, 0u);
  EXPECT_TRUE(tet.manifold);
  EXPECT_NEAR(tet.bbox_diagonal, std::sqrt(12.0), 1e-12);

  const TopologyReport torus = analyze_topology(test::torus(10, 6));
  EXPECT_EQ(torus.genus, 1);
  EXPECT_EQ(torus.components, 1u);
  EXPECT_TRUE(torus.manifold);

  const TopologyReport two = analyze_topology(test::join(test::torus(8, 5), test::cube()));
  EXPECT_EQ(two.components, 2u);
  EXPECT_EQ(two.genus, 1);  // total genus of the components
}

TEST(MeshTopology, BoundaryLoopsAndCappedGenus) {
  const TopologyReport disk = analyze_topology(test::grid(5));
  EXPECT_EQ(disk.boundary_loops, 1u);
  EXPECT_EQ(disk.boundary_edges, 20u);
  EXPECT_EQ(disk.genus, 0);
  const TopologyReport tube = analyze_topology(test::open_cylinder(12, 4));
  EXPECT_EQ(tube.boundary_loops, 2u);
  EXPECT_EQ(tube.genus, 0);  // a tube with both ends capped is a sphere
  EXPECT_TRUE(tube.manifold);
}

TEST(MeshTopology, NonManifoldEdgeIsCountedAndGenusUndefined) {
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const TopologyReport r = analyze_topology(m);
  EXPECT_EQ(r.non_manifold_edges, 1u);
  EXPECT_FALSE(r.manifold);
  EXPECT_FALSE(r.genus.has_value());
}

TEST(MeshTopology, PinchVertexIsNonManifoldButGenusIsThatOfTheSplitSurface) {
  TriMesh m = test::pinched_tetrahedra();
  const TopologyReport r = analyze_topology(m);
  EXPECT_EQ(r.non_manifold_vertices, 1u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_FALSE(r.manifold);
  EXPECT_EQ(r.components, 2u);  // edge-connected: the pinch does not join surfaces
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.unreferenced_vertices, 1u);  // b's old vertex 0 is no longer used
  EXPECT_EQ(r.vertices, 7u);
}

TEST(MeshTopology, DegenerateFacesAndUnreferencedVertices) {
  TriMesh m = test::tetrahedron();
  m.positions.push_back({5, 5, 5});                       // unreferenced
  m.positions.push_back({2, 2, 2});                       // collinear with vertex 0 and...
  m.positions.push_back({3, 3, 3});                       // ...this one
  m.triangles.push_back({0, 0, 1});                       // repeated index
  m.triangles.push_back({0, 5, 6});                       // zero area
  const TopologyReport r = analyze_topology(m);
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  EXPECT_EQ(r.faces, 6u);
}

TEST(MeshTopology, RejectsOutOfRangeIndex) {
  TriMesh m = test::tetrahedron();
  m.triangles.push_back({0, 1, 7});
  EXPECT_THROW(analyze_topology(m), InvalidInput);
}

}  // namespace
}  // namespace geomip
