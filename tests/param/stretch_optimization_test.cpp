// Properties of the stretch optimization (paper §3.3.2, Sander et al. 2001): it recovers the isometry of a
// flat grid from a distorted embedding, lowers stretch monotonically on curved surfaces, never flips a
// triangle and never moves a locked vertex.
#include "param/stretch_optimization.h"
#include "mesh/errors.h"
#include "param/stretch.h"
#include "tests/param/test_meshes.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>

namespace geomip {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<Eigen::Vector2d> xy(const TriMesh& m) {
  std::vector<Eigen::Vector2d> uv;
  for (const auto& p : m.positions) uv.emplace_back(p.x(), p.y());
  return uv;
}

/// Interior pushed toward the corner (0,0): p − α·16x(1−x)y(1−y)·p. Boundary points are fixed exactly.
std::vector<Eigen::Vector2d> pushed_to_corner(const std::vector<Eigen::Vector2d>& uv, double alpha) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : uv) {
    const double bump = 16 * p.x() * (1 - p.x()) * p.y() * (1 - p.y());
    out.push_back(p - alpha * bump * p);
  }
  return out;
}

/// The grid lifted onto a paraboloid cap z = a·((x−½)² + (y−½)²): curved, its xy projection is the unit
/// square.
TriMesh paraboloid(int n, double a) {
  TriMesh m = test::grid(n);
  for (auto& p : m.positions) p.z() = a * ((p.x() - 0.5) * (p.x() - 0.5) + (p.y() - 0.5) * (p.y() - 0.5));
  return m;
}

std::vector<std::vector<int>> vertex_rings(const TriMesh& m) {
  std::vector<std::vector<int>> rings(m.positions.size());
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    for (int v : m.triangles[f]) rings[v].push_back(static_cast<int>(f));
  }
  return rings;
}

bool bit_identical(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 2) == 0;
}

TEST(BoundaryVertexMask, GridHasItsSquareBoundary) {
  const TriMesh g = test::grid(5);
  const std::vector<char> mask = boundary_vertex_mask(g.positions.size(), g.triangles);
  for (std::size_t v = 0; v < g.positions.size(); ++v) {
    const auto& p = g.positions[v];
    const bool on_square = p.x() == 0 || p.x() == 1 || p.y() == 0 || p.y() == 1;
    EXPECT_EQ(mask[v] != 0, on_square) << v;
  }
  const std::vector<char> closed = boundary_vertex_mask(4, test::tetrahedron().triangles);
  EXPECT_TRUE(std::all_of(closed.begin(), closed.end(), [](char c) { return c == 0; }));
}

// A distorted embedding of a flat grid with its boundary fixed on the unit square: the optimum is the
// identity (stretch 1), and the optimization must get close to it.
TEST(OptimizeStretch, FlatGridRecoversIsometry) {
  const TriMesh g = test::grid(12);
  std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(g), 0.6);
  ASSERT_EQ(count_flipped(g.triangles, uv), 0u);
  const std::vector<char> locked = boundary_vertex_mask(g.positions.size(), g.triangles);
  const std::vector<Eigen::Vector2d> start = uv;

  StretchOptimizationOptions options;
  options.threshold = 1e-7;
  options.max_sweeps = 500;
  options.record_sweeps = true;
  const StretchOptimizationResult r = optimize_stretch(g.positions, g.triangles, uv, locked, options);

  std::cout << "flat grid 12x12: L2 " << r.before.l2 << " -> " << r.after.l2 << ", Linf " << r.before.linf
            << " -> " << r.after.linf << " in " << r.sweeps << " sweeps, " << r.vertex_moves << " moves\n";
  EXPECT_GT(r.before.l2, 1.1);
  EXPECT_LT(r.after.l2, 1.002);
  EXPECT_LT(r.after.l2 - 1, 0.05 * (r.before.l2 - 1));
  EXPECT_EQ(count_flipped(g.triangles, uv), 0u);
  const StretchValues check = mesh_stretch(g.positions, g.triangles, uv);
  EXPECT_EQ(check.l2, r.after.l2);
  double max_error = 0;
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (locked[v]) {
      EXPECT_TRUE(bit_identical(uv[v], start[v])) << v;
    }
    max_error = std::max(max_error, (uv[v] - xy(g)[v]).norm());
  }
  EXPECT_LT(max_error, 0.01);  // vertices back near their own (x, y); the edge length is 1/12
  ASSERT_EQ(r.per_sweep.size(), r.sweeps);
  for (std::size_t s = 1; s < r.per_sweep.size(); ++s) {
    EXPECT_LE(r.per_sweep[s].l2, r.per_sweep[s - 1].l2 * (1 + 1e-12)) << s;
  }
}

