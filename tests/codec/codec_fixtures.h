// Synthetic two-patch closed surfaces for the codec tests and benchmark (no mesh library needed).
#pragma once

#include <cmath>
#include <vector>

#include "codec/geometry_codec.h"

namespace geomip::codec::testing {

/// A bumpy ellipsoid as two (2^level+1)² geometry images glued along all four sides (the classic two-patch
/// layout: patch 1 is patch 0 mirrored in i with z negated). Every shared sample is bit-identical in both
/// patches. `seams` gets the 8 side links (both directions), all reversed.
inline std::vector<Grid3> two_patch_surface(int level, std::vector<PatchSeam>& seams, double bumps = 0.05) {
  const int m = 1 << level, n = m + 1;
  std::vector<Grid3> patches(2);
  for (auto& g : patches) {
    g.level = level;
    g.values.resize(3 * static_cast<std::size_t>(n) * n);
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * i / m - 1, v = 2.0 * j / m - 1;
      const double r = std::max(std::abs(u), std::abs(v)), len = std::hypot(u, v);
      const double x = len > 0 ? u * r / len : 0, y = len > 0 ? v * r / len : 0;
      const bool boundary = i == 0 || j == 0 || i == m || j == m;
      const double z = boundary ? 0.0 : std::sqrt(std::max(0.0, 1 - x * x - y * y));
      for (int p = 0; p < 2; ++p) {
        const double zz = p == 0 ? z : -z;
        const double s = 1 + bumps * std::sin(5 * x + 1) * std::cos(4 * y) * std::cos(3 * zz);
        float* out = patches[p].values.data() + 3 * (static_cast<std::size_t>(j) * n + (p == 0 ? i : m - i));
        out[0] = static_cast<float>(1.5 * x * s + 0.25);
        out[1] = static_cast<float>(y * s - 0.5);
        out[2] = static_cast<float>(0.8 * zz * s);
        if (boundary) out[2] = static_cast<float>(0.0);
      }
    }
  }
  seams = {{0, 0, 1, 0, true}, {0, 1, 1, 3, true}, {0, 2, 1, 2, true}, {0, 3, 1, 1, true},
           {1, 0, 0, 0, true}, {1, 1, 0, 3, true}, {1, 2, 0, 2, true}, {1, 3, 0, 1, true}};
  return patches;
}

/// Grid index of parameter k of side s (PatchSeam's convention).
inline int side_sample(int level, int side, int k) {
  const int m = 1 << level, n = m + 1;
  switch (side) {
    case 0:
      return k;
    case 1:
      return k * n + m;
    case 2:
      return m * n + (m - k);
    default:
      return (m - k) * n;
  }
}

}  // namespace geomip::codec::testing
