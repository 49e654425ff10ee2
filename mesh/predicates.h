// Planar orientation in the parameter domain, and the small keys every mesh algorithm hashes edges by.
// One copy of each for the whole project: where a sign decides whether a triangle is flipped, it is the exact
// predicate orient2d(); the value forms are for areas and interpolation only.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

/// Sign of the orientation of (a, b, c): +1 counter-clockwise, −1 clockwise, 0 exactly collinear. Exact for
/// every finite input (a filtered double evaluation, then an exact expansion of the determinant's six
/// products when the filter cannot decide; Shewchuk 1997). Cost: a few flops, ~100 when nearly collinear.
int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);

/// Twice the signed area of the uv triangle (a, b, c), in floating point: positive when counter-clockwise.
/// For areas and interpolation weights; decide signs with orient2d().
inline double signed_double_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                 const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
}

/// signed_double_area() of triangle t of `uv`. \pre t's ids index `uv`.
inline double signed_uv_area2(const std::vector<Eigen::Vector2d>& uv, const std::array<int, 3>& t) {
  return signed_double_area(uv[t[0]], uv[t[1]], uv[t[2]]);
}

/// Number of triangles that are not strictly counter-clockwise in `uv` (flipped or degenerate), decided by
/// orient2d(); triangles with a negative first id (absent at a level of a progressive mesh) are skipped.
/// \pre the other ids index `uv`.
std::size_t count_flipped_triangles(const std::vector<Eigen::Vector2d>& uv,
                                    const std::vector<std::array<int, 3>>& triangles);

/// Key of the directed edge a → b (a, b ≥ 0 vertex ids): distinct for every ordered pair; hash it.
inline std::uint64_t directed_edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

/// Key of the undirected edge {a, b}: the same for (a, b) and (b, a).
inline std::uint64_t edge_key(int a, int b) { return a < b ? directed_edge_key(a, b) : directed_edge_key(b, a); }

}  // namespace geomip