// On a curved cap the optimum is not 1, but every sweep must lower (never raise) the normalized L2 stretch,
// since the boundary is fixed and each move lowers its ring's area-weighted L2 energy.
TEST(OptimizeStretch, CurvedCapDecreasesMonotonically) {
  const TriMesh m = paraboloid(16, 2.0);
  for (double alpha : {0.0, 0.6}) {
    std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(m), alpha);
    ASSERT_EQ(count_flipped(m.triangles, uv), 0u);
    const std::vector<char> locked = boundary_vertex_mask(m.positions.size(), m.triangles);
    const std::vector<Eigen::Vector2d> start = uv;
    StretchOptimizationOptions options;
    options.threshold = 1e-6;
    options.max_sweeps = 300;
    options.record_sweeps = true;
    const StretchOptimizationResult r = optimize_stretch(m.positions, m.triangles, uv, locked, options);
    std::cout << "paraboloid cap 16x16 (push " << alpha << "): L2 " << r.before.l2 << " -> " << r.after.l2
              << ", Linf " << r.before.linf << " -> " << r.after.linf << " in " << r.sweeps << " sweeps\n";
    EXPECT_LT(r.after.l2, r.before.l2 - 0.01);
    EXPECT_GT(r.after.l2, 1.0);
    EXPECT_EQ(count_flipped(m.triangles, uv), 0u);
    double previous = r.before.l2;
    for (const StretchValues& s : r.per_sweep) {
      EXPECT_LE(s.l2, previous * (1 + 1e-12));
      previous = s.l2;
    }
    for (std::size_t v = 0; v < uv.size(); ++v) {
      if (locked[v]) {
        EXPECT_TRUE(bit_identical(uv[v], start[v])) << v;
      }
    }
  }
}

// L∞ mode: each move lowers its ring's max Γ, so the mesh's max Γ (with a fixed boundary) never increases.
TEST(OptimizeStretch, LinfModeLowersMaxStretch) {
  const TriMesh m = paraboloid(10, 1.5);
  std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(m), 0.6);
  const std::vector<char> locked = boundary_vertex_mask(m.positions.size(), m.triangles);
  StretchOptimizationOptions options;
  options.vertex.norm = StretchNorm::kLinf;
  options.vertex.num_directions = 4;
  options.threshold = 1e-6;
  options.max_sweeps = 200;
  options.record_sweeps = true;
  const StretchOptimizationResult r = optimize_stretch(m.positions, m.triangles, uv, locked, options);
  std::cout << "paraboloid cap 10x10, Linf mode: Linf " << r.before.linf << " -> " << r.after.linf << "\n";
  EXPECT_LT(r.after.linf, r.before.linf - 0.05);
  EXPECT_EQ(count_flipped(m.triangles, uv), 0u);
  double previous = r.before.linf;
  for (const StretchValues& s : r.per_sweep) {
    EXPECT_LE(s.linf, previous * (1 + 1e-12));
    previous = s.linf;
  }
}

