// Normal-mesh resampling (codec/normal_mesh.h) on an analytic surface: a wavy height field sampled with a
// tangential wobble, so the original details have large tangential parts that the resampling must remove.
#include "codec/normal_mesh.h"

#include "codec/wavelet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

namespace geomip::codec {
namespace {

double height(double x, double y) {
  return 0.15 * std::sin(3 * x) * std::cos(2 * y) + 0.05 * std::sin(7 * x + 5 * y);
}
Point3d surface_normal(double x, double y) {
  const double fx = 0.45 * std::cos(3 * x) * std::cos(2 * y) + 0.35 * std::cos(7 * x + 5 * y);
  const double fy = -0.3 * std::sin(3 * x) * std::sin(2 * y) + 0.25 * std::cos(7 * x + 5 * y);
  const double r = std::sqrt(fx * fx + fy * fy + 1);
  return {-fx / r, -fy / r, 1 / r};
}

/// A (2^level+1)² grid on z = height(x, y) over [−1, 1]², (x, y) wobbled by about one sample spacing.
Grid3 wavy_patch(int level) {
  Grid3 g{level, {}};
  const int n = g.size();
  g.values.resize(3 * static_cast<std::size_t>(n) * n);
  const double wobble = 1.0 / (n - 1);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = double(i) / (n - 1), v = double(j) / (n - 1);
      const double x = 2 * u - 1 + wobble * std::sin(37 * v + 11 * u) * std::sin(3.14159265 * u);
      const double y = 2 * v - 1 + wobble * std::cos(29 * u - 7 * v) * std::sin(3.14159265 * v);
      float* p = g.values.data() + 3 * (static_cast<std::size_t>(j) * n + i);
      p[0] = static_cast<float>(x);
      p[1] = static_cast<float>(y);
      p[2] = static_cast<float>(height(x, y));
    }
  }
  return g;
}

double off_surface(const float* p) {
  return std::abs(double(p[2]) - height(p[0], p[1]));
}

/// Crossing of a line with the height field nearest `hint` (within `radius`): sign changes of
/// z − height(x, y) along the line, scanned finely around the hint's foot and refined by bisection.
std::optional<Point3d> field_crossing(const Point3d& o, const Point3d& d, const Point3d& hint,
                                      double radius) {
  const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(length > 0)) return std::nullopt;
  const Point3d u{d[0] / length, d[1] / length, d[2] / length};
  const double t0 = (hint[0] - o[0]) * u[0] + (hint[1] - o[1]) * u[1] + (hint[2] - o[2]) * u[2];
  auto at = [&](double t) { return Point3d{o[0] + t * u[0], o[1] + t * u[1], o[2] + t * u[2]}; };
  auto f = [&](double t) {
    const Point3d p = at(t);
    return p[2] - height(p[0], p[1]);
  };
  std::optional<Point3d> best;
  double best_distance = radius;
  const int scan = 200;
  for (int k = 0; k < scan; ++k) {
    double a = t0 - radius + 2 * radius * k / scan, b = a + 2 * radius / scan;
    if ((f(a) > 0) == (f(b) > 0)) continue;
    for (int it = 0; it < 60; ++it) {
      const double m = 0.5 * (a + b);
      ((f(a) > 0) == (f(m) > 0) ? a : b) = m;
    }
    const Point3d p = at(0.5 * (a + b));
    const double distance = std::hypot(p[0] - hint[0], p[1] - hint[1], p[2] - hint[2]);
    if (distance <= best_distance) {
      best_distance = distance;
      best = p;
    }
  }
  return best;
}

