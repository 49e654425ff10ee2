#include "codec/wavelet.h"

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace geomip::codec {
namespace {

using I64 = std::int64_t;

/// The prediction of odd sample t (between evens t and t+1) of a line whose evens are e(0..E−1), as taps:
/// (Σ w_k · e(at_k) + round) >> shift (arithmetic shift: floor division). Linear: (e(t) + e(t+1) + 1) >> 1;
/// cubic (E ≥ 4): (−e(t−1) + 9 e(t) + 9 e(t+1) − e(t+2) + 8) >> 4 inside, the one-sided cubic at the ends.
struct Taps {
  int at[4];
  I64 w[4];
  I64 round;
  int shift;
};

Taps taps(int t, int num_evens, bool cubic) {
  if (!cubic || num_evens < 4) return {{t, t + 1, t, t}, {1, 1, 0, 0}, 1, 1};
  if (t == 0) return {{0, 1, 2, 3}, {5, 15, -5, 1}, 8, 4};
  if (t == num_evens - 2)
    return {{num_evens - 1, num_evens - 2, num_evens - 3, num_evens - 4}, {5, 15, -5, 1}, 8, 4};
  return {{t - 1, t, t + 1, t + 2}, {-1, 9, 9, -1}, 8, 4};
}

inline std::int32_t wrap(I64 v) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
}

/// One pass of one step. `rows` = true: the row pass (lines along i); false: the column pass.
/// sign = −1: forward (subtract the prediction), +1: inverse (add it). The taps of each odd position are
/// chosen once per pass, so the inner loops have no branches.
void predict_pass(std::int32_t* g, int size, int s, bool rows, bool cubic, int sign) {
  const int intervals = (size - 1) / s;  // of the current grid along a line
  const int num_evens = intervals / 2 + 1;
  const int num_odds = intervals / 2;
  if (rows) {
    std::vector<Taps> all(static_cast<std::size_t>(num_odds));
    for (int t = 0; t < num_odds; ++t) all[static_cast<std::size_t>(t)] = taps(t, num_evens, cubic);
    const std::ptrdiff_t step = 2 * static_cast<std::ptrdiff_t>(s);
    const bool interior =
        cubic && num_evens >= 4;  // then taps(t) for 0 < t < num_odds − 1 are (−1, 9, 9, −1)
    for (int j = 0; j < size; j += s) {
      std::int32_t* row = g + static_cast<std::ptrdiff_t>(j) * size;
      int t = 0;
      const auto general = [&] {
        const Taps& p = all[static_cast<std::size_t>(t)];
        const I64 sum = p.w[0] * row[p.at[0] * step] + p.w[1] * row[p.at[1] * step] +
                        p.w[2] * row[p.at[2] * step] + p.w[3] * row[p.at[3] * step];
        std::int32_t& x = row[(2 * t + 1) * s];
        x = wrap(x + sign * ((sum + p.round) >> p.shift));
      };
      if (interior) {
        general();  // t = 0
        // Cubic interior, t = 1 .. num_odds − 2: constant weights.
        for (t = 1; t + 1 < num_odds; ++t) {
          const std::int32_t* e = row + (t - 1) * step;
          const I64 sum = 9 * (static_cast<I64>(e[step]) + e[2 * step]) - e[0] - e[3 * step];
          std::int32_t& x = row[(2 * t + 1) * s];
          x = wrap(x + sign * ((sum + 8) >> 4));
        }
      }
      for (; t < num_odds; ++t) general();
    }
  } else {
    // Column pass, row-major friendly: for each odd row, all columns of the current grid at once.
    const std::ptrdiff_t line = static_cast<std::ptrdiff_t>(size);
    for (int t = 0; t < num_odds; ++t) {
      const Taps p = taps(t, num_evens, cubic);
      std::int32_t* odd = g + static_cast<std::ptrdiff_t>(2 * t + 1) * s * line;
      const std::int32_t* r[4];
      for (int k = 0; k < 4; ++k) r[k] = g + static_cast<std::ptrdiff_t>(2 * p.at[k]) * s * line;
      if (cubic && num_evens >= 4 && t > 0 && t + 1 < num_odds) {
        for (int i = 0; i < size; i += s) {
          const I64 sum = 9 * (static_cast<I64>(r[1][i]) + r[2][i]) - r[0][i] - r[3][i];
          odd[i] = wrap(odd[i] + sign * ((sum + 8) >> 4));
        }
        continue;
      }
      for (int i = 0; i < size; i += s) {
        const I64 sum = p.w[0] * r[0][i] + p.w[1] * r[1][i] + p.w[2] * r[2][i] + p.w[3] * r[3][i];
        odd[i] = wrap(odd[i] + sign * ((sum + p.round) >> p.shift));
      }
    }
  }
}

/// ⌊(a + b + 2) / 4⌋ for any int32 a, b, exactly, in 32-bit arithmetic (no overflow: each quarter is below
/// 2^29 in magnitude), so the loops below vectorize.
inline std::int32_t quarter_sum(std::int32_t a, std::int32_t b) {
  return (a >> 2) + (b >> 2) + (((a & 3) + (b & 3) + 2) >> 2);
}

/// e ± u modulo 2^32 (as wrap() of the 64-bit sum).
template <int kSign>
inline std::int32_t add_wrapped(std::int32_t e, std::int32_t u) {
  const auto ue = static_cast<std::uint32_t>(e), uu = static_cast<std::uint32_t>(u);
  return static_cast<std::int32_t>(kSign > 0 ? ue + uu : ue - uu);
}

/// The update step of one line: every even sample strictly inside the line gets ⌊(d_left + d_right + 2) / 4⌋
/// of its two neighbouring details added (kSign +1, forward) or subtracted (−1, inverse).
template <int kSign>
void update_row(std::int32_t* row, int size, int s) {
  const int num_evens = (size - 1) / s / 2 + 1;
  for (int t = 1; t + 1 < num_evens; ++t) {
    std::int32_t& e = row[2 * t * s];
    e = add_wrapped<kSign>(e, quarter_sum(row[(2 * t - 1) * s], row[(2 * t + 1) * s]));
  }
}

/// The update step of the column pass, row-major friendly: for each even row strictly inside, all interior
/// columns of the current grid at once (contiguous at s = 1, the finest and largest step).
template <int kSign>
void update_columns(std::int32_t* g, int size, int s) {
  const int num_evens = (size - 1) / s / 2 + 1;
  const std::ptrdiff_t line = static_cast<std::ptrdiff_t>(size) * s;
  for (int t = 1; t + 1 < num_evens; ++t) {
    std::int32_t* __restrict e = g + 2 * t * line;
    const std::int32_t* __restrict a = e - line;
    const std::int32_t* __restrict b = e + line;
    if (s == 1) {
      for (int i = 1; i + 1 < size; ++i) e[i] = add_wrapped<kSign>(e[i], quarter_sum(a[i], b[i]));
    } else {
      for (int i = s; i + 1 < size; i += s) e[i] = add_wrapped<kSign>(e[i], quarter_sum(a[i], b[i]));
    }
  }
}

template <int kSign>
void update_pass(std::int32_t* g, int size, int s, bool rows) {
  if (!rows) return update_columns<kSign>(g, size, s);
  for (int j = s; j + 1 < size; j += s) update_row<kSign>(g + static_cast<std::ptrdiff_t>(j) * size, size, s);
}

/// One pass of one step with the optional update on interior lines (border rows and columns are left to the
/// prediction alone, so a border line's coefficients still depend only on that line). Forward (sign −1):
/// predict, then update; inverse (+1): undo the update, then the prediction.
void pass(std::int32_t* g, int size, int s, bool rows, bool cubic, int sign, bool update) {
  if (update && sign > 0) update_pass<-1>(g, size, s, rows);
  predict_pass(g, size, s, rows, cubic, sign);
  if (update && sign < 0) update_pass<+1>(g, size, s, rows);
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

void wavelet_forward(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter, bool update) {
  check(grid, level, steps, "wavelet_forward");
  const int size = (1 << level) + 1;
  const bool cubic = filter == WaveletFilter::kCubic;
  for (int k = 1; k <= steps; ++k) {
    const int s = 1 << (k - 1);
    pass(grid.data(), size, s, true, cubic, -1, update);
    pass(grid.data(), size, s, false, cubic, -1, update);
  }
}

void wavelet_inverse(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter, bool update) {
  check(grid, level, steps, "wavelet_inverse");
  const int size = (1 << level) + 1;
  const bool cubic = filter == WaveletFilter::kCubic;
  for (int k = steps; k >= 1; --k) {
    const int s = 1 << (k - 1);
    pass(grid.data(), size, s, false, cubic, +1, update);
    pass(grid.data(), size, s, true, cubic, +1, update);
  }
}

}  // namespace geomip::codec
