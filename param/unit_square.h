// The unit square every patch is parameterized over, and the one convention for its corners and sides that
// param/, gimage/ and tools/ share (codec/ repeats the grid-index part in codec/geometry_codec.h's PatchSeam,
// because it depends on nothing of geomip).
//
// Corner k (k = 0..3, counter-clockwise): (0,0), (1,0), (1,1), (0,1). Side k runs from corner k to corner
// k+1 mod 4, so walking the sides in order goes once around the square counter-clockwise. On a
// (last+1)² grid, sample k of side s (k = 0 at corner s, k = last at corner s+1) is
//   s = 0: (i, j) = (k, 0);  s = 1: (last, k);  s = 2: (last − k, last);  s = 3: (0, last − k).
#pragma once

#include <Eigen/Core>

#include <array>
#include <utility>

namespace geomip {

/// Corner k of the unit square.
inline const std::array<Eigen::Vector2d, 4>& unit_square_corners() {
  static const std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                                         Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)};
  return corners;
}

/// The point at parameter t ∈ [0, 1] along side `side` (t = 0 at corner side, 1 at corner side+1).
inline Eigen::Vector2d point_on_side(int side, double t) {
  switch (side & 3) {
    case 0: return {t, 0.0};
    case 1: return {1.0, t};
    case 2: return {1.0 - t, 1.0};
    default: return {0.0, 1.0 - t};
  }
}

/// The parameter along side `side` of a point on it (the inverse of point_on_side()).
inline double position_on_side(const Eigen::Vector2d& uv, int side) {
  switch (side & 3) {
    case 0: return uv.x();
    case 1: return uv.y();
    case 2: return 1.0 - uv.x();
    default: return 1.0 - uv.y();
  }
}

/// Grid index (i, j) of sample k ∈ [0, last] along side `side` of a (last+1)² grid (see the file comment).
/// The same map serves cells: a row of `cells` cells along a side is a grid with last = cells − 1.
inline std::pair<int, int> side_grid_index(int side, int k, int last) {
  switch (side & 3) {
    case 0: return {k, 0};
    case 1: return {last, k};
    case 2: return {last - k, last};
    default: return {0, last - k};
  }
}

/// The inverse of side_grid_index(): the position k along side `side` of grid index (i, j) on that side.
inline int side_grid_position(int side, int i, int j, int last) {
  switch (side & 3) {
    case 0: return i;
    case 1: return j;
    case 2: return last - i;
    default: return last - j;
  }
}

}  // namespace geomip
