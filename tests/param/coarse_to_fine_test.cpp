#include "param/coarse_to_fine.h"

#include "mesh/errors.h"
#include "param/mean_value_embedding.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/progressive_mesh.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>

namespace geomip {
namespace {

std::array<int, 4> grid_corners(int n) {
  return {0, n, (n + 1) * (n + 1) - 1, n * (n + 1)};
}

/// Jittered grid lifted onto a saddle with a narrow bump: a strongly curved disk.
TriMesh curved(int n, unsigned seed = 5) {
  TriMesh m = test::grid(n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3 / n, 0.3 / n);
  for (int j = 1; j < n; ++j) {
    for (int i = 1; i < n; ++i) m.positions[j * (n + 1) + i] += Eigen::Vector3d(jitter(rng), jitter(rng), 0);
  }
  for (auto& p : m.positions) {
    const double r2 = (p.x() - 0.3) * (p.x() - 0.3) + (p.y() - 0.6) * (p.y() - 0.6);
    p.z() = 0.8 * (p.x() - 0.5) * (p.y() - 0.5) + 0.5 * std::exp(-r2 / 0.01);
  }
  return m;
}

struct Pipeline {
  TriMesh patch;
  PatchSides sides;
  std::vector<int> features;
  ProgressiveMesh pm;
  std::vector<Eigen::Vector2d> base_uv;
};

Pipeline make_pipeline(TriMesh patch, const PatchSides& sides, std::vector<int> features) {
  Pipeline p;
  p.patch = std::move(patch);
  p.sides = sides;
  p.features = std::move(features);
  p.pm = progressive_mesh(p.patch, p.sides, p.features);
  p.base_uv = mean_value_embedding(p.patch.positions, p.pm.base_triangles,
                                   square_boundary_uv(p.patch.positions, p.sides))
                  .uv;
  return p;
}

Pipeline curved_pipeline(int n) {
  TriMesh m = curved(n);
  const PatchSides sides = patch_sides(m, grid_corners(n));
  return make_pipeline(std::move(m), sides, {(n / 2) * (n + 1) + n / 2, (n / 3) * (n + 1) + 2 * n / 3});
}

/// The properties every final parameterization must have.
void expect_valid_square_parameterization(const Pipeline& p, const CoarseToFineResult& r) {
  ASSERT_EQ(r.uv.size(), p.patch.num_vertices());
  EXPECT_EQ(r.triangles, p.patch.triangles);
  EXPECT_EQ(count_flipped_triangles(r.uv, r.triangles), 0u);
  EXPECT_GT(r.min_area2, 0.0);
  for (const auto& q : r.uv) {
    ASSERT_TRUE(q.allFinite());
    EXPECT_GE(q.minCoeff(), 0.0);
    EXPECT_LE(q.maxCoeff(), 1.0);
  }
  const Eigen::Vector2d corner[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<char> boundary(p.patch.num_vertices(), 0);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(r.uv[p.sides[k].front()], corner[k]) << "corner " << k;
    const Eigen::Vector2d dir = corner[(k + 1) % 4] - corner[k];
    double previous = 0.0;
    for (std::size_t i = 1; i < p.sides[k].size(); ++i) {
      const int v = p.sides[k][i];
      boundary[v] = 1;
      const Eigen::Vector2d d = r.uv[v] - corner[k];
      EXPECT_EQ(d.x() * dir.y() - d.y() * dir.x(), 0.0) << "vertex " << v << " off side " << k;
      const double along = d.dot(dir);
      EXPECT_GT(along, previous) << "side " << k << " not monotone at vertex " << v;
      previous = along;
    }
  }
  for (std::size_t v = 0; v < r.uv.size(); ++v) {
    if (boundary[v]) continue;
    EXPECT_GT(r.uv[v].minCoeff(), 0.0) << v;
    EXPECT_LT(r.uv[v].maxCoeff(), 1.0) << v;
  }
  for (int f : p.features) EXPECT_EQ(r.uv[f], p.base_uv[f]) << "feature " << f << " moved";
}

TEST(CoarseToFine, NoFlipAtAnyLevelOnACurvedPatch) {
  const Pipeline p = curved_pipeline(24);
  CoarseToFineOptions options;
  options.check_all_triangles = true;  // the class's own O(F) check after each split
  CoarseToFine c2f(p.patch, p.pm, p.base_uv, options);
  ASSERT_EQ(c2f.num_splits(), p.pm.collapses.size());
  ASSERT_GT(c2f.num_splits(), 400u);
  std::size_t alive = p.pm.base_triangles.size(), calls = 0;
  const VertexOptimizer no_op = [&](int, const std::vector<int>&) { ++calls; };
  while (!c2f.finished()) {
    const int v = c2f.split_next(no_op);
    ASSERT_GE(v, 0);
    // Independent check of the whole level: every existing triangle counter-clockwise with positive area.
    std::size_t count = 0;
    for (const auto& t : c2f.current_triangles()) {
      if (t[0] < 0) continue;
      ++count;
      ASSERT_GT(signed_uv_area2(c2f.uv(), t), 0.0) << "after split " << c2f.splits_done();
    }
    const auto& c = p.pm.collapses[p.pm.collapses.size() - c2f.splits_done()];
    alive += (c.left_triangle >= 0) + (c.right_triangle >= 0);
    ASSERT_EQ(count, alive);
  }
  EXPECT_EQ(c2f.split_next(no_op), -1);
  EXPECT_GT(calls, 3 * c2f.num_splits());  // the new vertex and its free neighbours, each split
  const CoarseToFineResult r = c2f.result();
  expect_valid_square_parameterization(p, r);
}

TEST(CoarseToFine, ValidOnManyCurvedPatches) {
  // Several jitters of the saddle-with-bump, and a grid pushed onto a sphere cap (about 140° wide), with
  // features scattered over the interior.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const int n = 18 + static_cast<int>(seed) * 3;
    TriMesh m = curved(n, seed);
    if (seed % 2 == 0) {
      for (auto& q : m.positions) q = Eigen::Vector3d(q.x() - 0.5, q.y() - 0.5, 0.18).normalized();
    }
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> interior(1, n - 1);
    std::set<int> features;
    for (int i = 0; i < 5; ++i) features.insert(interior(rng) * (n + 1) + interior(rng));
    const PatchSides sides = patch_sides(m, grid_corners(n));
    const Pipeline p = make_pipeline(std::move(m), sides, {features.begin(), features.end()});
    SCOPED_TRACE("seed " + std::to_string(seed));
    expect_valid_square_parameterization(p, coarse_to_fine(p.patch, p.pm, p.base_uv));
  }
}

TEST(CoarseToFine, FreeFunctionMatchesTheClassAndIsDeterministic) {
  const Pipeline p = curved_pipeline(20);
  const CoarseToFineResult a = coarse_to_fine(p.patch, p.pm, p.base_uv);
  const CoarseToFineResult b = coarse_to_fine(p.patch, p.pm, p.base_uv);
  expect_valid_square_parameterization(p, a);
  EXPECT_EQ(a.uv, b.uv);
}

TEST(CoarseToFine, BoundaryVerticesGoToTheirChordLengthPosition) {
  // On the flat grid the base embedding is exact, every level is planar, and chord length along a side is the
  // true coordinate: boundary vertices must land exactly where they are in the plane.
  const int n = 16;
  TriMesh g = test::grid(n);
  const PatchSides sides = patch_sides(g, grid_corners(n));
  const Pipeline p = make_pipeline(std::move(g), sides, {});
  const CoarseToFineResult r = coarse_to_fine(p.patch, p.pm, p.base_uv);
  expect_valid_square_parameterization(p, r);
  // Interior vertices go to kernel centroids, not to their planar positions, so a chord-length position can
  // occasionally flip a triangle; those (counted) boundary vertices go elsewhere between their neighbours.
  std::size_t off = 0, boundary = 0;
  for (int k = 0; k < 4; ++k) {
    for (int v : p.sides[k]) {
      ++boundary;
      off += (r.uv[v] - p.patch.positions[v].head<2>()).norm() > 1e-12 ? 1 : 0;
    }
  }
  EXPECT_EQ(off, r.boundary_off_chord);
  EXPECT_LE(off, boundary / 10);
}

// With side metrics the boundary vertices go to their chord-length positions in the metric, where
// square_boundary_uv() with the same tensors puts them (the base mesh's and the full patch's sides agree).
TEST(CoarseToFine, BoundaryVerticesFollowTheSideMetric) {
  const int n = 16;
  TriMesh g = test::grid(n);
  const PatchSides sides = patch_sides(g, grid_corners(n));
  std::vector<Eigen::Matrix3d> metrics;
  for (const auto& q : g.positions) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    m(0, 0) = 1 + 8 * q.x() * q.x();  // x grows longer to the right
    metrics.push_back(m);
  }
  Pipeline p;
  p.patch = std::move(g);
  p.sides = sides;
  p.pm = progressive_mesh(p.patch, p.sides, {});
  const auto target = square_boundary_uv(p.patch.positions, p.sides, &metrics);
  p.base_uv = mean_value_embedding(p.patch.positions, p.pm.base_triangles, target).uv;
  CoarseToFineOptions options;
  options.side_metrics = &metrics;
  const CoarseToFineResult r = coarse_to_fine(p.patch, p.pm, p.base_uv, options);
  expect_valid_square_parameterization(p, r);
  std::size_t off = 0, moved = 0;
  for (const auto& [v, uv] : target) {
    off += (r.uv[v] - uv).norm() > 1e-12 ? 1 : 0;
    moved += (uv - p.patch.positions[v].head<2>()).norm() > 1e-3 ? 1 : 0;
  }
  EXPECT_EQ(off, r.boundary_off_chord);
  EXPECT_LE(off, target.size() / 10);
  EXPECT_GT(moved, target.size() / 4) << "the metric moved the side vertices off their Euclidean places";
  std::vector<Eigen::Matrix3d> short_metrics(3, Eigen::Matrix3d::Identity());
  options.side_metrics = &short_metrics;
  EXPECT_THROW(CoarseToFine(p.patch, p.pm, p.base_uv, options), InvalidInput);
}