// min_local_stretch: a sweep leaves the vertices whose local stretch is below it where they are; above the
// largest local stretch nothing moves at all; in L∞ mode the mesh's max never rises.
TEST(OptimizeStretch, MinLocalStretchLeavesLowVerticesAlone) {
  const TriMesh m = paraboloid(10, 1.5);
  const std::vector<Eigen::Vector2d> start = pushed_to_corner(xy(m), 0.6);
  const std::vector<char> locked = boundary_vertex_mask(m.positions.size(), m.triangles);
  const auto rings = vertex_rings(m);
  StretchOptimizationOptions options;
  options.vertex.norm = StretchNorm::kLinf;
  std::vector<double> local(m.positions.size(), 0);
  double largest = 0;
  for (std::size_t v = 0; v < local.size(); ++v) {
    if (locked[v]) continue;
    local[v] = local_stretch(static_cast<int>(v), rings[v], m.positions, m.triangles, start, options.vertex);
    largest = std::max(largest, local[v]);
  }
  std::vector<double> sorted = local;
  std::sort(sorted.begin(), sorted.end());
  options.min_local_stretch = sorted[sorted.size() / 2];  // about half the vertices below
  options.max_sweeps = 1;
  std::vector<Eigen::Vector2d> uv = start;
  const StretchOptimizationResult r = optimize_stretch(m.positions, m.triangles, uv, locked, options);
  EXPECT_GT(r.vertex_moves, 0u);
  EXPECT_LE(r.after.linf, r.before.linf);
  EXPECT_EQ(count_flipped(m.triangles, uv), 0u);
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (locked[v] || local[v] < options.min_local_stretch) {
      EXPECT_TRUE(bit_identical(uv[v], start[v])) << v;
    }
  }
  options.min_local_stretch = 2 * largest;
  options.max_sweeps = 20;
  uv = start;
  EXPECT_EQ(optimize_stretch(m.positions, m.triangles, uv, locked, options).vertex_moves, 0u);
  for (std::size_t v = 0; v < uv.size(); ++v) EXPECT_TRUE(bit_identical(uv[v], start[v])) << v;
  options.min_local_stretch = -1;
  EXPECT_THROW(optimize_stretch(m.positions, m.triangles, uv, locked, options), InvalidInput);
}

TEST(OptimizeStretch, LockedInteriorVerticesStayAndResultIsDeterministic) {
  const TriMesh m = paraboloid(8, 1.0);
  const std::vector<Eigen::Vector2d> start = pushed_to_corner(xy(m), 0.5);
  std::vector<char> locked = boundary_vertex_mask(m.positions.size(), m.triangles);
  for (int v : {20, 40, 41}) locked[v] = 1;  // "feature points"
  StretchOptimizationOptions options;
  options.seed = 42;
  std::vector<Eigen::Vector2d> a = start, b = start;
  const StretchOptimizationResult ra = optimize_stretch(m.positions, m.triangles, a, locked, options);
  optimize_stretch(m.positions, m.triangles, b, locked, options);
  EXPECT_GT(ra.vertex_moves, 0u);
  EXPECT_LT(ra.after.l2, ra.before.l2);
  for (std::size_t v = 0; v < a.size(); ++v) {
    EXPECT_TRUE(bit_identical(a[v], b[v])) << v;
    if (locked[v]) {
      EXPECT_TRUE(bit_identical(a[v], start[v])) << v;
    }
  }
  options.seed = 43;
  std::vector<Eigen::Vector2d> c = start;
  optimize_stretch(m.positions, m.triangles, c, locked, options);
  EXPECT_FALSE(std::equal(a.begin(), a.end(), c.begin(), bit_identical));
}

// A flipped triangle in the input: its vertices are skipped, nothing new flips, the rest is still optimized.
TEST(OptimizeStretch, LeavesExistingFlipsAloneAndAddsNone) {
  const TriMesh g = test::grid(6);
  std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(g), 0.5);
  uv[8] = Eigen::Vector2d(0.45, 0.45);  // interior vertex (1,1)/6 pushed across its ring
  const std::size_t flipped_before = count_flipped(g.triangles, uv);
  ASSERT_GT(flipped_before, 0u);
  const std::vector<char> locked = boundary_vertex_mask(g.positions.size(), g.triangles);
  const StretchOptimizationResult r = optimize_stretch(g.positions, g.triangles, uv, locked);
  EXPECT_TRUE(std::isinf(r.before.l2));
  EXPECT_GT(r.skipped_vertices, 0u);
  EXPECT_GT(r.vertex_moves, 0u);
  EXPECT_LE(count_flipped(g.triangles, uv), flipped_before);
}

