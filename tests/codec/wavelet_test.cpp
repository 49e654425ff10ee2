#include "codec/wavelet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace geomip::codec {
namespace {

constexpr WaveletFilter kFilters[] = {WaveletFilter::kLinear, WaveletFilter::kCubic,
                                      WaveletFilter::kCubicLong};

std::vector<std::int32_t> random_grid(int level, std::uint32_t seed, int range = 1 << 20) {
  const int n = (1 << level) + 1;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> d(-range, range);
  std::vector<std::int32_t> g(static_cast<std::size_t>(n) * n);
  for (auto& v : g) v = d(rng);
  return g;
}

TEST(Wavelet, PerfectReconstructionOnRandomIntegers) {
  for (bool update : {false, true}) {  // the interpolating transform, then with the update step
    for (auto filter : kFilters) {
      for (int level = 0; level <= 8; ++level) {
        for (int steps = 0; steps <= level; ++steps) {
          auto g = random_grid(level, static_cast<std::uint32_t>(level * 31 + steps));
          const auto original = g;
          wavelet_forward(g, level, steps, filter, update);
          if (steps > 0 && level >= 2) {
            EXPECT_NE(g, original);
          }
          wavelet_inverse(g, level, steps, filter, update);
          ASSERT_EQ(g, original) << "level " << level << " steps " << steps;
        }
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

TEST(Wavelet, TheUpdateAveragesTheCoarseBandButLeavesTheBorderToItself) {
  // With the update the coarse band is no longer the subsample inside the grid (it still is on the border
  // lines, which are never updated).
  for (auto filter : kFilters) {
    const int level = 6, n = 65, steps = 3, s = 1 << steps;
    auto g = random_grid(level, 7, 1000);
    const auto original = g;
    wavelet_forward(g, level, steps, filter, true);
    int inner_changed = 0;
    for (int j = 0; j < n; j += s) {
      for (int i = 0; i < n; i += s) {
        const bool border = i == 0 || j == 0 || i == n - 1 || j == n - 1;
        if (border) {
          ASSERT_EQ(g[j * n + i], original[j * n + i]) << i << ", " << j;
        } else {
          inner_changed += g[j * n + i] != original[j * n + i];
        }
      }
    }
    EXPECT_GT(inner_changed, 0);
    // A spike on a constant field at a sample that is not in the coarse band: the subsample misses it, the
    // updated band keeps its mass (the update preserves the mean: each coarse sample stands for 4 finer
    // ones).
    for (bool update : {false, true}) {
      std::vector<std::int32_t> f(static_cast<std::size_t>(n) * n, 500);
      const int spike = 4096;
      f[33 * n + 31] += spike;  // odd row and column: not a coarse sample after one step
      wavelet_forward(f, level, 1, filter, update);
      std::int64_t mass = 0;
      for (int j = 0; j < n; j += 2) {
        for (int i = 0; i < n; i += 2) mass += f[j * n + i] - 500;
      }
      if (update) {
        EXPECT_NEAR(4.0 * static_cast<double>(mass), spike, 16.0) << static_cast<int>(filter);
      } else {
        EXPECT_EQ(mass, 0);
      }
    }
  }
}

TEST(Wavelet, BoundaryCoefficientsDependOnlyOnTheBoundaryLineAndReverse) {
  for (bool update : {false, true}) {  // the interpolating transform, then with the update step
    // Two grids with the same boundary row j = 0 reversed as column i = n−1 (as on a reversed seam),
    // different interiors: the coefficients along those lines agree (reversed), for every side pairing used
    // by seams.
    for (auto filter : kFilters) {
      const int level = 7, n = 129;
      auto a = random_grid(level, 11), b = random_grid(level, 12);
      for (int k = 0; k < n; ++k) b[(n - 1 - k) * n + (n - 1)] = a[k];  // side 0 of a == side 1 of b reversed
      wavelet_forward(a, level, level, filter, update);
      wavelet_forward(b, level, level, filter, update);
      for (int k = 0; k < n; ++k) ASSERT_EQ(b[(n - 1 - k) * n + (n - 1)], a[k]) << "k = " << k;
      // And a changed interior leaves the boundary coefficients alone.
      auto c = random_grid(level, 13);
      auto d = c;
      for (int j = 1; j < n - 1; ++j) {
        for (int i = 1; i < n - 1; ++i) d[j * n + i] += 17 * i - 5 * j;
      }
      wavelet_forward(c, level, 5, filter, update);
      wavelet_forward(d, level, 5, filter, update);
      for (int k = 0; k < n; ++k) {
        ASSERT_EQ(c[k], d[k]);
        ASSERT_EQ(c[(n - 1) * n + k], d[(n - 1) * n + k]);
        ASSERT_EQ(c[k * n], d[k * n]);
        ASSERT_EQ(c[k * n + n - 1], d[k * n + n - 1]);
      }
    }
  }
}

TEST(Wavelet, OneDimensionalReversalEquivariance) {
  for (bool update : {false, true}) {  // the interpolating transform, then with the update step
    // A grid and its mirror image (i → n−1−i) transform to mirrored coefficients.
    for (auto filter : kFilters) {
      for (int level = 1; level <= 6; ++level) {
        const int n = (1 << level) + 1;
        auto a = random_grid(level, 40 + level);
        auto b = a;
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) b[j * n + i] = a[j * n + (n - 1 - i)];
        }
        wavelet_forward(a, level, level, filter, update);
        wavelet_forward(b, level, level, filter, update);
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) ASSERT_EQ(b[j * n + i], a[j * n + (n - 1 - i)]);
        }
      }
    }
  }
}

TEST(Wavelet, LinearFieldsHaveZeroDetailsWithTheLinearFilter) {
  for (bool update : {false, true}) {  // the interpolating transform, then with the update step
    const int level = 7, n = 129;
    std::vector<std::int32_t> g(n * n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) g[j * n + i] = 1234 + 37 * i - 91 * j;
    }
    for (auto filter : kFilters) {
      auto c = g;
      wavelet_forward(c, level, level, filter, update);
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          if (i % (n - 1) == 0 && j % (n - 1) == 0) continue;  // the level-0 corners
          ASSERT_EQ(c[j * n + i], 0) << "(" << i << ", " << j << ")";
        }
      }
    }
  }
}