TEST(CoarseToFine, OptimizerSeesNewVertexAndNeighboursButNeverCornersOrFeatures) {
  const Pipeline p = curved_pipeline(20);
  CoarseToFine c2f(p.patch, p.pm, p.base_uv);
  std::set<int> locked(p.features.begin(), p.features.end());
  for (int k = 0; k < 4; ++k) locked.insert(p.sides[k].front());
  std::size_t calls = 0, moved = 0;
  int expected_first = -1;
  bool first_of_split = false;
  // A simple optimizer: move an interior vertex halfway to the average of its neighbours when that keeps its
  // triangles counter-clockwise (it may move only the vertex it is called on).
  auto optimize = [&](int v, const std::vector<int>& ring) {
    ++calls;
    if (first_of_split) {
      EXPECT_EQ(v, expected_first);
      first_of_split = false;
    }
    EXPECT_FALSE(locked.count(v)) << "optimizer called on locked vertex " << v;
    ASSERT_FALSE(ring.empty());
    Eigen::Vector2d sum(0, 0);
    int count = 0;
    bool boundary = false;
    for (int id : ring) {
      const auto& t = c2f.triangle(id);
      ASSERT_NE(std::find(t.begin(), t.end(), v), t.end()) << "ring triangle without the vertex";
      for (int w : t) {
        if (w != v) sum += c2f.uv()[w], ++count;
      }
    }
    for (const auto& s : p.sides) boundary |= std::find(s.begin(), s.end(), v) != s.end();
    if (boundary) return;
    const Eigen::Vector2d old = c2f.uv()[v];
    c2f.uv()[v] = 0.5 * (old + sum / count);
    for (int id : ring) {
      if (!(signed_uv_area2(c2f.uv(), c2f.triangle(id)) > 0)) {
        c2f.uv()[v] = old;
        return;
      }
    }
    ++moved;
  };
  const std::size_t nsplits = c2f.num_splits();
  for (std::size_t i = 0; i < nsplits; ++i) {
    expected_first = p.pm.collapses[nsplits - 1 - i].removed;
    first_of_split = true;
    c2f.split_next(optimize);
  }
  EXPECT_GT(calls, 3 * nsplits);
  EXPECT_GT(moved, nsplits);
  expect_valid_square_parameterization(p, c2f.result());
}