// With only the four corners locked, boundary vertices move too (the energy rewards larger uv area), but no
// triangle may flip and the corners stay put.
TEST(OptimizeStretch, UnlockedBoundaryNeverFlips) {
  const TriMesh m = paraboloid(8, 1.5);
  std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(m), 0.5);
  std::vector<char> locked(m.positions.size(), 0);
  for (int v : {0, 8, 72, 80}) locked[v] = 1;
  const std::vector<Eigen::Vector2d> start = uv;
  StretchOptimizationOptions options;
  options.max_sweeps = 30;
  const StretchOptimizationResult r = optimize_stretch(m.positions, m.triangles, uv, locked, options);
  EXPECT_EQ(count_flipped(m.triangles, uv), 0u);
  EXPECT_GT(r.vertex_moves, 0u);
  bool boundary_moved = false;
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (locked[v]) {
      EXPECT_TRUE(bit_identical(uv[v], start[v])) << v;
    }
    const auto& p = m.positions[v];
    if ((p.x() == 0 || p.y() == 0) && !locked[v]) boundary_moved = boundary_moved || uv[v] != start[v];
  }
  EXPECT_TRUE(boundary_moved);
}

TEST(OptimizeStretch, RejectsBadInput) {
  const TriMesh g = test::grid(3);
  std::vector<Eigen::Vector2d> uv = xy(g);
  const std::vector<char> locked = boundary_vertex_mask(g.positions.size(), g.triangles);
  std::vector<char> short_locked(locked.begin(), locked.end() - 1);
  EXPECT_THROW(optimize_stretch(g.positions, g.triangles, uv, short_locked), InvalidInput);
  std::vector<Eigen::Vector2d> nan_uv = uv;
  nan_uv[5].x() = std::nan("");
  EXPECT_THROW(optimize_stretch(g.positions, g.triangles, nan_uv, locked), InvalidInput);
  StretchOptimizationOptions bad;
  bad.vertex.bracket_fraction = 1.0;
  EXPECT_THROW(optimize_stretch(g.positions, g.triangles, uv, locked, bad), InvalidInput);

  const auto rings = vertex_rings(g);
  std::mt19937 rng(1);
  std::vector<int> wrong_ring = rings[5];
  for (std::size_t f = 0; f < g.triangles.size(); ++f) {
    const auto& t = g.triangles[f];
    if (t[0] != 5 && t[1] != 5 && t[2] != 5) {
      wrong_ring.push_back(static_cast<int>(f));  // a triangle that does not contain vertex 5
      break;
    }
  }
  EXPECT_THROW(optimize_vertex(5, wrong_ring, g.positions, g.triangles, uv, {}, rng), InvalidInput);
  EXPECT_THROW(optimize_vertex(99, rings[5], g.positions, g.triangles, uv, {}, rng), InvalidInput);
}