/// Share of the squared detail length that is tangential (off the height field's normal at the sample),
/// over the details of wavelet steps 1..steps — computed with the codec's own integer transform on the grid
/// quantized to 2^20 steps, independently of normal_mesh.cpp.
double tangential_share(const Grid3& g, int steps) {
  const int n = g.size();
  const std::size_t cells = static_cast<std::size_t>(n) * n;
  std::vector<std::vector<std::int32_t>> channels(3, std::vector<std::int32_t>(cells));
  const double unit = 4.0 / (1 << 20);
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < cells; ++i)
      channels[c][i] = static_cast<std::int32_t>(std::lround(g.values[3 * i + c] / unit));
    wavelet_forward(channels[c], g.level, steps, WaveletFilter::kCubic);
  }
  const int coarse = 1 << steps;
  double tangential = 0, total = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      if (i % coarse == 0 && j % coarse == 0) continue;  // coarse band, not a detail of steps 1..steps
      const std::size_t k = static_cast<std::size_t>(j) * n + i;
      const double d[3] = {channels[0][k] * unit, channels[1][k] * unit, channels[2][k] * unit};
      const float* p = g.values.data() + 3 * k;
      const Point3d normal = surface_normal(p[0], p[1]);
      const double along = d[0] * normal[0] + d[1] * normal[1] + d[2] * normal[2];
      const double length2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      total += length2;
      tangential += length2 - along * along;
    }
  }
  return tangential / total;
}

TEST(NormalMesh, SamplesLandOnTheSurfaceAndBordersStay) {
  const Grid3 before = wavy_patch(6);
  Grid3 after = before;
  const NormalMeshStats stats = normal_mesh_resample(after, field_crossing, {.steps = 3});
  const int n = after.size();
  EXPECT_GT(stats.candidates, 0u);
  EXPECT_GE(stats.moved, stats.candidates * 95 / 100);
  EXPECT_EQ(stats.moved + stats.no_crossing + stats.would_fold, stats.candidates);
  EXPECT_LE(stats.max_shift, 4.0);  // the foot's reach (0.5 spacings) plus the wobble (about 1 spacing)
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::size_t k = 3 * (static_cast<std::size_t>(j) * n + i);
      const float* p = after.values.data() + k;
      ASSERT_LT(off_surface(p), 1e-5) << i << "," << j;
      if (i == 0 || j == 0 || i == n - 1 || j == n - 1) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(after.values[k + c], before.values[k + c]) << i << "," << j;
      }
    }
  }
}

TEST(NormalMesh, DetailsBecomeNormal) {
  const Grid3 before = wavy_patch(6);
  Grid3 after = before;
  normal_mesh_resample(after, field_crossing, {.steps = 3});
  const double share_before = tangential_share(before, 3), share_after = tangential_share(after, 3);
  EXPECT_GT(share_before, 0.3);  // the wobble makes the original details largely tangential
  EXPECT_LT(share_after, 0.05 * share_before) << share_before << " -> " << share_after;
}

TEST(NormalMesh, ResampledGridIsAFixedPoint) {
  Grid3 g = wavy_patch(6);
  normal_mesh_resample(g, field_crossing, {.steps = 3});
  const NormalMeshStats again = normal_mesh_resample(g, field_crossing, {.steps = 3});
  EXPECT_GE(again.moved, again.candidates * 95 / 100);
  EXPECT_LT(again.max_shift, 1e-3);
}

TEST(NormalMesh, NoCrossingOrNoStepsLeavesTheGridAlone) {
  const Grid3 before = wavy_patch(5);
  Grid3 g = before;
  const SurfaceCrossing none = [](const Point3d&, const Point3d&, const Point3d&, double) {
    return std::optional<Point3d>();
  };
  const NormalMeshStats stats = normal_mesh_resample(g, none, {.steps = 2});
  EXPECT_EQ(stats.moved, 0u);
  EXPECT_EQ(stats.no_crossing, stats.candidates);
  EXPECT_EQ(g.values, before.values);
  EXPECT_EQ(normal_mesh_resample(g, field_crossing, {.steps = 0}).candidates, 0u);
  EXPECT_EQ(g.values, before.values);
}