TEST(CoarseToFine, AnOptimizerThatFlipsATriangleIsCaught) {
  const Pipeline p = curved_pipeline(12);
  CoarseToFine c2f(p.patch, p.pm, p.base_uv);
  auto evil = [&](int v, const std::vector<int>& ring) {
    // Reflect the vertex through the first opposite edge of its ring: that triangle flips.
    const auto& t = c2f.triangle(ring.front());
    const int i = static_cast<int>(std::find(t.begin(), t.end(), v) - t.begin());
    const Eigen::Vector2d a = c2f.uv()[t[(i + 1) % 3]], b = c2f.uv()[t[(i + 2) % 3]];
    const Eigen::Vector2d d = (b - a).normalized();
    const Eigen::Vector2d q = c2f.uv()[v] - a;
    c2f.uv()[v] = a + 2 * q.dot(d) * d - q;
  };
  EXPECT_THROW(c2f.refine_all(evil), SolverFailure);
}

TEST(CoarseToFine, RejectsABaseEmbeddingThatDoesNotFit) {
  const Pipeline p = curved_pipeline(12);
  std::vector<Eigen::Vector2d> bad = p.base_uv;
  std::swap(bad[p.sides[0].front()], bad[p.sides[1].front()]);  // corners swapped: triangles flip
  EXPECT_THROW(CoarseToFine(p.patch, p.pm, bad), InvalidInput);
  EXPECT_THROW(CoarseToFine(p.patch, p.pm, std::vector<Eigen::Vector2d>(3)), InvalidInput);
  CoarseToFine c2f(p.patch, p.pm, p.base_uv);
  EXPECT_THROW(c2f.result(), InvalidInput);  // not finished
}

