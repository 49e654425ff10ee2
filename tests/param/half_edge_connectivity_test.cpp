// The partition's half-edge connectivity: the incremental update after edge splits must give exactly the
// arrays a fresh build gives (the partition's paths, and so every layout and pack, depend on their order).
#include "param/half_edge_connectivity.h"

#include "mesh/errors.h"
#include "test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace geomip {
namespace {

void expect_same(const Connectivity& a, const Connectivity& b) {
  EXPECT_EQ(a.out_begin, b.out_begin);
  EXPECT_EQ(a.out, b.out);
  EXPECT_EQ(a.out_to, b.out_to);
  EXPECT_EQ(a.opposite, b.opposite);
}

// Random undirected edges of `m`, `count` of them at most, some sharing a triangle (two or three of its
// edges split at once) and some listed twice or in both directions.
std::vector<std::pair<int, int>> random_edges(const TriMesh& m, std::size_t count, std::mt19937& rng) {
  std::vector<std::pair<int, int>> edges;
  std::uniform_int_distribution<std::size_t> face(0, m.triangles.size() - 1);
  std::uniform_int_distribution<int> corner(0, 2), how_many(1, 3);
  while (edges.size() < count) {
    const auto& t = m.triangles[face(rng)];
    const int first = corner(rng), n = how_many(rng);
    for (int k = 0; k < n; ++k) {
      const int j = (first + k) % 3;
      if (k == 1 && (rng() & 1))
        edges.emplace_back(t[(j + 1) % 3], t[j]);  // the other direction
      else
        edges.emplace_back(t[j], t[(j + 1) % 3]);
    }
    if ((rng() & 7) == 0) edges.push_back(edges.back());  // listed twice
  }
  return edges;
}

TEST(HalfEdgeConnectivity, SplitEdgesUpdatesToExactlyAFreshBuild) {
  for (const TriMesh& start : {test::sphere(2), test::torus(12, 8), test::double_torus()}) {
    TriMesh m = start;
    Connectivity conn = build_connectivity(m);
    std::mt19937 rng(7);
    for (int round = 0; round < 6; ++round) {
      const std::size_t faces = m.triangles.size(), vertices = m.positions.size();
      const auto edges = random_edges(m, 1 + static_cast<std::size_t>(round) * 9, rng);
      std::set<std::pair<int, int>> distinct;
      for (auto [a, b] : edges) distinct.emplace(std::min(a, b), std::max(a, b));
      const std::size_t added = split_edges(m, conn, edges);
      EXPECT_EQ(added, distinct.size());
      EXPECT_EQ(m.positions.size(), vertices + added);
      EXPECT_GT(m.triangles.size(), faces);
      expect_same(conn, build_connectivity(m));
      for (int h = 0; h < static_cast<int>(conn.opposite.size()); ++h) {  // a closed mesh stays closed
        ASSERT_GE(conn.opposite[h], 0);
        EXPECT_EQ(conn.opposite[conn.opposite[h]], h);
      }
    }
  }
}

TEST(HalfEdgeConnectivity, RefusesWhatIsNotAnEdgeAndAnInconsistentMesh) {
  TriMesh m = test::tetrahedron();
  Connectivity conn = build_connectivity(m);
  EXPECT_THROW(split_edges(m, conn, {{0, 0}}), std::logic_error);
  std::swap(m.triangles[0][0], m.triangles[0][1]);  // one triangle turned over
  EXPECT_THROW(build_connectivity(m), InvalidInput);
}

}  // namespace
}  // namespace geomip