TEST(Wavelet, CubicFieldsHaveZeroDetailsWithTheCubicFilter) {
  for (bool update : {false, true}) {  // the interpolating transform, then with the update step
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
    const int coarse = 1 << steps;
    for (auto filter : {WaveletFilter::kCubic, WaveletFilter::kCubicLong}) {  // order 6 reproduces cubics too
      auto c = g;
      wavelet_forward(c, level, steps, filter, update);
      int nonzero = 0;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          if (i % coarse == 0 && j % coarse == 0) continue;
          nonzero += c[j * n + i] != 0;
        }
      }
      EXPECT_EQ(nonzero, 0) << "filter " << int(filter);
    }
    auto l = g;
    wavelet_forward(l, level, steps, WaveletFilter::kLinear);
    int linear_nonzero = 0;
    for (auto v : l) linear_nonzero += v != 0;
    EXPECT_GT(linear_nonzero, n * n / 2);  // the linear filter does not reproduce cubics
  }
}

// The transform as the header defines it, one line and one sample at a time in 64-bit arithmetic, stored
// modulo 2^32: what the fast implementation (contiguous 32-bit lanes, gathered sub-grids) must equal bit for
// bit, so streams of every pack version decode to the same samples.
std::int32_t wrap64(std::int64_t v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
}

std::int64_t defined_prediction(const std::vector<std::int64_t>& e, int t, bool cubic, bool six) {
  const int n = static_cast<int>(e.size());
  const auto at = [&](int k) { return e[static_cast<std::size_t>(k)]; };
  if (!cubic || n < 4) return (at(t) + at(t + 1) + 1) >> 1;
  if (six && t >= 2 && t + 3 < n)
    return (3 * at(t - 2) - 25 * at(t - 1) + 150 * at(t) + 150 * at(t + 1) - 25 * at(t + 2) + 3 * at(t + 3) +
            128) >>
           8;
  if (t == 0) return (5 * at(0) + 15 * at(1) - 5 * at(2) + at(3) + 8) >> 4;
  if (t == n - 2) return (5 * at(n - 1) + 15 * at(n - 2) - 5 * at(n - 3) + at(n - 4) + 8) >> 4;
  return (-at(t - 1) + 9 * at(t) + 9 * at(t + 1) - at(t + 2) + 8) >> 4;
}

/// One line (its samples by pointer), forward (sign −1: predict, then update) or inverse (+1).
void defined_line(const std::vector<std::int32_t*>& x, int sign, bool cubic, bool six, bool updated,
                  bool update4) {
  const int m = static_cast<int>(x.size()) / 2;
  const auto d = [&](int k) { return std::int64_t{*x[static_cast<std::size_t>(k)]}; };
  const auto update = [&](int sg) {
    for (int t = 1; t < m; ++t) {
      const std::int64_t u = update4 && t >= 2 && t + 2 <= m
                                 ? (9 * (d(2 * t - 1) + d(2 * t + 1)) - d(2 * t - 3) - d(2 * t + 3) + 16) >> 5
                                 : (d(2 * t - 1) + d(2 * t + 1) + 2) >> 2;
      *x[2 * t] = wrap64(*x[2 * t] + sg * u);
    }
  };
  if (updated && sign > 0) update(-1);
  std::vector<std::int64_t> e;
  for (int t = 0; t <= m; ++t) e.push_back(*x[2 * t]);
  for (int t = 0; t < m; ++t)
    *x[2 * t + 1] = wrap64(*x[2 * t + 1] + sign * defined_prediction(e, t, cubic, six));
  if (updated && sign < 0) update(+1);
}

