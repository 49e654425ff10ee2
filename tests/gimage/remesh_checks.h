// Properties every uniform remesh must have: closed (each edge in exactly two faces), consistently oriented
// (each directed edge once), the input's genus, outward (positive signed volume).
#pragma once

#include "mesh/mesh.h"
#include "mesh/mesh_topology.h"

#include <gtest/gtest.h>

#include <map>
#include <utility>

namespace geomip::test {

inline double signed_volume(const TriMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) v += m.positions[t[0]].dot(m.positions[t[1]].cross(m.positions[t[2]]));
  return v / 6.0;
}

/// `outward`: also require a positive signed volume (not for M0 of a sphere, whose 4 corners may be
/// coplanar).
inline void expect_watertight_oriented(const TriMesh& mesh, int genus, const std::string& what,
                                       bool outward = true) {
  SCOPED_TRACE(what);
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  std::size_t bad = 0;
  for (const auto& [e, count] : directed) {
    const auto back = directed.find({e.second, e.first});
    if (count != 1 || back == directed.end() || back->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "directed edges not paired exactly once with their reverse";
  const TopologyReport r = analyze_topology(mesh);
  EXPECT_EQ(r.boundary_loops, 0u);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_TRUE(r.manifold);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(r.unreferenced_vertices, 0u);
  ASSERT_TRUE(r.genus.has_value());
  EXPECT_EQ(*r.genus, genus);
  if (outward) {
    EXPECT_GT(signed_volume(mesh), 0.0) << "not outward";
  }
}

}  // namespace geomip::test
