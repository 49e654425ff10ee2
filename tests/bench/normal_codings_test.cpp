// The two-channel normal codings that `codec_bench --normals` measures (normal_codings.h): exact round trips
// without quantization, the quantization bound with it, and unit normals from any decoded values — so the
// figures in docs/codec-v3.md measure the codings, not a bug in them.
#include "tests/bench/normal_codings.h"

#include "tests/codec/pillow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace geomip::bench {
namespace {

/// Largest angle (radians) between two sets of unit normal grids.
double max_angle(const std::vector<Grid3>& a, const std::vector<Grid3>& b) {
  double e = 0;
  for (std::size_t p = 0; p < a.size(); ++p)
    for (std::size_t k = 0; k + 2 < a[p].values.size(); k += 3) {
      const float* x = a[p].values.data() + k;
      const float* y = b[p].values.data() + k;
      const double c[3] = {double(x[1]) * y[2] - double(x[2]) * y[1], double(x[2]) * y[0] - double(x[0]) * y[2],
                           double(x[0]) * y[1] - double(x[1]) * y[0]};
      const double dot = double(x[0]) * y[0] + double(x[1]) * y[1] + double(x[2]) * y[2];
      e = std::max(e, std::atan2(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), dot));
    }
  return e;
}

/// A pillow's geometry at `level` and normal maps one level finer (as `geomip convert` writes them); the
/// normalized position serves as a unit field that is not the surface normal (all of the sphere).
struct Fixture {
  std::vector<Grid3> geometry, normals;
};
Fixture fixture(int level) {
  return {test::make_pillow(level).patches, test::position_normals(test::make_pillow(level + 1).patches)};
}

TEST(NormalCodings, ResidualRoundTripsWithoutQuantization) {
  const Fixture f = fixture(4);
  for (const Orientation& along : {Orientation{true, true}, Orientation{false, true}, Orientation{}}) {
    std::vector<Grid3> maps = normal_residual(f.normals, f.geometry, along);
    for (const Grid3& g : maps)
      for (std::size_t k = 0; k < g.values.size(); k += 3) {
        ASSERT_LE(std::abs(g.values[k]), 1.0f);  // the folded half has |u| + |v| > 1
        ASSERT_LE(std::abs(g.values[k + 1]), 1.0f);
        ASSERT_EQ(g.values[k + 2], 0.f);
      }
    apply_normal_residual(maps, f.geometry, along);
    EXPECT_LE(max_angle(maps, f.normals), 1e-5);
  }
}

// Two layers: frames whose normal is a given field (here a rotated copy of the normals: 0.2 rad about x).
TEST(NormalCodings, TwoLayerResidualRoundTrips) {
  const Fixture f = fixture(4);
  std::vector<Grid3> axes = f.normals;
  const double c = std::cos(0.2), s = std::sin(0.2);
  for (Grid3& g : axes)
    for (std::size_t k = 0; k < g.values.size(); k += 3) {
      const double y = g.values[k + 1], z = g.values[k + 2];
      g.values[k + 1] = static_cast<float>(c * y - s * z), g.values[k + 2] = static_cast<float>(s * y + c * z);
    }
  std::vector<Grid3> maps = normal_residual(f.normals, f.geometry, {}, &axes);
  for (const Grid3& g : maps)
    for (std::size_t k = 0; k < g.values.size(); k += 3)
      ASSERT_LE(std::abs(g.values[k]) + std::abs(g.values[k + 1]), 0.21f);  // |(u, v)|₁ ≤ tan-ish of 0.2 rad
  apply_normal_residual(maps, f.geometry, {}, &axes);
  EXPECT_LE(max_angle(maps, f.normals), 1e-5);
}

// Each octahedral channel off by at most d moves (u, v) by at most d·√2; the octahedral decoding D is
// piecewise linear with |dD| ≤ √3·|d(u, v)| and |D| ≥ 1/√3 (its L1 norm is 1), so the unit normal turns by at
// most 3·√2·d.
TEST(NormalCodings, ChannelErrorsTurnTheNormalByABoundedAngle) {
  const Fixture f = fixture(4);
  const double d = 1.0 / 1024;
  std::vector<Grid3> maps = normal_residual(f.normals, f.geometry, {});
  int sign = 1;
  for (Grid3& g : maps)
    for (std::size_t k = 0; k < g.values.size(); k += 3, sign = -sign) {
      g.values[k] += static_cast<float>(sign * d);
      g.values[k + 1] -= static_cast<float>(d);
    }
  apply_normal_residual(maps, f.geometry, {});
  EXPECT_LE(max_angle(maps, f.normals), 3 * std::sqrt(2.0) * d + 1e-5);
}

TEST(NormalCodings, AnyDecodedValuesGiveUnitNormals) {
  const Fixture f = fixture(3);
  std::vector<Grid3> maps = f.normals;
  const float odd[] = {0.f, 5.f, -7.f, std::numeric_limits<float>::quiet_NaN(), 1e30f, -0.5f};
  std::size_t n = 0;
  for (Grid3& g : maps)
    for (float& v : g.values) v = odd[n++ % 6];
  std::vector<Grid3> zeros = f.geometry;  // degenerate geometry: every frame falls back to the axes
  for (Grid3& g : zeros)
    for (float& v : g.values) v = 0.f;
  for (const std::vector<Grid3>* geometry : {&f.geometry, static_cast<const std::vector<Grid3>*>(&zeros)}) {
    std::vector<Grid3> out = maps;
    apply_normal_residual(out, *geometry, {});
    for (const Grid3& g : out)
      for (std::size_t k = 0; k < g.values.size(); k += 3) {
        const double len = std::hypot(double(g.values[k]), double(g.values[k + 1]), double(g.values[k + 2]));
        ASSERT_NEAR(len, 1.0, 1e-6);
      }
  }
}

TEST(NormalCodings, OrientationFollowsTheNormals) {
  const Fixture f = fixture(3);
  const Orientation along = normal_frames_along_grid(f.normals, f.geometry);
  ASSERT_EQ(along.size(), 2u);
  std::vector<Grid3> flipped = f.normals;  // patch 1's normals reversed
  for (float& v : flipped[1].values) v = -v;
  const Orientation other = normal_frames_along_grid(flipped, f.geometry);
  EXPECT_EQ(other[0], along[0]);
  EXPECT_NE(other[1], along[1]);
}

}  // namespace
}  // namespace geomip::bench
