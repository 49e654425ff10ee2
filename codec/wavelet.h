// Integer lifting wavelet on one channel of a (2^n+1)² grid: Deslauriers–Dubuc subdivision wavelets
// (Deslauriers & Dubuc 1989; lifting form: Sweldens 1996, "The lifting scheme"), interpolating (prediction
// only) or with an update step on interior lines, separable, exactly reversible on integers.
//
// One step at spacing s (s = 1 for the finest step, doubling each step) works on the current grid (the
// samples at multiples of s):
//   1. row pass: in every row of the current grid, each odd sample (column an odd multiple of s) is replaced
//      by d = x − P, P predicted from the even samples (multiples of 2s) of that row;
//   2. column pass: in every column of the current grid (including the columns that now hold row details),
//      each odd sample (row an odd multiple of s) is replaced by d = x − P from the even samples of the
//      column.
//   With `update` (codec header version 4), each pass is followed by an update of the same lines: every even
//   sample strictly inside an interior line (neither the line nor the sample on the grid's border) gets
//   U = floor((d_left + d_right + 2) / 4) of its two neighbouring details added — the (4, 2) biorthogonal
//   lifting of the cubic prediction (2 dual vanishing moments): the coarse band becomes a local average of the
//   finer samples instead of a subsample, so a truncated reconstruction is a smoothed fit rather than an
//   interpolant of every 2^k-th sample. The inverse subtracts U before undoing the prediction.
//   kCubicLong (codec header version 5) has the 4-tap update U = floor((9·(d_left + d_right) − d_left2 −
//   d_right2 + 16) / 32) (4 dual vanishing moments) at the evens with two details on each side, the 2-tap
//   one at the others.
// Prediction: P = floor((Σ w·e + denom/2) / denom), integer weights:
//   kLinear (order 2): (1, 1)/2 of the two neighbours;
//   kCubic (order 4): (−1, 9, 9, −1)/16 of the four nearest evens; next to an end, the one-sided cubic
//     (5, 15, −5, 1)/16 of the four evens nearest that end (mirrored exactly at the far end). Lines with
//     fewer than four evens (2 or 3) use the linear prediction.
//   kCubicLong: kCubic on the two finest steps; from step 3 on (spacing ≥ 4), the 6-point (order 6)
//     (3, −25, 150, 150, −25, 3)/256 of the six nearest evens at odds with two evens on each side, kCubic's
//     predictions at the others. Measured on the bunny, horse, venus and armadillo (docs/codec-v3.md,
//     "Longer lifting filters"): +0.16 … +0.29 dB on the mean of their pack-prefix curves.
// Properties (tested): exact reconstruction, with or without update; without it the coarse band after k steps
// is exactly the nested (2^(n−k)+1)² subsample of the input; the weights are mirror-symmetric, so
// transforming a reversed line gives the reversed coefficients; a boundary row or column's coefficients
// depend only on that row or column, with or without update (what makes seams between patches consistent);
// kLinear gives zero details on affine fields, kCubic on separable cubic polynomials (p(i) + q(j), as long as
// every line has at least four evens), with or without update (the update only adds zero details).
// Synthesis norms (unit coefficient, level 8, measured): without update row/column details ≈ 1.13·2^(k−1),
// diagonal ≈ 0.80·2^(k−1); with update ≈ 0.87·2^(k−1) and 0.47·2^(k−1); the coarse band after k steps
// ≈ 0.9·2^k either way.
//
// Detail bands of step k (s = 2^(k−1)): positions (i, j), multiples of s, not both multiples of 2s —
// (odd, even) multiples of s: row details; (even, odd): column details; (odd, odd): diagonal details.
//
// Arithmetic is defined in 64 bits and stored back modulo 2^32, so arbitrary (even garbage) coefficients never
// cause undefined behaviour; for quantized inputs of up to 2^24 no wrap-around can happen. (The implementation
// runs a step in vectorizable 32-bit lanes when its samples are small enough for that to be exact, and is
// tested bit for bit against this definition.)
#pragma once

#include <cstdint>
#include <span>

namespace geomip::codec {

enum class WaveletFilter : std::uint8_t {
  kLinear = 0,  ///< interpolating, 2-point prediction (Deslauriers–Dubuc order 2)
  kCubic = 1,   ///< interpolating, 4-point prediction (Deslauriers–Dubuc order 4)
  /// kCubic on the two finest steps, the 6-point prediction (order 6) inside the lines of coarser steps,
  /// and with the update step its 4-tap form (codec header version 5)
  kCubicLong = 2,
};

/// Forward transform of `grid` ((2^level+1)² int32, row-major: grid[j·size + i]) in place, `steps` steps
/// (0 ≤ steps ≤ level), finest first, every step with the update step when `update`. `first_step` > 1: the
/// grid is the sub-grid at spacing 2^(first_step − 1) of a larger one, and its step k is that grid's step
/// k + first_step − 1 (kCubicLong's steps differ by index). \throw std::invalid_argument on a wrong size,
/// step count or first step (outside [1, 16]).
void wavelet_forward(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter,
                     bool update = false, int first_step = 1);

/// Inverse of wavelet_forward() (same arguments), coarsest step first.
void wavelet_inverse(std::span<std::int32_t> grid, int level, int steps, WaveletFilter filter,
                     bool update = false, int first_step = 1);

}  // namespace geomip::codec
