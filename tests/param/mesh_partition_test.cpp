// Properties of partition_mesh() and choose_partition_points() on synthetic meshes (label unit).
#include "param/mesh_partition.h"

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"
#include "tests/param/partition_checks.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>

namespace geomip {
namespace {

using test::nearest_vertex;
using test::sphere;
using test::subdivide;

// Tutte's map of every patch onto the unit square is one-to-one (the use §3.3 makes of the patches).
std::string embedding_problems(const PartitionResult& r) {
  std::string problems;
  for (int p = 0; p < static_cast<int>(r.patches.size()); ++p) {
    const std::size_t flipped = test::tutte_square_embedding(r, p).flipped;
    if (flipped) problems += "patch " + std::to_string(p) + ": " + std::to_string(flipped) + " flipped; ";
  }
  return problems;
}

void expect_invalid(const TriMesh& m, const std::vector<int>& p, const std::vector<int>& aux,
                    const std::string& fragment, const PartitionOptions& options = {}) {
  try {
    partition_mesh(m, p, aux, options);
    ADD_FAILURE() << "no exception; expected one mentioning '" << fragment << "'";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("partition_mesh:"), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
  }
}

// ------------------------------------------------------------------------------------------- genus 0

TEST(PartitionGenus0, SphereEquatorLoopMakesNorthPatch0) {
  const TriMesh m = sphere(4);  // 3072 triangles
  const std::vector<int> p = {nearest_vertex(m, {1, 0, 0}), nearest_vertex(m, {0, 1, 0}),
                              nearest_vertex(m, {-1, 0, 0}), nearest_vertex(m, {0, -1, 0})};
  const PartitionResult r = partition_mesh(m, p, {});
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  // The loop runs CCW seen from +z, so patch 0 (left of the loop, outside) is the northern half.
  for (int k = 0; k < 2; ++k) {
    double z = 0.0;
    for (int f : r.patches[k].faces) {
      for (int v : r.mesh.triangles[f]) z += r.mesh.positions[v].z();
    }
    EXPECT_GT(k == 0 ? z : -z, 0.0) << "patch " << k;
  }
  const PartitionStats s = partition_stats(r);
  EXPECT_GT(s.area_balance, 0.9);
  EXPECT_NEAR(s.cut_length, 2 * 3.14159265, 0.6);  // about the equator
  // Patch 1 is patch 0 mirrored across its diagonal P0-P2: side s of patch 0 is side 3-s of patch 1.
  for (int s2 = 0; s2 < 4; ++s2) {
    EXPECT_EQ(r.adjacency[s2].other_patch, 1);
    EXPECT_EQ(r.adjacency[s2].other_side, 3 - s2);
  }
}

TEST(PartitionGenus0, AuxiliaryPointsGuideThePaths) {
  const TriMesh m = sphere(4);
  const std::vector<int> p = {nearest_vertex(m, {1, 0, 0}), nearest_vertex(m, {0, 1, 0}),
                              nearest_vertex(m, {-1, 0, 0}), nearest_vertex(m, {0, -1, 0})};
  // Path 0 (P0→P1) is forced over the north pole.
  const Eigen::Vector3d over = Eigen::Vector3d(0.5, 0.5, 1).normalized();
  const std::vector<int> aux = {nearest_vertex(m, over), nearest_vertex(m, {-0.7, 0.7, -0.1}),
                                nearest_vertex(m, {-0.7, -0.7, -0.1}), nearest_vertex(m, {0.7, -0.7, -0.1})};
  const PartitionResult r = partition_mesh(m, p, aux);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  for (int k = 0; k < 4; ++k) {
    const auto& side = r.patches[0].sides[k].vertices;
    EXPECT_NE(std::find(side.begin(), side.end(), aux[k]), side.end()) << "side " << k;
  }
  // The northern detour makes patch 0 (left of the loop) the smaller one.
  const PartitionStats s = partition_stats(r);
  EXPECT_LT(s.patches[0].area, s.patches[1].area);
}

TEST(PartitionGenus0, TetrahedronChordsAreSplit) {
  const TriMesh m = test::tetrahedron();
  const std::vector<int> p = {0, 1, 2, 3};
  // The loop 0-1-2-3 leaves the chords 0-2 and 1-3: every triangle has 3 loop vertices.
  const PartitionResult r = partition_mesh(m, p, {});
  EXPECT_EQ(r.split_vertices, 2u);
  EXPECT_EQ(r.mesh.num_vertices(), 6u);
  EXPECT_EQ(r.mesh.num_triangles(), 8u);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  PartitionOptions strict;
  strict.split_degenerate = false;
  expect_invalid(m, p, {}, "degenerate configuration", strict);
}

TEST(PartitionGenus0, CubeFaceLoopSplitsItsDiagonal) {
  const TriMesh m = test::cube();
  const std::vector<int> p = {0, 1, 2, 3};  // the bottom face; its diagonal 0-2 is a chord
  const PartitionResult r = partition_mesh(m, p, {});
  EXPECT_EQ(r.split_vertices, 1u);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  // Untouched triangles keep their ids and corners.
  int kept = 0;
  for (std::size_t f = 0; f < m.triangles.size(); ++f) kept += r.mesh.triangles[f] == m.triangles[f];
  EXPECT_EQ(kept, 10);
}

TEST(PartitionGenus0, EveryOrderedQuadrupleOnTetrahedronAndCubePartitions) {
  // The coarsest closed meshes: paths are single edges, chords everywhere, corners walled in by earlier
  // paths.
  for (const TriMesh& m : {test::tetrahedron(), test::cube()}) {
    const int nv = static_cast<int>(m.positions.size());
    int count = 0;
    std::vector<int> p(4);
    for (p[0] = 0; p[0] < nv; ++p[0]) {
      for (p[1] = 0; p[1] < nv; ++p[1]) {
        for (p[2] = 0; p[2] < nv; ++p[2]) {
          for (p[3] = 0; p[3] < nv; ++p[3]) {
            if (std::set<int>(p.begin(), p.end()).size() != 4) continue;
            ++count;
            try {
              const PartitionResult r = partition_mesh(m, p, {});
              ASSERT_EQ(test::check_partition(m, p, r), "")
                  << p[0] << "," << p[1] << "," << p[2] << "," << p[3];
              ASSERT_EQ(embedding_problems(r), "") << p[0] << "," << p[1] << "," << p[2] << "," << p[3];
            } catch (const Error& e) {
              ADD_FAILURE() << p[0] << "," << p[1] << "," << p[2] << "," << p[3] << ": " << e.what();
            }
          }
        }
      }
    }
    EXPECT_EQ(count, nv * (nv - 1) * (nv - 2) * (nv - 3));
  }
}

TEST(PartitionGenus0, WalledInCornerIsFreedBySplittingChords) {
  // On the cube, paths 0-6 and 6-3 leave vertex 3's free neighbours cut off from 1 by chords.
  const TriMesh m = test::cube();
  const std::vector<int> p = {0, 6, 3, 1};
  PartitionOptions strict;
  strict.split_degenerate = false;
  expect_invalid(m, p, {}, "cannot trace path 2 from vertex 3 to vertex 1", strict);
  const PartitionResult r = partition_mesh(m, p, {});
  EXPECT_GT(r.split_vertices, 0u);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
}

TEST(PartitionGenus0, RandomQuadruplesOnASubdividedCubeAreValidOrCleanlyRejected) {
  const TriMesh m = subdivide(test::cube(), 1);
  const int nv = static_cast<int>(m.positions.size());
  std::mt19937 rng(7);
  int valid = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<int> ids(nv);
    std::iota(ids.begin(), ids.end(), 0);
    std::shuffle(ids.begin(), ids.end(), rng);
    const std::vector<int> p(ids.begin(), ids.begin() + 4);
    try {
      const PartitionResult r = partition_mesh(m, p, {});
      EXPECT_EQ(test::check_partition(m, p, r), "")
          << "points " << p[0] << "," << p[1] << "," << p[2] << "," << p[3];
      ++valid;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("cannot trace path"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(valid, 360);
}

TEST(PartitionGenus0, RandomPointsOnAFineSphereAlwaysPartition) {
  const TriMesh m = sphere(3);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(m.positions.size()) - 1);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<int> p;
    while (p.size() < 4) {
      const int v = pick(rng);
      if (std::find(p.begin(), p.end(), v) == p.end()) p.push_back(v);
    }
    const PartitionResult r = partition_mesh(m, p, {});
    EXPECT_EQ(test::check_partition(m, p, r), "") << "trial " << trial;
    EXPECT_EQ(embedding_problems(r), "") << "trial " << trial;
  }
}

TEST(PartitionChecks, TheCheckerCatchesBrokenResults) {
  // check_partition() is what the other tests rely on: it must see each kind of damage.
  const TriMesh m = sphere(3);
  const std::vector<int> p = {nearest_vertex(m, {1, 0, 0}), nearest_vertex(m, {0, 1, 0}),
                              nearest_vertex(m, {-1, 0, 0}), nearest_vertex(m, {0, -1, 0})};
  const PartitionResult good = partition_mesh(m, p, {});
  ASSERT_EQ(test::check_partition(m, p, good), "");
  std::vector<std::pair<std::string, PartitionResult>> broken;
  broken.emplace_back("face moved to the other patch", good);
  {
    auto& r = broken.back().second;
    const int f = r.patches[0].faces.back();
    r.patches[0].faces.pop_back();
    r.patches[1].faces.push_back(f);
    r.face_patch[f] = 1;
  }
  broken.emplace_back("face dropped", good);
  broken.back().second.patches[1].faces.pop_back();
  broken.emplace_back("side reversed", good);
  {
    auto& v = broken.back().second.patches[0].sides[1].vertices;
    std::reverse(v.begin(), v.end());
  }
  broken.emplace_back("corners rotated", good);
  {
    auto& patch = broken.back().second.patches[1];
    std::rotate(patch.corners.begin(), patch.corners.begin() + 1, patch.corners.end());
    std::rotate(patch.sides.begin(), patch.sides.begin() + 1, patch.sides.end());
  }
  broken.emplace_back("wrong gluing", good);
  broken.back().second.adjacency[0].other_side = 2;
  broken.emplace_back("vertex moved", good);
  broken.back().second.mesh.positions[p[2]].z() += 0.01;
  for (const auto& [what, r] : broken) EXPECT_NE(test::check_partition(m, p, r), "") << what;

  // The cube's bottom loop with its chord 0-2 put back (the split undone): only that defect is reported.
  const TriMesh cube = test::cube();
  const std::vector<int> q = {0, 1, 2, 3};
  PartitionResult unsplit = partition_mesh(cube, q, {});
  ASSERT_EQ(unsplit.split_vertices, 1u);
  unsplit.mesh = cube;
  unsplit.split_vertices = 0;
  unsplit.face_patch.resize(cube.triangles.size());
  for (auto& patch : unsplit.patches) {
    patch.faces.erase(std::remove_if(patch.faces.begin(), patch.faces.end(), [](int f) { return f >= 12; }),
                      patch.faces.end());
  }
  const std::string problems = test::check_partition(cube, q, unsplit);
  EXPECT_NE(problems.find("all vertices on the cut"), std::string::npos) << problems;
  EXPECT_NE(problems.find("edge (0,2) joins two cut vertices"), std::string::npos) << problems;
  EXPECT_EQ(std::count(problems.begin(), problems.end(), ';'), 2) << "only the chord expected: " << problems;
}

TEST(PartitionGenus0, ChosenPointsCutAnEllipsoidAlongItsThinDirection) {
  TriMesh m = sphere(4);
  for (auto& q : m.positions) q = Eigen::Vector3d(3 * q.x() + 0.2 * q.y(), 2 * q.y(), 0.7 * q.z());
  const PartitionPoints pts = choose_partition_points(m);
  ASSERT_EQ(pts.partition_points.size(), 4u);
  EXPECT_EQ(pts.auxiliary_points.size(), 4u);
  const PartitionResult r = partition_mesh(m, pts.partition_points, pts.auxiliary_points);
  EXPECT_EQ(test::check_partition(m, pts.partition_points, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  const PartitionStats s = partition_stats(r);
  EXPECT_GT(s.area_balance, 0.9);
  // Each half is the top or the bottom (z) of the flat ellipsoid: nearly a height field.
  for (const auto& ps : s.patches) EXPECT_GT(ps.flatness, 0.6);
  // Corners are the x and y extremes of the outline.
  double max_abs_x = 0.0;
  for (int v : pts.partition_points) max_abs_x = std::max(max_abs_x, std::abs(m.positions[v].x()));
  EXPECT_GT(max_abs_x, 2.9);
}

TEST(PartitionGenus0, ChosenPointsWorkOnCoarseMeshes) {
  for (const TriMesh& m : {test::cube(), subdivide(test::cube(), 1), sphere(1), test::tetrahedron()}) {
    const PartitionPoints pts = choose_partition_points(m);
    const PartitionResult r = partition_mesh(m, pts.partition_points, pts.auxiliary_points);
    EXPECT_EQ(test::check_partition(m, pts.partition_points, r), "") << m.num_triangles() << " triangles";
    EXPECT_EQ(embedding_problems(r), "");
  }
}

// ----------------------------------------------------------------------------- genus 0, several guides a path

// The vertices of `side` in order; true when `guides` appear in it in that order.
bool passes_in_order(const std::vector<int>& side, const std::vector<int>& guides) {
  auto at = side.begin();
  for (int g : guides) {
    at = std::find(at, side.end(), g);
    if (at == side.end()) return false;
  }
  return true;
}

TEST(PartitionGuided, EveryPathPassesItsGuidesInOrder) {
  const TriMesh m = sphere(4);
  const std::vector<int> p = {nearest_vertex(m, {1, 0, 0}), nearest_vertex(m, {0, 1, 0}),
                              nearest_vertex(m, {-1, 0, 0}), nearest_vertex(m, {0, -1, 0})};
  // Path 0 climbs to the north pole and comes back down beside its way up; path 2 dips south twice.
  const std::vector<std::vector<int>> guides = {
      {nearest_vertex(m, Eigen::Vector3d(0.8, 0.1, 0.6).normalized()), nearest_vertex(m, {0, 0, 1}),
       nearest_vertex(m, Eigen::Vector3d(0.1, 0.8, 0.6).normalized())},
      {},
      {nearest_vertex(m, Eigen::Vector3d(-0.9, -0.2, -0.4).normalized()),
       nearest_vertex(m, Eigen::Vector3d(-0.6, -0.6, 0.1).normalized()),
       nearest_vertex(m, Eigen::Vector3d(-0.2, -0.9, -0.4).normalized())},
      {nearest_vertex(m, Eigen::Vector3d(0.7, -0.7, 0).normalized())}};
  const PartitionResult r = partition_mesh_guided(m, p, guides);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  for (int k = 0; k < 4; ++k) {
    EXPECT_TRUE(passes_in_order(r.patches[0].sides[k].vertices, guides[k])) << "side " << k;
  }
}

TEST(PartitionGuided, OneGuidePerPathIsPartitionMesh) {
  const TriMesh m = sphere(4);
  const std::vector<int> p = {nearest_vertex(m, {1, 0, 0}), nearest_vertex(m, {0, 1, 0}),
                              nearest_vertex(m, {-1, 0, 0}), nearest_vertex(m, {0, -1, 0})};
  const std::vector<int> aux = {nearest_vertex(m, Eigen::Vector3d(0.5, 0.5, 1).normalized()),
                                nearest_vertex(m, {-0.7, 0.7, -0.1}), nearest_vertex(m, {-0.7, -0.7, -0.1}),
                                nearest_vertex(m, {0.7, -0.7, -0.1})};
  const PartitionResult a = partition_mesh(m, p, aux);
  const PartitionResult b = partition_mesh_guided(m, p, {{aux[0]}, {aux[1]}, {aux[2]}, {aux[3]}});
  EXPECT_EQ(a.face_patch, b.face_patch);
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (std::size_t q = 0; q < a.patches.size(); ++q) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(a.patches[q].sides[k].vertices, b.patches[q].sides[k].vertices);
  }
}

TEST(PartitionGuided, BadGuideListsAreRejectedWithAClearMessage) {
  const TriMesh m = sphere(2);
  auto expect = [](const std::function<void()>& call, const std::string& fragment) {
    try {
      call();
      ADD_FAILURE() << "no exception; expected one mentioning '" << fragment << "'";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect([&] { partition_mesh_guided(m, {0, 5, 9, 20}, {{1}, {2}, {3}}); }, "one guide list per path (4), got 3");
  expect([&] { partition_mesh_guided(m, {0, 5, 9, 20}, {{1, 2}, {}, {2}, {}}); }, "must be distinct");
  expect([&] { partition_mesh_guided(m, {0, 5, 9, 20}, {{1}, {}, {9}, {}}); }, "must be distinct");
  expect([&] { partition_mesh_guided(m, {0, 5, 9}, {{}, {}, {}, {}}); }, "expected 4 partition points");
  const TriMesh torus = test::torus(16, 8);
  expect([&] { partition_mesh_guided(torus, {0, 3, 20, 30}, {{}, {}, {}, {}}); }, "genus 0");
}

int highest_vertex(const TriMesh& m) {
  int best = 0;
  for (int v = 1; v < static_cast<int>(m.positions.size()); ++v) {
    if (m.positions[v].z() > m.positions[best].z()) best = v;
  }
  return best;
}

bool on_cut(const PartitionResult& r, int v) {
  for (const auto& side : r.patches[0].sides) {
    if (std::find(side.vertices.begin(), side.vertices.end(), v) != side.vertices.end()) return true;
  }
  return false;
}

TEST(PartitionTipLoop, TheLoopRunsDownASpikeAndSplitsItBetweenThePatches) {
  const TriMesh m = test::spiked_ellipsoid(5, 0.12);
  const int tip = highest_vertex(m);
  // The spike's upper half (z > 2.2 on a body of height 1): which patches hold its triangles.
  auto spike_patches = [&](const PartitionResult& r) {
    std::set<int> patches;
    for (int f = 0; f < static_cast<int>(r.mesh.triangles.size()); ++f) {
      double z = 0.0;
      for (int v : r.mesh.triangles[f]) z += r.mesh.positions[v].z() / 3.0;
      if (z > 2.2) patches.insert(r.face_patch[f]);
    }
    return patches;
  };
  const PartitionPoints plain = choose_partition_points(m);
  const PartitionResult a = partition_mesh(m, plain.partition_points, plain.auxiliary_points);
  EXPECT_FALSE(on_cut(a, tip));
  EXPECT_EQ(spike_patches(a).size(), 1u) << "the plain outline leaves the spike whole inside one patch";

  PartitionPointsOptions options;
  options.tip_loop = true;
  const PartitionPoints pts = choose_partition_points(m, options);
  ASSERT_EQ(pts.side_guides.size(), 4u);
  EXPECT_TRUE(pts.auxiliary_points.empty());
  const PartitionResult b = partition_mesh_guided(m, pts.partition_points, pts.side_guides);
  EXPECT_EQ(test::check_partition(m, pts.partition_points, b), "");
  EXPECT_EQ(embedding_problems(b), "");
  EXPECT_TRUE(on_cut(b, tip));
  EXPECT_EQ(spike_patches(b).size(), 2u) << "the loop splits the spike lengthwise";
  EXPECT_GT(partition_stats(b).area_balance, 0.8);
}

TEST(PartitionTipLoop, ARoundedShapeHasNoTipsAndKeepsThePlainOutline) {
  // The deepest points of the two halves of an ellipsoid are domes, not protrusions.
  TriMesh m = sphere(4);
  for (auto& q : m.positions) q = Eigen::Vector3d(3 * q.x() + 0.2 * q.y(), 2 * q.y(), 0.7 * q.z());
  PartitionPointsOptions options;
  options.tip_loop = true;
  const PartitionPoints tipped = choose_partition_points(m, options);
  const PartitionPoints plain = choose_partition_points(m);
  EXPECT_TRUE(tipped.side_guides.empty());
  EXPECT_EQ(tipped.partition_points, plain.partition_points);
  EXPECT_EQ(tipped.auxiliary_points, plain.auxiliary_points);
}

// The tube test decides what counts as a tip: an ellipsoid's two domes (area half way down about π·depth²)
// are not tips at the default ratio 2 but are at 10; the end loop's settings (4 outline guides, ratio 2.5)
// still route a valid loop over the spike's tip. A ratio that is not a positive number is refused.
TEST(PartitionTipLoop, TheTubeRatioSeparatesTubesFromCaps) {
  TriMesh ellipsoid = sphere(4);
  for (auto& q : ellipsoid.positions) q = Eigen::Vector3d(3 * q.x() + 0.2 * q.y(), 2 * q.y(), 0.7 * q.z());
  PartitionPointsOptions options;
  options.tip_loop = true;
  EXPECT_TRUE(choose_partition_points(ellipsoid, options).side_guides.empty());
  options.tube_ratio = 10;
  EXPECT_FALSE(choose_partition_points(ellipsoid, options).side_guides.empty()) << "domes pass a loose tube test";

  const TriMesh m = test::spiked_ellipsoid(5, 0.12);
  options.tube_ratio = 2.5;
  options.outline_guides = 4;
  const PartitionPoints pts = choose_partition_points(m, options);
  ASSERT_EQ(pts.side_guides.size(), 4u);
  const PartitionResult r = partition_mesh_guided(m, pts.partition_points, pts.side_guides);
  EXPECT_EQ(test::check_partition(m, pts.partition_points, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  EXPECT_TRUE(on_cut(r, highest_vertex(m)));

  for (double bad : {0.0, -1.0, std::nan("")}) {
    options.tube_ratio = bad;
    EXPECT_THROW(choose_partition_points(m, options), InvalidInput) << bad;
  }
}

// ------------------------------------------------------------------------------------------- genus 1

struct TorusSetup {
  TriMesh mesh;
  std::vector<int> p, aux;
};

// Torus grid (i around the big circle, j around the tube) with the corners and auxiliary points on grid
// lines.
TorusSetup torus_setup(int n, int m) {
  TorusSetup t{test::torus(n, m), {}, {}};
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  t.p = {id(0, 0), id(n / 2, 0), id(0, m / 2), id(n / 2, m / 2)};
  t.aux = {id(n / 4, 0), id(3 * n / 4, 0), id(n / 4, m / 2), id(3 * n / 4, m / 2),
           id(0, m / 4), id(0, 3 * m / 4), id(n / 2, m / 4), id(n / 2, 3 * m / 4)};
  return t;
}

// The same grid with the roles of the two directions swapped: mirrored with respect to the header's picture.
TorusSetup mirrored(const TorusSetup& t) {
  TorusSetup u = t;
  u.p = {t.p[0], t.p[2], t.p[1], t.p[3]};
  u.aux = {t.aux[4], t.aux[5], t.aux[6], t.aux[7], t.aux[0], t.aux[1], t.aux[2], t.aux[3]};
  return u;
}

// Checks the documented genus-1 order on a torus grid; returns whether the layout is transposed (mirrored).
bool check_torus_grid(const TorusSetup& t) {
  const PartitionResult r = partition_mesh(t.mesh, t.p, t.aux);
  EXPECT_EQ(test::check_partition(t.mesh, t.p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  if (r.patches.size() != 4u) {
    ADD_FAILURE() << r.patches.size() << " patches";
    return false;
  }
  auto side_between = [](const Patch& patch, int a, int b) -> const std::vector<int>* {
    for (int s = 0; s < 4; ++s) {
      const auto& v = patch.sides[s].vertices;
      if ((v.front() == a && v.back() == b) || (v.front() == b && v.back() == a)) return &v;
    }
    return nullptr;
  };
  auto contains = [](const std::vector<int>* v, int x) {
    return v && std::find(v->begin(), v->end(), x) != v->end();
  };
  for (int index = 0; index < 4; ++index) {
    const Patch& patch = r.patches[index];
    const int a = index / 2, b = index % 2;
    EXPECT_TRUE(contains(side_between(patch, t.p[0], t.p[1]), t.aux[a])) << "patch " << index;
    EXPECT_TRUE(contains(side_between(patch, t.p[0], t.p[2]), t.aux[4 + b])) << "patch " << index;
    EXPECT_TRUE(contains(side_between(patch, t.p[2], t.p[3]), t.aux[2]) ||
                contains(side_between(patch, t.p[2], t.p[3]), t.aux[3]));
    // Corner 0 is the patch's lower-left corner P_{a+2b}; corners P0, P1, P3, P2 in cyclic order.
    const auto& c = patch.corners;
    EXPECT_EQ(c[0], t.p[a + 2 * b]) << "patch " << index;
    EXPECT_EQ(c[2], t.p[3 - (a + 2 * b)]) << "patch " << index;
  }
  // Side 0 is of the same kind (P0-P1/P2-P3 "horizontal" or P0-P2/P1-P3 "vertical") in all patches, so the
  // 4 squares tile a 2x2 periodic grid with translations. Here: sides 0 and 2 of patch 0 vs 1 and 3 of
  // patch 1.
  auto horizontal = [&](const PatchSide& s) {
    const std::set<int> ends = {s.vertices.front(), s.vertices.back()};
    return ends == std::set<int>{t.p[0], t.p[1]} || ends == std::set<int>{t.p[2], t.p[3]};
  };
  for (int index = 0; index < 4; ++index) {
    for (int s = 0; s < 4; ++s) {
      EXPECT_EQ(horizontal(r.patches[index].sides[s]), horizontal(r.patches[0].sides[s % 2]));
    }
  }
  // Translational gluing in the 2x2 grid: the right side (1) of cell (a,b) is the left side (3) of cell
  // (a+1,b), the top (2) of (a,b) the bottom (0) of (a,b+1), periodically; cells are (a,b) or (b,a).
  const bool transposed = !horizontal(r.patches[0].sides[0]);
  for (int index = 0; index < 4; ++index) {
    int x = index / 2, y = index % 2;
    if (transposed) std::swap(x, y);
    auto cell = [&](int cx, int cy) {
      cx = (cx + 2) % 2;
      cy = (cy + 2) % 2;
      return transposed ? 2 * cy + cx : 2 * cx + cy;
    };
    EXPECT_EQ(r.adjacency[4 * index + 1].other_patch, cell(x + 1, y));
    EXPECT_EQ(r.adjacency[4 * index + 1].other_side, 3);
    EXPECT_EQ(r.adjacency[4 * index + 2].other_patch, cell(x, y + 1));
    EXPECT_EQ(r.adjacency[4 * index + 2].other_side, 0);
  }
  // Each corner has the grid diagonal across 2 of its 4 corner triangles: 4 × 2 chords split.
  EXPECT_EQ(r.split_vertices, 8u);
  // Symmetric torus, symmetric grid: equal areas.
  EXPECT_GT(partition_stats(r).area_balance, 0.999);
  return transposed;
}

TEST(PartitionGenus1, TorusGridGivesFourQuadsInTheDocumentedOrder) {
  const TorusSetup t = torus_setup(24, 12);
  const bool transposed = check_torus_grid(t);
  // Mirroring the placement transposes the layout and nothing else.
  EXPECT_NE(check_torus_grid(mirrored(t)), transposed);
}

TEST(PartitionGenus1, CoarseTorusStillValid) {
  const TorusSetup t = torus_setup(8, 8);
  const PartitionResult r = partition_mesh(t.mesh, t.p, t.aux);
  EXPECT_EQ(test::check_partition(t.mesh, t.p, r), "");
  EXPECT_EQ(embedding_problems(r), "");
}

TEST(PartitionGenus1, ContractibleEdgePairIsRejected) {
  TorusSetup t = torus_setup(24, 12);
  // e1 guided next to e0 instead of the other way round the torus: e0 and e1 bound a thin disk (2 sides).
  t.aux[1] = ((24 / 4) % 24) * 12 + 1;
  expect_invalid(t.mesh, t.p, t.aux, "2x2 grid");
}

TEST(PartitionGenus1, ChosenPointsPartitionATorus) {
  const TriMesh m = test::torus(40, 16);
  const PartitionPoints pts = choose_partition_points(m);
  ASSERT_EQ(pts.partition_points.size(), 4u);
  ASSERT_EQ(pts.auxiliary_points.size(), 8u);
  const PartitionResult r = partition_mesh(m, pts.partition_points, pts.auxiliary_points);
  EXPECT_EQ(test::check_partition(m, pts.partition_points, r), "");
  EXPECT_EQ(embedding_problems(r), "");
  EXPECT_GT(partition_stats(r).area_balance, 0.6);
}

// ------------------------------------------------------------------------------------------- bad input

TEST(PartitionErrors, BadPointsAreRejectedWithAClearMessage) {
  const TriMesh m = sphere(2);
  const int nv = static_cast<int>(m.positions.size());
  expect_invalid(m, {0, 1, 2}, {}, "expected 4 partition points, got 3");
  expect_invalid(m, {0, 1, 2, 3, 4}, {}, "expected 4 partition points, got 5");
  expect_invalid(m, {0, 5, 9, 5}, {}, "must be distinct");
  expect_invalid(m, {0, 5, 9, nv}, {}, "out of range");
  expect_invalid(m, {-1, 5, 9, 20}, {}, "out of range");
  expect_invalid(m, {0, 5, 9, 20}, {1, 2, 3}, "0 or 4 auxiliary points");
  expect_invalid(m, {0, 5, 9, 20}, {1, 2, 3, 9}, "must be distinct");
  TriMesh with_unused = m;
  with_unused.positions.emplace_back(5, 5, 5);
  expect_invalid(with_unused, {0, 5, 9, nv}, {}, "not a vertex of any triangle");
}

TEST(PartitionErrors, BadMeshesAreRejectedWithAClearMessage) {
  expect_invalid(test::grid(6), {0, 3, 20, 30}, {}, "not closed");
  const TriMesh two = test::join(sphere(1), sphere(1));
  expect_invalid(two, {0, 3, 20, 30}, {}, "2 connected components");
  TriMesh flipped = sphere(2);
  std::swap(flipped.triangles[5][0], flipped.triangles[5][1]);
  EXPECT_THROW(partition_mesh(flipped, {0, 3, 20, 30}, {}), InvalidInput);
  const TriMesh dt = test::double_torus();
  expect_invalid(dt, {0, 3, 20, 30}, {}, "genus 2");
  EXPECT_THROW(choose_partition_points(dt), InvalidInput);
  const TorusSetup t = torus_setup(16, 8);
  expect_invalid(t.mesh, t.p, {}, "8 auxiliary points");
  std::vector<int> aux = t.aux;
  aux[7] = t.p[2];
  expect_invalid(t.mesh, t.p, aux, "must be distinct");
}

// ------------------------------------------------------------------------------------------- quad layouts

// The cube's 6 faces as quads over its 8 corners (test::cube()'s vertex ids), counter-clockwise from outside.
const std::vector<std::array<int, 4>> kCubeQuads = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                    {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

// test::sphere() keeps the cube's corners as vertices 0..7 (subdivision appends).
QuadLayout cube_layout() {
  return QuadLayout{{0, 1, 2, 3, 4, 5, 6, 7}, kCubeQuads};
}

void expect_invalid_layout(const TriMesh& m, const QuadLayout& layout, const std::string& fragment) {
  test::expect_invalid_input([&] { partition_mesh_layout(m, layout); }, "partition_mesh:", fragment);
}

TEST(PartitionLayout, CubeLayoutOnASphereGivesSixGluedDisks) {
  const TriMesh m = sphere(4);
  const QuadLayout layout = cube_layout();
  const PartitionResult r = partition_mesh_layout(m, layout);
  EXPECT_EQ(test::check_partition(m, layout.corners, r, &layout), "");
  EXPECT_EQ(embedding_problems(r), "");
  // By symmetry every face of the cube gets a sixth of the sphere.
  const PartitionStats stats = partition_stats(r);
  EXPECT_GT(stats.area_balance, 0.95);
}

TEST(PartitionLayout, CornerCyclesAreKeptWhenShortestPathsWouldCross) {
  // Corners moved off the cube's vertices (towards a neighbouring face centre) and a rotated sphere: the
  // paths are no longer mesh lines, and each must leave its corners between the right neighbours.
  TriMesh m = sphere(4);
  const Eigen::Matrix3d rot =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  for (auto& p : m.positions) p = rot * p;
  QuadLayout layout = cube_layout();
  const TriMesh c = test::cube();
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner = c.positions[k] - Eigen::Vector3d::Constant(0.5);
    const Eigen::Vector3d pushed = corner + Eigen::Vector3d(0.25 * (k % 3 == 0 ? 1 : -1), 0.1 * (k % 2), 0.0);
    layout.corners[k] = nearest_vertex(m, rot * pushed.normalized());
  }
  const PartitionResult r = partition_mesh_layout(m, layout);
  EXPECT_EQ(test::check_partition(m, layout.corners, r, &layout), "");
  EXPECT_EQ(embedding_problems(r), "");
}

TEST(PartitionLayout, TorusGridLayoutOfNineQuads) {
  const int n = 24, mm = 12;
  const TriMesh m = test::torus(n, mm);
  auto id = [&](int i, int j) { return ((i + n) % n) * mm + (j + mm) % mm; };
  QuadLayout layout;
  auto corner = [&](int a, int b) { return ((a + 3) % 3) * 3 + (b + 3) % 3; };
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) layout.corners.push_back(id(a * n / 3, b * mm / 3));
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b)
      layout.quads.push_back({corner(a, b), corner(a + 1, b), corner(a + 1, b + 1), corner(a, b + 1)});
  }
  const PartitionResult r = partition_mesh_layout(m, layout);
  EXPECT_EQ(test::check_partition(m, layout.corners, r, &layout), "");
  EXPECT_EQ(embedding_problems(r), "");
}

// A PartitionMeshCache (the mesh checked and connected once, as choose_quad_layout() partitions it many
// times) gives every layout the same partition, bit for bit, and every bad layout the same error.
TEST(PartitionLayout, ACachedMeshGivesTheSamePartitionsAndErrors) {
  TriMesh m = sphere(4);
  const Eigen::Matrix3d rot =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d(3, 1, 2).normalized())).toRotationMatrix();
  for (auto& p : m.positions) p = rot * p;  // paths off the mesh lines: chords to split
  const PartitionMeshCache cache(m);
  EXPECT_EQ(&cache.mesh(), &m);
  QuadLayout moved = cube_layout();
  moved.corners[2] = nearest_vertex(m, rot * Eigen::Vector3d(0.2, 0.9, -0.4).normalized());
  QuadLayout inside_out = cube_layout();
  for (auto& q : inside_out.quads) std::reverse(q.begin(), q.end());
  std::size_t splits = 0;
  for (const QuadLayout& layout : {cube_layout(), moved, inside_out}) {
    const PartitionResult plain = partition_mesh_layout(m, layout);
    const PartitionResult cached = partition_mesh_layout(cache, layout);
    EXPECT_EQ(cached.mesh.positions, plain.mesh.positions);
    EXPECT_EQ(cached.mesh.triangles, plain.mesh.triangles);
    EXPECT_EQ(cached.face_patch, plain.face_patch);
    EXPECT_EQ(cached.split_vertices, plain.split_vertices);
    ASSERT_EQ(cached.adjacency.size(), plain.adjacency.size());
    for (std::size_t i = 0; i < plain.adjacency.size(); ++i) {
      EXPECT_EQ(cached.adjacency[i].other_patch, plain.adjacency[i].other_patch);
      EXPECT_EQ(cached.adjacency[i].other_side, plain.adjacency[i].other_side);
      EXPECT_EQ(cached.adjacency[i].reversed, plain.adjacency[i].reversed);
    }
    EXPECT_EQ(test::check_partition(m, layout.corners, cached, &layout), "");
    splits += cached.split_vertices;
  }
  EXPECT_GT(splits, 0u);  // the cached connectivity went through chord splits too
  QuadLayout open = cube_layout();
  open.quads.pop_back();
  test::expect_invalid_input([&] { partition_mesh_layout(cache, open); }, "partition_mesh:", "not closed");
  QuadLayout bad_vertex = cube_layout();
  bad_vertex.corners[3] = static_cast<int>(m.positions.size());
  test::expect_invalid_input([&] { partition_mesh_layout(cache, bad_vertex); },
                             "partition_mesh:", "out of range");
  // The cache checks the mesh as partition_mesh_layout() does.
  TriMesh open_mesh = m;
  open_mesh.triangles.pop_back();
  test::expect_invalid_input([&] { PartitionMeshCache bad(open_mesh); }, "partition_mesh:", "not closed");
}

TEST(PartitionLayout, BadLayoutsAreRejectedWithOneLine) {
  const TriMesh m = sphere(3);
  QuadLayout open = cube_layout();
  open.quads.pop_back();
  expect_invalid_layout(m, open, "not closed");
  QuadLayout flipped = cube_layout();
  std::reverse(flipped.quads[2].begin(), flipped.quads[2].end());
  expect_invalid_layout(m, flipped, "same way by two quads");
  QuadLayout repeated = cube_layout();
  repeated.quads[0][1] = repeated.quads[0][0];
  expect_invalid_layout(m, repeated, "repeats corner");
  QuadLayout out_of_range = cube_layout();
  out_of_range.quads[0][0] = 8;
  expect_invalid_layout(m, out_of_range, "outside [0,8)");
  QuadLayout bad_vertex = cube_layout();
  bad_vertex.corners[3] = static_cast<int>(m.positions.size());
  expect_invalid_layout(m, bad_vertex, "out of range");
  // Inside out (the mirror image): still a cube layout of the sphere, with every corner's cyclic order
  // reversed; the paths must wind around the corners, and the result is a valid partition.
  QuadLayout inside_out = cube_layout();
  for (auto& q : inside_out.quads) std::reverse(q.begin(), q.end());
  const PartitionResult mirrored = partition_mesh_layout(m, inside_out);
  EXPECT_EQ(test::check_partition(m, inside_out.corners, mirrored, &inside_out), "");
  // A sphere's layout on a torus: wrong Euler characteristic.
  const TriMesh t = test::torus(16, 8);
  expect_invalid_layout(t, cube_layout(), "Euler characteristic 2");
  EXPECT_EQ(check_quad_layout(cube_layout(), 8, 0), "");
  // Two-quad corners: the 2-patch loop as a layout is fine (quads 0 and 1); a pillow in quads 1 and 3 is not
  // (both odd: their remesh corner cells would share a diagonal).
  EXPECT_EQ(check_quad_layout(QuadLayout{{0, 1, 2, 3}, {{0, 1, 2, 3}, {0, 3, 2, 1}}}, 4, 0), "");
  const QuadLayout odd_pillow{{0, 1, 2, 3, 4, 5, 6, 7}, {{4, 5, 6, 7}, {0, 1, 2, 3}, {4, 7, 6, 5}, {0, 3, 2, 1}}};
  EXPECT_NE(check_quad_layout(odd_pillow, 8, 0).find("both odd-numbered"), std::string::npos);
}

}  // namespace
}  // namespace geomip