void defined_transform(std::vector<std::int32_t>& g, int level, int steps, WaveletFilter filter, bool update,
                       bool forward) {
  const int size = (1 << level) + 1;
  const bool cubic = filter != WaveletFilter::kLinear, long_filter = filter == WaveletFilter::kCubicLong;
  const auto pass = [&](int k, bool rows, int sign) {
    const int s = 1 << (k - 1);
    for (int l = 0; l < size; l += s) {
      std::vector<std::int32_t*> x;
      for (int a = 0; a < size; a += s)
        x.push_back(&g[static_cast<std::size_t>(rows ? l * size + a : a * size + l)]);
      defined_line(x, sign, cubic, long_filter && k >= 3, update && l > 0 && l + 1 < size, long_filter);
    }
  };
  if (forward) {
    for (int k = 1; k <= steps; ++k) pass(k, true, -1), pass(k, false, -1);
  } else {
    for (int k = steps; k >= 1; --k) pass(k, false, +1), pass(k, true, +1);
  }
}

TEST(Wavelet, EqualsTheDefinitionBitForBit) {
  // Quantized-size values (the 32-bit lanes), then any int32 (garbage of a corrupt stream: the 64-bit
  // fallback, wrap-around included), then a mix (lines of both kinds in one pass).
  // 2^18: kCubicLong's 32-bit lanes too (they take samples below 2^19).
  for (int range : {1 << 18, 1 << 20, (1 << 26) - 1, 2147483647}) {
    for (bool update : {false, true}) {
      for (auto filter : kFilters) {
        for (int level = 0; level <= 6; ++level) {
          for (int steps = 0; steps <= level; ++steps) {
            const auto seed = static_cast<std::uint32_t>(level * 131 + steps * 7 + update);
            auto g = random_grid(level, seed, range);
            if (range == 2147483647) {  // every other row small: 32-bit and 64-bit lines side by side
              const int n = (1 << level) + 1;
              for (int j = 0; j < n; j += 2)
                for (int i = 0; i < n; ++i) g[static_cast<std::size_t>(j * n + i)] >>= 12;
            }
            for (bool forward : {true, false}) {
              auto fast = g, defined = g;
              if (forward) {
                wavelet_forward(fast, level, steps, filter, update);
              } else {
                wavelet_inverse(fast, level, steps, filter, update);
              }
              defined_transform(defined, level, steps, filter, update, forward);
              ASSERT_EQ(fast, defined) << "range " << range << " update " << update << " level " << level
                                       << " steps " << steps << (forward ? " forward" : " inverse");
            }
          }
        }
      }
    }
  }
}

TEST(Wavelet, ASubGridsStepsAreTheLargerGridsSteps) {
  // FrameField::compute and the normal-mesh resampling transform the sub-grid at spacing 2^(k−1) of a grid
  // with first_step k: the result must be the larger grid's steps k, k + 1, ... (kCubicLong's prediction
  // differs by step).
  for (auto filter : kFilters) {
    for (bool update : {false, true}) {
      const int level = 7, n = 129;
      for (int first = 2; first <= 4; ++first) {
        const int s = 1 << (first - 1), sub_level = level - first + 1, m = (1 << sub_level) + 1;
        auto g = random_grid(level, static_cast<std::uint32_t>(first + 17 * update), 1 << 16);
        wavelet_forward(g, level, first - 1, filter, update);
        std::vector<std::int32_t> sub(static_cast<std::size_t>(m) * m);
        for (int j = 0; j < m; ++j)
          for (int i = 0; i < m; ++i)
            sub[static_cast<std::size_t>(j * m + i)] = g[static_cast<std::size_t>(j * s * n + i * s)];
        auto whole = g;
        wavelet_inverse(whole, level, first - 1, filter, update);
        wavelet_forward(whole, level, level, filter, update);  // every step on the whole grid
        wavelet_forward(sub, sub_level, sub_level, filter, update, first);
        for (int j = 0; j < m; ++j)
          for (int i = 0; i < m; ++i)
            ASSERT_EQ(sub[static_cast<std::size_t>(j * m + i)],
                      whole[static_cast<std::size_t>(j * s * n + i * s)])
                << "filter " << int(filter) << " first step " << first << " at " << i << "," << j;
        wavelet_inverse(sub, sub_level, sub_level, filter, update, first);
        for (int j = 0; j < m; ++j)
          for (int i = 0; i < m; ++i)
            ASSERT_EQ(sub[static_cast<std::size_t>(j * m + i)],
                      g[static_cast<std::size_t>(j * s * n + i * s)]);
      }
    }
  }
}

TEST(Wavelet, RejectsWrongSizes) {
  std::vector<std::int32_t> g(10);
  EXPECT_THROW(wavelet_forward(g, 2, 1, WaveletFilter::kCubic), std::invalid_argument);
  std::vector<std::int32_t> h(25);
  EXPECT_THROW(wavelet_forward(h, 2, 3, WaveletFilter::kCubic), std::invalid_argument);
  EXPECT_NO_THROW(wavelet_forward(h, 2, 2, WaveletFilter::kCubic));
  EXPECT_THROW(wavelet_forward(h, 2, 2, WaveletFilter::kCubic, false, 0), std::invalid_argument);
}

}  // namespace
}  // namespace geomip::codec