// ---- real meshes
// ----------------------------------------------------------------------------------------------

/// Faces of `mesh` whose centroid lies below (`lower`) or above the median along `axis`, cleaned into a disk:
/// the largest edge-connected piece, without triangles whose three corners are all on the boundary (ears of
/// the cut), repeated until stable.
TriMesh half_disk(const TriMesh& mesh, int axis, bool lower) {
  std::vector<double> xs;
  for (const auto& t : mesh.triangles) {
    xs.push_back((mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]])[axis] / 3);
  }
  std::vector<double> sorted = xs;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double cut = sorted[sorted.size() / 2];
  std::vector<std::array<int, 3>> tris;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    if ((xs[i] < cut) == lower) tris.push_back(mesh.triangles[i]);
  }
  for (int round = 0; round < 100; ++round) {
    // Largest edge-connected component (union-find over shared edges).
    std::vector<int> parent(tris.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::function<int(int)> find = [&](int x) { return parent[x] == x ? x : parent[x] = find(parent[x]); };
    std::map<std::pair<int, int>, std::vector<int>> edge_faces;
    for (std::size_t f = 0; f < tris.size(); ++f) {
      for (int i = 0; i < 3; ++i) {
        const int a = tris[f][i], b = tris[f][(i + 1) % 3];
        edge_faces[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(f));
      }
    }
    std::set<int> boundary;
    for (const auto& [e, fs] : edge_faces) {
      for (std::size_t i = 1; i < fs.size(); ++i) parent[find(fs[i])] = find(fs[0]);
      if (fs.size() == 1) boundary.insert(e.first), boundary.insert(e.second);
    }
    std::map<int, int> size;
    for (std::size_t f = 0; f < tris.size(); ++f) ++size[find(static_cast<int>(f))];
    int best = -1;
    for (const auto& [root, s] : size) {
      if (best < 0 || s > size[best]) best = root;
    }
    std::vector<std::array<int, 3>> kept;
    bool changed = false;
    for (std::size_t f = 0; f < tris.size(); ++f) {
      const auto& t = tris[f];
      const bool ear = boundary.count(t[0]) && boundary.count(t[1]) && boundary.count(t[2]);
      if (find(static_cast<int>(f)) == best && !ear) {
        kept.push_back(t);
      } else {
        changed = true;
      }
    }
    tris.swap(kept);
    if (!changed) break;
  }
  // Compact the vertex ids.
  TriMesh half;
  std::map<int, int> id;
  for (auto& t : tris) {
    for (int& v : t) {
      auto [it, inserted] = id.emplace(v, static_cast<int>(half.positions.size()));
      if (inserted) half.positions.push_back(mesh.positions[v]);
      v = it->second;
    }
  }
  half.triangles = tris;
  return half;
}

/// Four corners evenly spaced (by edge count) along the boundary loop, starting `offset` vertices in.
std::array<int, 4> loop_corners(const TriMesh& patch, std::size_t offset) {
  std::set<std::pair<int, int>> directed;
  for (const auto& t : patch.triangles) {
    for (int i = 0; i < 3; ++i) directed.insert({t[i], t[(i + 1) % 3]});
  }
  std::map<int, int> next;
  for (const auto& [a, b] : directed) {
    if (!directed.count({b, a})) next[a] = b;
  }
  std::vector<int> loop = {next.begin()->first};
  while (next.at(loop.back()) != loop.front()) loop.push_back(next.at(loop.back()));
  std::array<int, 4> corners{};
  for (int k = 0; k < 4; ++k) corners[k] = loop[(offset + k * loop.size() / 4) % loop.size()];
  return corners;
}

