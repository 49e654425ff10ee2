#include "codec/wavelet.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace geomip::codec {
namespace {

constexpr WaveletFilter kFilters[] = {WaveletFilter::kLinear, WaveletFilter::kCubic};

std::vector<std::int32_t> random_grid(int level, std::uint32_t seed, int range = 1 << 20) {
  const int n = (1 << level) + 1;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> d(-range, range);
  std::vector<std::int32_t> g(static_cast<std::size_t>(n) * n);
  for (auto& v : g) v = d(rng);
  return g;
}

TEST(Wavelet, PerfectReconstructionOnRandomIntegers) {
  for (auto filter : kFilters) {
    for (int level = 0; level <= 8; ++level) {
      for (int steps = 0; steps <= level; ++steps) {
        auto g = random_grid(level, static_cast<std::uint32_t>(level * 31 + steps));
        const auto original = g;
        wavelet_forward(g, level, steps, filter);
        if (steps > 0 && level >= 2) {
          EXPECT_NE(g, original);
        }
        wavelet_inverse(g, level, steps, filter);
        ASSERT_EQ(g, original) << "level " << level << " steps " << steps;
      }
    }
  }
}

TEST(Wavelet, CoarseBandIsTheNestedSubsample) {
  for (auto filter : kFilters) {
    const int level = 6, n = 65;
    for (int steps = 0; steps <= level; ++steps) {
      auto g = random_grid(level, 5);
      const auto original = g;
      wavelet_forward(g, level, steps, filter);
      const int s = 1 << steps;
      for (int j = 0; j < n; j += s) {
        for (int i = 0; i < n; i += s) ASSERT_EQ(g[j * n + i], original[j * n + i]);
      }
    }
  }
}

TEST(Wavelet, BoundaryCoefficientsDependOnlyOnTheBoundaryLineAndReverse) {
  // Two grids with the same boundary row j = 0 reversed as column i = n−1 (as on a reversed seam), different
  // interiors: the coefficients along those lines agree (reversed), for every side pairing used by seams.
  for (auto filter : kFilters) {
    const int level = 7, n = 129;
    auto a = random_grid(level, 11), b = random_grid(level, 12);
    for (int k = 0; k < n; ++k) b[(n - 1 - k) * n + (n - 1)] = a[k];  // side 0 of a == side 1 of b reversed
    wavelet_forward(a, level, level, filter);
    wavelet_forward(b, level, level, filter);
    for (int k = 0; k < n; ++k) ASSERT_EQ(b[(n - 1 - k) * n + (n - 1)], a[k]) << "k = " << k;
    // And a changed interior leaves the boundary coefficients alone.
    auto c = random_grid(level, 13);
    auto d = c;
    for (int j = 1; j < n - 1; ++j) {
      for (int i = 1; i < n - 1; ++i) d[j * n + i] += 17 * i - 5 * j;
    }
    wavelet_forward(c, level, 5, filter);
    wavelet_forward(d, level, 5, filter);
    for (int k = 0; k < n; ++k) {
      ASSERT_EQ(c[k], d[k]);
      ASSERT_EQ(c[(n - 1) * n + k], d[(n - 1) * n + k]);
      ASSERT_EQ(c[k * n], d[k * n]);
      ASSERT_EQ(c[k * n + n - 1], d[k * n + n - 1]);
    }
  }
}

TEST(Wavelet, OneDimensionalReversalEquivariance) {
  // A grid and its mirror image (i → n−1−i) transform to mirrored coefficients.
  for (auto filter : kFilters) {
    for (int level = 1; level <= 6; ++level) {
      const int n = (1 << level) + 1;
      auto a = random_grid(level, 40 + level);
      auto b = a;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) b[j * n + i] = a[j * n + (n - 1 - i)];
      }
      wavelet_forward(a, level, level, filter);
      wavelet_forward(b, level, level, filter);
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) ASSERT_EQ(b[j * n + i], a[j * n + (n - 1 - i)]);
      }
    }
  }
}

TEST(Wavelet, LinearFieldsHaveZeroDetailsWithTheLinearFilter) {
  const int level = 7, n = 129;
  std::vector<std::int32_t> g(n * n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) g[j * n + i] = 1234 + 37 * i - 91 * j;
  }
  for (auto filter : kFilters) {
    auto c = g;
    wavelet_forward(c, level, level, filter);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        if (i % (n - 1) == 0 && j % (n - 1) == 0) continue;  // the level-0 corners
        ASSERT_EQ(c[j * n + i], 0) << "(" << i << ", " << j << ")";
      }
    }
  }
}

TEST(Wavelet, CubicFieldsHaveZeroDetailsWithTheCubicFilter) {
  // p(i) + q(j) cubic: exact wherever the line has at least 4 evens (current grid of ≥ 9 samples).
  const int level = 7, n = 129;
  std::vector<std::int32_t> g(n * n);
  auto p = [](std::int64_t x) { return x * x * x - 60 * x * x + 7 * x; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::int64_t v = (static_cast<std::int64_t>(i) * i * i - 150 * i * i + 3 * i) + 2 * p(j);
      g[j * n + i] = static_cast<std::int32_t>(v);
    }
  }
  const int steps = level - 2;  // the last step works on a 9-sample grid: 5 evens
  auto c = g;
  wavelet_forward(c, level, steps, WaveletFilter::kCubic);
  const int coarse = 1 << steps;
  int nonzero = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      if (i % coarse == 0 && j % coarse == 0) continue;
      nonzero += c[j * n + i] != 0;
    }
  }
  EXPECT_EQ(nonzero, 0);
  auto l = g;
  wavelet_forward(l, level, steps, WaveletFilter::kLinear);
  int linear_nonzero = 0;
  for (auto v : l) linear_nonzero += v != 0;
  EXPECT_GT(linear_nonzero, n * n / 2);  // the linear filter does not reproduce cubics
}

TEST(Wavelet, RejectsWrongSizes) {
  std::vector<std::int32_t> g(10);
  EXPECT_THROW(wavelet_forward(g, 2, 1, WaveletFilter::kCubic), std::invalid_argument);
  std::vector<std::int32_t> h(25);
  EXPECT_THROW(wavelet_forward(h, 2, 3, WaveletFilter::kCubic), std::invalid_argument);
  EXPECT_NO_THROW(wavelet_forward(h, 2, 2, WaveletFilter::kCubic));
}

}  // namespace
}  // namespace geomip::codec