/// A random star: center vertex 0 inside a fan of k random uv neighbours (angular gaps < π so the center is
/// in the kernel), with random 3D positions (an arbitrary, strongly anisotropic target).
TriMesh random_star(std::mt19937& rng, std::vector<Eigen::Vector2d>& uv, bool closed) {
  std::uniform_int_distribution<int> count(3, 10);
  std::uniform_real_distribution<double> unit(0, 1);
  TriMesh m;
  uv.clear();
  const int k = count(rng);
  m.positions.emplace_back(unit(rng), unit(rng), unit(rng));
  uv.emplace_back(0, 0);
  std::vector<double> angles;
  for (;;) {
    angles.clear();
    for (int i = 0; i < k; ++i) angles.push_back((closed ? 2 * kPi : 0.9 * kPi) * unit(rng));
    std::sort(angles.begin(), angles.end());
    bool ok = true;
    for (int i = 0; i + 1 < k; ++i)
      ok = ok && angles[i + 1] - angles[i] < 0.95 * kPi && angles[i + 1] > angles[i];
    if (closed) ok = ok && angles[0] + 2 * kPi - angles[k - 1] < 0.95 * kPi;
    if (ok) break;
  }
  for (int i = 0; i < k; ++i) {
    const double r = 0.2 + unit(rng);
    uv.emplace_back(r * std::cos(angles[i]), r * std::sin(angles[i]));
    m.positions.emplace_back(3 * unit(rng), 3 * unit(rng), 3 * unit(rng));
  }
  for (int i = 0; i < k; ++i) {
    if (!closed && i + 1 == k) break;
    m.triangles.push_back({0, 1 + i, 1 + (i + 1) % k});
  }
  // Move the center to a random point strictly inside the kernel (a random convex combination of the origin
  // and small steps that keep every triangle counter-clockwise).
  const Eigen::Vector2d step(0.05 * (unit(rng) - 0.5), 0.05 * (unit(rng) - 0.5));
  uv[0] += step;
  if (count_flipped(m.triangles, uv) != 0) uv[0] -= step;
  return m;
}

// Property test: from random stars, random 3D targets, random seeds and all three norms, optimize_vertex
// never flips a ring triangle, never raises the local stretch, writes only uv[v], and returns the local
// stretch of where it leaves v, which agrees with the per-triangle definition (triangle_stretch).
TEST(OptimizeVertex, NeverFlipsAndNeverRaisesStretch) {
  std::mt19937 shapes(2024);
  int moved = 0, total = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Eigen::Vector2d> uv;
    const bool closed = trial % 4 != 0;  // every fourth star is a boundary vertex (open fan)
    const TriMesh m = random_star(shapes, uv, closed);
    ASSERT_EQ(count_flipped(m.triangles, uv), 0u);
    std::vector<int> ring(m.triangles.size());
    for (std::size_t f = 0; f < ring.size(); ++f) ring[f] = static_cast<int>(f);

    VertexOptimizationOptions options;
    options.norm = trial % 3 == 0   ? StretchNorm::kL2
                   : trial % 3 == 1 ? StretchNorm::kLinf
                                    : StretchNorm::kBlend;
    options.linf_weight = 0.3;
    std::mt19937 rng(static_cast<unsigned>(trial));
    double previous = local_stretch(0, ring, m.positions, m.triangles, uv, options);
    for (int call = 0; call < 20; ++call) {
      const std::vector<Eigen::Vector2d> before = uv;
      const double value = optimize_vertex(0, ring, m.positions, m.triangles, uv, options, rng);
      ++total;
      ASSERT_EQ(count_flipped(m.triangles, uv), 0u) << "trial " << trial << " call " << call;
      for (std::size_t i = 1; i < uv.size(); ++i) ASSERT_TRUE(bit_identical(uv[i], before[i]));
      EXPECT_LE(value, previous);
      EXPECT_EQ(value, local_stretch(0, ring, m.positions, m.triangles, uv, options));
      if (value == previous) {
        EXPECT_TRUE(bit_identical(uv[0], before[0]));
      } else {
        ++moved;
      }
      previous = value;
    }
    // Cross-check the closed form against the definition through triangle_stretch.
    double sum_a3 = 0, sum = 0, max_linf = 0;
    for (const auto& t : m.triangles) {
      const Eigen::Vector3d q[3] = {m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
      const Eigen::Vector2d p[3] = {uv[t[0]], uv[t[1]], uv[t[2]]};
      const double a3 = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
      const StretchValues s = triangle_stretch(q, p);
      sum_a3 += a3;
      sum += a3 * s.l2 * s.l2;
      max_linf = std::max(max_linf, s.linf);
    }
    const double w = options.norm == StretchNorm::kL2 ? 0 : options.norm == StretchNorm::kLinf ? 1 : 0.3;
    const double expected = std::sqrt((1 - w) * sum / sum_a3 + w * max_linf * max_linf);
    EXPECT_NEAR(previous, expected, 1e-9 * expected) << "trial " << trial;
  }
  EXPECT_GT(moved, total / 10);  // the property is not vacuous: vertices do move
}