/// Runs PM + MVC + coarse-to-fine on `half` (a disk) and checks every property; returns the seconds spent.
double run_real_half(const TriMesh& half, const std::string& name) {
  const TopologyReport topo = analyze_topology(half);
  EXPECT_TRUE(topo.manifold && topo.components == 1 && topo.boundary_loops == 1 && topo.genus == 0)
      << name << ": the half is not a disk";
  // Corners placed so that no interior edge joins two vertices of one side (progressive_mesh() checks it).
  for (std::size_t offset = 0; offset < 16; ++offset) {
    PatchSides sides = patch_sides(half, loop_corners(half, offset));
    using Clock = std::chrono::steady_clock;
    auto seconds_since = [](Clock::time_point t) {
      return std::chrono::duration<double>(Clock::now() - t).count();
    };
    const auto start = Clock::now();
    Pipeline p;
    p.patch = half;
    p.sides = sides;
    try {
      p.pm = progressive_mesh(p.patch, p.sides, {});
    } catch (const InvalidInput&) {
      continue;  // a chord between two vertices of one side: try the next placement
    }
    const double pm_seconds = seconds_since(start);
    const auto mvc_start = Clock::now();
    p.base_uv = mean_value_embedding(p.patch.positions, p.pm.base_triangles,
                                     square_boundary_uv(p.patch.positions, sides))
                    .uv;
    const double mvc_seconds = seconds_since(mvc_start);
    const auto c2f_start = Clock::now();
    const CoarseToFineResult r = coarse_to_fine(p.patch, p.pm, p.base_uv);
    const double c2f_seconds = seconds_since(c2f_start);
    const double seconds = seconds_since(start);
    expect_valid_square_parameterization(p, r);
    // The progressive mesh of a real patch: corners survive, the base mesh is a disk.
    const TopologyReport base = analyze_topology(TriMesh{p.patch.positions, p.pm.base_triangles});
    EXPECT_TRUE(base.manifold && base.components == 1 && base.boundary_loops == 1 && base.genus == 0);
    EXPECT_EQ(base.vertices, p.pm.base_vertices.size());
    for (int k = 0; k < 4; ++k) {
      EXPECT_TRUE(std::binary_search(p.pm.base_vertices.begin(), p.pm.base_vertices.end(), sides[k].front()));
    }
    // Floater's theorem on real data: mean value coordinates of the full patch are an embedding too.
    const auto full_start = Clock::now();
    const auto full = mean_value_embedding(p.patch.positions, p.patch.triangles,
                                           square_boundary_uv(p.patch.positions, sides));
    const double full_seconds = seconds_since(full_start);
    EXPECT_EQ(count_flipped_triangles(full.uv, p.patch.triangles), 0u);
    EXPECT_LT(full.residual, 1e-9);
    std::printf(
        "%s: %zu vertices, %zu triangles, base %zu vertices, %zu boundary vertices off chord; "
        "PM %.3f s + MVC %.3f s + coarse-to-fine %.3f s = %.3f s (MVC of the full patch: %.3f s)\n",
        name.c_str(), half.num_vertices(), half.num_triangles(), p.pm.base_vertices.size(),
        r.boundary_off_chord, pm_seconds, mvc_seconds, c2f_seconds, seconds, full_seconds);
    return seconds;
  }
  ADD_FAILURE() << name << ": no corner placement without a one-side chord";
  return 0;
}

TEST(CoarseToFineReal, SpotHalves) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "spot.obj");
  const TriMesh spot = read_mesh(path);
  for (bool lower : {true, false}) {
    const TriMesh half = half_disk(spot, 0, lower);
    EXPECT_GE(half.num_triangles(), 2500u);
    run_real_half(half, lower ? "spot, lower half" : "spot, upper half");
  }
}

TEST(CoarseToFineReal, BunnyHalves) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "bunny.obj");
  const TriMesh bunny = repair_mesh(read_mesh(path)).mesh;  // holes filled: two disks of ~35k triangles
  // The first axis whose median plane cuts the bunny into two disks (a plane through an ear leaves a ring).
  auto is_disk = [](const TriMesh& m) {
    const TopologyReport t = analyze_topology(m);
    return t.manifold && t.components == 1 && t.boundary_loops == 1 && t.genus == 0;
  };
  int axis = 0;
  while (axis < 3 && !(is_disk(half_disk(bunny, axis, true)) && is_disk(half_disk(bunny, axis, false))))
    ++axis;
  ASSERT_LT(axis, 3) << "no median plane cuts the bunny into two disks";
  double seconds = 0;
  for (bool lower : {true, false}) {
    const TriMesh half = half_disk(bunny, axis, lower);
    EXPECT_GE(half.num_triangles(), 30000u);
    seconds += run_real_half(
        half, std::string("bunny, axis ") + "xyz"[axis] + (lower ? " lower half" : " upper half"));
  }
  // Speed is a benchmark (tests/bench/param_bench), not a test: a loaded machine must not fail the suite.
  std::printf("bunny halves: %.3f s (PM + MVC + insertion for both)\n", seconds);
}

}  // namespace
}  // namespace geomip