/// The plane z = 0 sampled regularly over [−1, 1]²: every prediction is exact and every normal is +z.
Grid3 flat_patch(int level) {
  Grid3 g{level, {}};
  const int n = g.size();
  g.values.resize(3 * static_cast<std::size_t>(n) * n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      float* p = g.values.data() + 3 * (static_cast<std::size_t>(j) * n + i);
      p[0] = static_cast<float>(2.0 * i / (n - 1) - 1);
      p[1] = static_cast<float>(2.0 * j / (n - 1) - 1);
      p[2] = 0;
    }
  }
  return g;
}

/// A stand-in for the surface crossing that answers a point on the plane `factor` reaches (radius = half a
/// sample spacing) along +x from the hint: 6 = three spacings, past the sample's neighbour, as a crossing on
/// the far side of a thin part would be.
SurfaceCrossing shifted_crossing(double factor) {
  return [factor](const Point3d&, const Point3d&, const Point3d& hint, double radius) {
    return std::optional<Point3d>(Point3d{hint[0] + factor * radius, hint[1], 0});
  };
}

/// Triangles of the grid's quads (split along the (i,j)–(i+1,j+1) diagonal) that face −z.
int triangles_facing_down(const Grid3& g) {
  const int n = g.size();
  auto at = [&](int i, int j) {
    const float* p = g.values.data() + 3 * (static_cast<std::size_t>(j) * n + i);
    return Point3d{p[0], p[1], p[2]};
  };
  auto down = [](const Point3d& a, const Point3d& b, const Point3d& c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0;
  };
  int count = 0;
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      count += down(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      count += down(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return count;
}

TEST(NormalMesh, GuardedStepsRefuseMovesThatFold) {
  const Grid3 before = flat_patch(5);
  ASSERT_EQ(triangles_facing_down(before), 0);

  // Every step guarded: a crossing three spacings away would fold every umbrella, so nothing moves.
  Grid3 g = before;
  NormalMeshStats stats =
      normal_mesh_resample(g, shifted_crossing(6), {.steps = 3, .fold_guard_from_step = 1});
  EXPECT_GT(stats.candidates, 0u);
  EXPECT_EQ(stats.would_fold, stats.candidates);
  EXPECT_EQ(stats.moved, 0u);
  EXPECT_EQ(g.values, before.values);

  // A crossing a tenth of a spacing away folds nothing: every sample moves. (One step: over several, the
  // moved coarser samples make the cubic prediction overshoot near the fixed border.)
  g = before;
  stats = normal_mesh_resample(g, shifted_crossing(0.2), {.steps = 1, .fold_guard_from_step = 1});
  EXPECT_EQ(stats.would_fold, 0u);
  EXPECT_EQ(stats.moved, stats.candidates);
  EXPECT_EQ(triangles_facing_down(g), 0);

  // Unguarded, the far crossing is taken and the grid folds.
  g = before;
  stats = normal_mesh_resample(g, shifted_crossing(6), {.steps = 3, .fold_guard_from_step = 0});
  EXPECT_EQ(stats.moved, stats.candidates);
  EXPECT_GT(triangles_facing_down(g), 0);

  // The default guards the coarsest of the three steps only: its interior samples (the level-3 grid's 7²
  // less the level-2 grid's 3²: 40) stay, the finer steps' move.
  g = before;
  stats = normal_mesh_resample(g, shifted_crossing(6), {.steps = 3});
  EXPECT_EQ(NormalMeshOptions{}.fold_guard_from_step, 3);
  EXPECT_EQ(stats.would_fold, 40u);
  EXPECT_EQ(stats.moved, stats.candidates - 40u);
}

TEST(NormalMesh, RejectsBadGrids) {
  Grid3 wrong_size{3, std::vector<float>(10)};
  EXPECT_THROW(normal_mesh_resample(wrong_size, field_crossing), std::invalid_argument);
  Grid3 nan = wavy_patch(3);
  nan.values[7] = NAN;
  EXPECT_THROW(normal_mesh_resample(nan, field_crossing), std::invalid_argument);
}

}  // namespace
}  // namespace geomip::codec