// Repeated calls converge to a local minimum of the (smooth) L2 ring energy: afterwards no small step in any
// direction lowers local_stretch. This checks that the line searches minimize the true energy.
TEST(OptimizeVertex, ConvergesToLocalMinimumOfL2Energy) {
  std::mt19937 shapes(77);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Eigen::Vector2d> uv;
    const TriMesh m = random_star(shapes, uv, /*closed=*/true);
    std::vector<int> ring(m.triangles.size());
    for (std::size_t f = 0; f < ring.size(); ++f) ring[f] = static_cast<int>(f);
    VertexOptimizationOptions options;
    options.tolerance = 1e-6;
    std::mt19937 rng(static_cast<unsigned>(trial));
    double value = 0;
    for (int call = 0; call < 60; ++call)
      value = optimize_vertex(0, ring, m.positions, m.triangles, uv, options, rng);
    // Scale of the ring: the shortest uv distance from the center to a neighbour.
    double scale = std::numeric_limits<double>::infinity();
    for (std::size_t i = 1; i < uv.size(); ++i) scale = std::min(scale, (uv[i] - uv[0]).norm());
    const Eigen::Vector2d optimum = uv[0];
    for (int k = 0; k < 16; ++k) {
      const double h = 1e-3 * scale;
      uv[0] = optimum + h * Eigen::Vector2d(std::cos(k * kPi / 8), std::sin(k * kPi / 8));
      const double nearby = local_stretch(0, ring, m.positions, m.triangles, uv, options);
      EXPECT_GE(nearby, value * (1 - 1e-7))
          << "relative gap " << (value - nearby) / value << ", trial " << trial << " direction " << k;
    }
    uv[0] = optimum;
  }
}

// One interior vertex of a flat grid displaced inside its ring returns to its isometric position.
TEST(OptimizeVertex, FlatRingReturnsToIsometry) {
  const TriMesh g = test::grid(4);
  const auto rings = vertex_rings(g);
  const int v = 12;  // the center (2,2)/4
  std::mt19937 rng(5);
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.08, 0.05), Eigen::Vector2d(-0.06, 0.09)}) {
    std::vector<Eigen::Vector2d> uv = xy(g);
    uv[v] += offset;
    ASSERT_EQ(count_flipped(g.triangles, uv), 0u);
    double value = 0;
    for (int call = 0; call < 40; ++call) {
      value = optimize_vertex(v, rings[v], g.positions, g.triangles, uv, {}, rng);
    }
    EXPECT_NEAR((uv[v] - Eigen::Vector2d(0.5, 0.5)).norm(), 0.0, 1e-3);
    EXPECT_NEAR(value, 1.0, 1e-5);
  }
}

// Scale: a 101×101 grid (10,201 vertices, 20,000 triangles) on a paraboloid from a distorted start. Reports
// the time; checks only the properties (the time is machine dependent).
TEST(OptimizeStretch, TenThousandVertices) {
  const TriMesh m = paraboloid(100, 1.5);
  std::vector<Eigen::Vector2d> uv = pushed_to_corner(xy(m), 0.6);
  const std::vector<char> locked = boundary_vertex_mask(m.positions.size(), m.triangles);
  StretchOptimizationOptions options;  // defaults: threshold 1e-3, at most 50 sweeps
  const auto t0 = std::chrono::steady_clock::now();
  const StretchOptimizationResult r = optimize_stretch(m.positions, m.triangles, uv, locked, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "10,201 vertices: L2 " << r.before.l2 << " -> " << r.after.l2 << " in " << r.sweeps
            << " sweeps, " << r.vertex_moves << " moves, " << seconds << " s\n";
  RecordProperty("seconds", std::to_string(seconds));
  EXPECT_LT(r.after.l2, r.before.l2);
  EXPECT_EQ(count_flipped(m.triangles, uv), 0u);
}

}  // namespace
}  // namespace geomip
