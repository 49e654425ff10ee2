#include "codec/wavelet.h"

#include <cstddef>
#include <stdexcept>
#include <string>

namespace geomip::codec {
namespace {

using I64 = std::int64_t;

/// Prediction of odd sample t (between evens t and t+1) of a line whose evens are e(0..E−1).
template <typename Even>
inline I64 predict(const Even& e, int t, int num_evens, bool cubic) {
  if (!cubic || num_evens < 4) return (e(t) + e(t + 1) + 1) >> 1;
  I64 sum;
  if (t == 0) {
    sum = 5 * e(0) + 15 * e(1) - 5 * e(2) + e(3);
  } else if (t == num_evens - 2) {
    sum = 5 * e(num_evens - 1) + 15 * e(num_evens - 2) - 5 * e(num_evens - 3) + e(num_evens - 4);
  } else {
    sum = -e(t - 1) + 9 * (e(t) + e(t + 1)) - e(t + 2);
  }
  return (sum + 8) >> 4;  // arithmetic shift: floor division
}

inline std::int32_t wrap(I64 v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
}

/// One pass of one step. `rows` = true: the row pass (lines along i); false: the column pass.
/// sign = −1: forward (subtract the prediction), +1: inverse (add it).
void pass(std::int32_t* g, int size, int s, bool rows, bool cubic, int sign) {
  const int intervals = (size - 1) / s;  // of the current grid along a line
  const int num_evens = intervals / 2 + 1;
  const int num_odds = intervals / 2;
  if (rows) {
    for (int j = 0; j < size; j += s) {
      std::int32_t* row = g + static_cast<std::ptrdiff_t>(j) * size;
      auto e = [&](int u) { return static_cast<I64>(row[2 * u * s]); };
      for (int t = 0; t < num_odds; ++t) {
        std::int32_t& x = row[(2 * t + 1) * s];
        x = wrap(x + sign * predict(e, t, num_evens, cubic));
      }
    }
  } else {
    // Column pass, row-major friendly: for each odd row, all columns of the current grid at once.
    const std::ptrdiff_t line = static_cast<std::ptrdiff_t>(size);
    for (int t = 0; t < num_odds; ++t) {
      std::int32_t* odd = g + static_cast<std::ptrdiff_t>(2 * t + 1) * s * line;
      for (int i = 0; i < size; i += s) {
        auto e = [&](int u) {
          return static_cast<I64>(g[static_cast<std::ptrdiff_t>(2 * u) * s * line + i]);
        };
        odd[i] = wrap(odd[i] + sign * predict(e, t, num_evens, cubic));
      }
    }
  }
}

void check(std::span<std::int32_t> grid, int level, int steps, const char* who) {
  if (level < 0 || level > 15 || steps < 0 || steps > level) {
    throw std::invalid_argument(std::string(who) + ": level " + std::to_string(level) + " / steps " +
                                std::to_string(steps) + " out of range");
  }
  const std::size_t size = (std::size_t{1} << level) + 1;
  if (grid.size() != size * size) {
    throw std::invalid_argument(std::string(who) + ": grid has " + std::to_string(grid.size()) +
                                " samples, expected " + std::to_string(size * size));
  }
}

}  // namespace

void wavelet_forward(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter) {
  check(grid, level, steps, "wavelet_forward");
  const int size = (1 << level) + 1;
  const bool cubic = filter == WaveletFilter::kCubic;
  for (int k = 1; k <= steps; ++k) {
    const int s = 1 << (k - 1);
    pass(grid.data(), size, s, true, cubic, -1);
    pass(grid.data(), size, s, false, cubic, -1);
  }
}

void wavelet_inverse(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter) {
  check(grid, level, steps, "wavelet_inverse");
  const int size = (1 << level) + 1;
  const bool cubic = filter == WaveletFilter::kCubic;
  for (int k = steps; k >= 1; --k) {
    const int s = 1 << (k - 1);
    pass(grid.data(), size, s, false, cubic, +1);
    pass(grid.data(), size, s, true, cubic, +1);
  }
}

}  // namespace geomip::codec
