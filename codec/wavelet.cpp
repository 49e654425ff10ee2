#include "codec/wavelet.h"

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>

namespace geomip::codec {
namespace {

using I64 = std::int64_t;

/// The prediction of odd sample t (between evens t and t+1) of a line whose evens are e(0..E−1): which evens
/// it reads (at) and with which weights (kind). Linear: (e(t) + e(t+1) + 1) >> 1; cubic (E ≥ 4):
/// (−e(t−1) + 9 e(t) + 9 e(t+1) − e(t+2) + 8) >> 4 inside, the one-sided (5 e(0) + 15 e(1) − 5 e(2) + e(3) +
/// 8) >> 4 at the ends (mirrored at the far end). Arithmetic shifts: floor division.
struct Taps {
  enum Kind { kLinear, kOneSided, kInterior, kSixPoint } kind;
  int at[6];
};

/// What one step does (WaveletFilter and the step's index): its prediction and its update.
struct StepKind {
  bool cubic = true;  ///< 4-point prediction (else linear)
  bool six = false;   ///< 6-point prediction at odds with two evens on each side (kCubicLong, spacing ≥ 4)
  int update = 0;     ///< 0: none, 2: the 2-tap update, 4: the 4-tap update where it fits (kCubicLong)
};

Taps taps(int t, int num_evens, const StepKind& kind) {
  if (!kind.cubic || num_evens < 4) return {Taps::kLinear, {t, t + 1, t, t, t, t}};
  if (kind.six && t >= 2 && t + 3 < num_evens)
    return {Taps::kSixPoint, {t - 2, t - 1, t, t + 1, t + 2, t + 3}};
  if (t == 0) return {Taps::kOneSided, {0, 1, 2, 3, 3, 3}};
  if (t == num_evens - 2)
    return {Taps::kOneSided, {num_evens - 1, num_evens - 2, num_evens - 3, num_evens - 4, 0, 0}};
  return {Taps::kInterior, {t - 1, t, t + 1, t + 2, t + 2, t + 2}};
}

// Speed (issue #16): every pass runs on contiguous memory (a row's evens and odds split into two buffers; the
// column pass across whole rows; the coarser steps on a gathered copy of their sub-grid), in 32-bit lanes
// that the compiler vectorizes. A step runs in 32 bits when every sample of its grid lies in [−2^23, 2^23)
// when it starts: then no intermediate value of the step exceeds 5.2·2^23 in magnitude (an update adds at
// most half the largest detail, a prediction 26/16 of the largest even), so no weighted sum (at most 26 times
// an even) and no update sum reaches 2^31. Otherwise (garbage coefficients of a corrupt stream) the step
// takes 64-bit sums. The results are the same either way: the header's 64-bit definition, stored modulo 2^32.
// kCubicLong's steps (a 6-point sum reaches 356 times an even, the 4-tap update adds up to 0.625 of the
// largest detail) run in 32 bits when every sample lies in [−2^19, 2^19): a forward step then keeps every
// value below 7·2^19 and every sum below 940·2^19, an inverse step below 6·2^19 and 2,100·2^19 < 2^31.

/// True when every v[i] lies in [−2^bits, 2^bits).
bool fits_32(const std::int32_t* v, std::size_t n, int bits) {
  std::uint32_t out = 0;
  for (std::size_t i = 0; i < n; ++i) out |= (static_cast<std::uint32_t>(v[i]) + (1u << bits)) >> (bits + 1);
  return out == 0;
}

/// x ± d modulo 2^32 (kSign +1 / −1): the 64-bit x ± d stored back as int32.
template <int kSign>
inline std::int32_t add_wrapped(std::int32_t x, std::uint32_t d) {
  const auto ux = static_cast<std::uint32_t>(x);
  return static_cast<std::int32_t>(kSign > 0 ? ux + d : ux - d);
}

/// The update term ⌊(a + b + 2) / 4⌋ (T int32 only within a 32-bit step, where a + b + 2 cannot overflow).
template <typename T>
inline std::uint32_t quarter_sum(std::int32_t a, std::int32_t b) {
  return static_cast<std::uint32_t>((T{a} + T{b} + 2) >> 2);
}

/// The 4-tap update term ⌊(9(b + c) − a − d + 16) / 32⌋ of the details a, b | c, d around an even.
template <typename T>
inline std::uint32_t update4_sum(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
  return static_cast<std::uint32_t>((9 * (T{b} + T{c}) - T{a} - T{d} + 16) >> 5);
}

/// The update of the evens 1..m−1 of a line (details o[0..m−1]) by ± its update term.
template <typename T, int kSign>
void update_line(std::int32_t* __restrict e, const std::int32_t* __restrict o, int m, int update) {
  if (update == 4 && m >= 4) {
    e[1] = add_wrapped<kSign>(e[1], quarter_sum<T>(o[0], o[1]));
    for (int t = 2; t + 1 < m; ++t)
      e[t] = add_wrapped<kSign>(e[t], update4_sum<T>(o[t - 2], o[t - 1], o[t], o[t + 1]));
    e[m - 1] = add_wrapped<kSign>(e[m - 1], quarter_sum<T>(o[m - 2], o[m - 1]));
    return;
  }
  for (int t = 1; t < m; ++t) e[t] = add_wrapped<kSign>(e[t], quarter_sum<T>(o[t - 1], o[t]));
}

/// The prediction step of one line with its m + 1 evens e and m odds o in separate contiguous buffers
/// (kSign −1: forward, subtract; +1: inverse, add).
template <typename T, int kSign>
void predict_line(std::int32_t* __restrict o, const std::int32_t* __restrict e, int m, const StepKind& kind) {
  if (!kind.cubic || m + 1 < 4) {
    for (int t = 0; t < m; ++t)
      o[t] = add_wrapped<kSign>(o[t], static_cast<std::uint32_t>((T{e[t]} + T{e[t + 1]} + 1) >> 1));
    return;
  }
  const auto one_sided = [](T a, T b, T c, T d) { return (5 * a + 15 * b - 5 * c + d + 8) >> 4; };
  o[0] = add_wrapped<kSign>(o[0], static_cast<std::uint32_t>(one_sided(e[0], e[1], e[2], e[3])));
  const auto four = [&](int t) {  // (−1, 9, 9, −1)
    const T sum = 9 * (T{e[t]} + T{e[t + 1]}) - T{e[t - 1]} - T{e[t + 2]};
    o[t] = add_wrapped<kSign>(o[t], static_cast<std::uint32_t>((sum + 8) >> 4));
  };
  if (kind.six && m + 1 >= 6) {  // the 4-point prediction at t = 1 and m − 2, the 6-point one between
    four(1);
    for (int t = 2; t + 3 <= m; ++t) {
      const T sum =
          150 * (T{e[t]} + T{e[t + 1]}) - 25 * (T{e[t - 1]} + T{e[t + 2]}) + 3 * (T{e[t - 2]} + T{e[t + 3]});
      o[t] = add_wrapped<kSign>(o[t], static_cast<std::uint32_t>((sum + 128) >> 8));
    }
    four(m - 2);
  } else {
    for (int t = 1; t + 1 < m; ++t) four(t);
  }
  o[m - 1] =
      add_wrapped<kSign>(o[m - 1], static_cast<std::uint32_t>(one_sided(e[m], e[m - 1], e[m - 2], e[m - 3])));
}

/// The prediction of a whole odd row from the even rows r[k] = row at[k] of taps p, n columns.
template <typename T, int kSign>
void predict_rows(std::int32_t* __restrict o, const std::int32_t* const r[6], const Taps& p, int n) {
  const std::int32_t* __restrict a = r[0];
  const std::int32_t* __restrict b = r[1];
  const std::int32_t* __restrict c = r[2];
  const std::int32_t* __restrict d = r[3];
  if (p.kind == Taps::kSixPoint) {  // (3, −25, 150, 150, −25, 3)
    const std::int32_t* __restrict x = r[4];
    const std::int32_t* __restrict y = r[5];
    for (int i = 0; i < n; ++i) {
      const T sum = 150 * (T{c[i]} + T{d[i]}) - 25 * (T{b[i]} + T{x[i]}) + 3 * (T{a[i]} + T{y[i]});
      o[i] = add_wrapped<kSign>(o[i], static_cast<std::uint32_t>((sum + 128) >> 8));
    }
  } else if (p.kind == Taps::kInterior) {  // (−1, 9, 9, −1)
    for (int i = 0; i < n; ++i) {
      const T sum = 9 * (T{b[i]} + T{c[i]}) - T{a[i]} - T{d[i]};
      o[i] = add_wrapped<kSign>(o[i], static_cast<std::uint32_t>((sum + 8) >> 4));
    }
  } else if (p.kind == Taps::kLinear) {  // (1, 1) / 2 of a and b
    for (int i = 0; i < n; ++i)
      o[i] = add_wrapped<kSign>(o[i], static_cast<std::uint32_t>((T{a[i]} + T{b[i]} + 1) >> 1));
  } else {  // the one-sided cubic (5, 15, −5, 1)
    for (int i = 0; i < n; ++i) {
      const T sum = 5 * T{a[i]} + 15 * T{b[i]} - 5 * T{c[i]} + T{d[i]};
      o[i] = add_wrapped<kSign>(o[i], static_cast<std::uint32_t>((sum + 8) >> 4));
    }
  }
}

/// Scratch of one transform: a line's evens and odds, and a gathered sub-grid for the steps at spacing ≥ 2
/// (left uninitialized: every entry is written before it is read).
struct Scratch {
  std::unique_ptr<std::int32_t[]> evens, odds, sub;
};

/// The row pass of one step on an n × n grid at unit spacing (n = 2m + 1), with the update on interior rows.
/// kSign −1: forward (predict, then update); +1: inverse (undo the update, then the prediction).
template <typename T, int kSign>
void row_pass(std::int32_t* g, int n, const StepKind& kind, Scratch& s) {
  const int m = n / 2;
  std::int32_t* __restrict e = s.evens.get();
  std::int32_t* __restrict o = s.odds.get();
  for (int j = 0; j < n; ++j) {
    std::int32_t* __restrict row = g + static_cast<std::ptrdiff_t>(j) * n;
    for (int t = 0; t < m; ++t) e[t] = row[2 * t], o[t] = row[2 * t + 1];
    e[m] = row[2 * m];
    const bool updated = kind.update != 0 && j > 0 && j + 1 < n;
    if (updated && kSign > 0) update_line<T, -1>(e, o, m, kind.update);
    predict_line<T, kSign>(o, e, m, kind);
    if (updated && kSign < 0) update_line<T, +1>(e, o, m, kind.update);
    for (int t = 0; t < m; ++t) row[2 * t] = e[t], row[2 * t + 1] = o[t];
  }
}

/// The update of the column pass: every even row strictly inside, at its interior columns, ± a quarter of
/// the odd rows around it.
template <typename T, int kSign>
void update_columns(std::int32_t* g, int n, int update) {
  const int m = n / 2;
  for (int t = 1; t < m; ++t) {
    std::int32_t* __restrict e = g + static_cast<std::ptrdiff_t>(2 * t) * n;
    const std::int32_t* __restrict a = e - n;
    const std::int32_t* __restrict b = e + n;
    if (update == 4 && t >= 2 && t + 2 <= m) {  // the 4-tap update (as update_line())
      const std::int32_t* __restrict a2 = e - 3 * n;
      const std::int32_t* __restrict b2 = e + 3 * n;
      for (int i = 1; i + 1 < n; ++i)
        e[i] = add_wrapped<kSign>(e[i], update4_sum<T>(a2[i], a[i], b[i], b2[i]));
    } else {
      for (int i = 1; i + 1 < n; ++i) e[i] = add_wrapped<kSign>(e[i], quarter_sum<T>(a[i], b[i]));
    }
  }
}

/// The column pass of one step on an n × n grid at unit spacing, whole rows at a time.
template <typename T, int kSign>
void column_pass(std::int32_t* g, int n, const StepKind& kind) {
  const int m = n / 2;
  if (kind.update != 0 && kSign > 0) update_columns<T, -1>(g, n, kind.update);
  for (int t = 0; t < m; ++t) {
    const Taps p = taps(t, m + 1, kind);
    const std::int32_t* r[6];
    for (int k = 0; k < 6; ++k) r[k] = g + static_cast<std::ptrdiff_t>(2 * p.at[k]) * n;
    predict_rows<T, kSign>(g + static_cast<std::ptrdiff_t>(2 * t + 1) * n, r, p, n);
  }
  if (kind.update != 0 && kSign < 0) update_columns<T, +1>(g, n, kind.update);
}

/// One step on an n × n grid at unit spacing: forward (kSign −1: rows, then columns) or inverse (+1:
/// columns, then rows).
template <typename T, int kSign>
void unit_step(std::int32_t* w, int n, const StepKind& kind, Scratch& scratch) {
  if (kSign < 0) row_pass<T, kSign>(w, n, kind, scratch);
  column_pass<T, kSign>(w, n, kind);
  if (kSign > 0) row_pass<T, kSign>(w, n, kind, scratch);
}

/// Copies the samples at multiples of s (n × n of them) of the size × size grid g to w (`to_sub`) or back.
template <bool kToSub>
void copy_sub(std::int32_t* g, int size, int s, std::int32_t* w, int n) {
  for (int y = 0; y < n; ++y) {
    std::int32_t* line = g + static_cast<std::ptrdiff_t>(y) * s * size;
    std::int32_t* sub = w + static_cast<std::ptrdiff_t>(y) * n;
    if (s == 2) {  // three quarters of all copies: a constant stride the compiler vectorizes
      for (int x = 0; x < n; ++x) kToSub ? void(sub[x] = line[2 * x]) : void(line[2 * x] = sub[x]);
    } else {
      for (int x = 0; x < n; ++x) {
        const auto at = static_cast<std::ptrdiff_t>(x) * s;
        kToSub ? void(sub[x] = line[at]) : void(line[at] = sub[x]);
      }
    }
  }
}

/// One step at spacing s of the (size × size) grid g (at s ≥ 2 on a gathered copy of its sub-grid).
template <int kSign>
void step(std::int32_t* g, int size, int s, const StepKind& kind, Scratch& scratch) {
  const int n = (size - 1) / s + 1;
  std::int32_t* w = g;
  if (s > 1) {
    w = scratch.sub.get();
    copy_sub<true>(g, size, s, w, n);
  }
  // The 6-point prediction and the 4-tap update grow intermediate values more (see the bound above).
  const int bits = kind.six || kind.update == 4 ? 19 : 23;
  if (fits_32(w, static_cast<std::size_t>(n) * static_cast<std::size_t>(n), bits)) {
    unit_step<std::int32_t, kSign>(w, n, kind, scratch);
  } else {
    unit_step<I64, kSign>(w, n, kind, scratch);
  }
  if (s > 1) copy_sub<false>(g, size, s, w, n);
}

Scratch make_scratch(int size, int steps) {
  Scratch s;
  const auto half = static_cast<std::size_t>(size / 2 + 1);
  s.evens.reset(new std::int32_t[half]);
  s.odds.reset(new std::int32_t[half]);
  if (steps >= 2) s.sub.reset(new std::int32_t[half * half]);
  return s;
}

/// The kind of step k (1 = finest) of a transform with `filter` and `update`.
StepKind step_kind(WaveletFilter filter, bool update, int k) {
  StepKind kind;
  kind.cubic = filter != WaveletFilter::kLinear;
  kind.six = filter == WaveletFilter::kCubicLong && k >= 3;
  kind.update = !update ? 0 : filter == WaveletFilter::kCubicLong ? 4 : 2;
  return kind;
}

void check(std::span<std::int32_t> grid, int level, int steps, int first_step, const char* who) {
  if (level < 0 || level > 15 || steps < 0 || steps > level || first_step < 1 || first_step > 16) {
    throw std::invalid_argument(std::string(who) + ": level " + std::to_string(level) + " / steps " +
                                std::to_string(steps) + " / first step " + std::to_string(first_step) +
                                " out of range");
  }
  const std::size_t size = (std::size_t{1} << level) + 1;
  if (grid.size() != size * size) {
    throw std::invalid_argument(std::string(who) + ": grid has " + std::to_string(grid.size()) +
                                " samples, expected " + std::to_string(size * size));
  }
}

}  // namespace

void wavelet_forward(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter, bool update,
                     int first_step) {
  check(grid, level, steps, first_step, "wavelet_forward");
  const int size = (1 << level) + 1;
  Scratch scratch = make_scratch(size, steps);
  for (int k = 1; k <= steps; ++k)
    step<-1>(grid.data(), size, 1 << (k - 1), step_kind(filter, update, k + first_step - 1), scratch);
}

void wavelet_inverse(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter, bool update,
                     int first_step) {
  check(grid, level, steps, first_step, "wavelet_inverse");
  const int size = (1 << level) + 1;
  Scratch scratch = make_scratch(size, steps);
  for (int k = steps; k >= 1; --k)
    step<+1>(grid.data(), size, 1 << (k - 1), step_kind(filter, update, k + first_step - 1), scratch);
}

}  // namespace geomip::codec
