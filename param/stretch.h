// clang-format off
// Geometric stretch of a piecewise-linear parameterization (Sander, Snyder, Gortler, Hoppe 2001, "Texture
// mapping progressive meshes", §3 and §4), the distortion metric that section 3.3.2 of the
// consistent-parameterization paper minimizes (see stretch_optimization.h).
//
// For a triangle T with parameter corners p_i = (s_i, t_i) and 3D corners q_i, the affine map S: (s,t) → R³
// has the Jacobian [S_s S_t] (Sander 2001 §3):
//   A   = ((s2−s1)(t3−t1) − (s3−s1)(t2−t1)) / 2          signed parametric area
//   S_s = (q1(t2−t3) + q2(t3−t1) + q3(t1−t2)) / (2A)
//   S_t = (q1(s3−s2) + q2(s1−s3) + q3(s2−s1)) / (2A)
//   a = S_s·S_s,  b = S_s·S_t,  c = S_t·S_t
//   Γ = sqrt(((a+c) + sqrt((a−c)² + 4b²)) / 2)          largest singular value (longest image of a unit uv step)
//   γ = sqrt(((a+c) − sqrt((a−c)² + 4b²)) / 2)          smallest singular value
//   L2(T) = sqrt((Γ² + γ²) / 2) = sqrt((a+c) / 2),   L∞(T) = Γ.
// Stretch is a length ratio: 3D units per parameter unit. It is 1 for an isometry, 1/s when the uv triangle
// is scaled by s, and +∞ for a flipped or degenerate uv triangle (A <= 0).
// clang-format on
#pragma once

#include "mesh/predicates.h"  // signed_double_area, orient2d

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace geomip {

/// L2 (root-mean-square over directions) and L∞ (worst direction) stretch; dimensionless once normalized.
struct StretchValues {
  double l2 = 0;
  double linf = 0;
};

/// Stretch of one triangle (Sander 2001 §3): 3D corners `q[0..2]` (any units), parameter corners `p[0..2]`
/// (counter-clockwise = positive area). Returns L2 = sqrt((Γ²+γ²)/2) and L∞ = Γ, in 3D units per uv unit.
/// Returns {+inf, +inf} if the signed uv area is <= 0 (flipped or degenerate). Never throws.
StretchValues triangle_stretch(const Eigen::Vector3d q[3], const Eigen::Vector2d p[3]);

/// Mesh stretch (Sander 2001 §4), with A3(T) the 3D area and A2(T) the uv area of triangle T:
///
///     L2(M)  = sqrt(Σ L2(T)² A3(T) / Σ A3(T)) · N
///     L∞(M)  = max_T L∞(T) · N
///     N      = sqrt(Σ A2(T) / Σ A3(T))
///
/// The normalization N makes both values invariant to scaling uv and to scaling the 3D positions, so that an
/// isometry up to scale gives exactly 1, and every other embedding gives more (L2 ≥ 1 by Cauchy–Schwarz,
/// since Γγ = A3/A2; L∞ ≥ L2). Triangles with zero 3D area contribute nothing to L2.
///
/// \param positions  #V 3D positions (any units)
/// \param triangles  #F triangles, indices into positions and uv
/// \param uv         #V parameter coordinates
/// \return {+inf, +inf} if any triangle has uv signed area <= 0.
/// \throw InvalidInput if uv.size() != positions.size(), an index is out of range, there are no triangles
///        or the total 3D area is zero.
StretchValues mesh_stretch(const std::vector<Eigen::Vector3d>& positions,
                           const std::vector<std::array<int, 3>>& triangles,
                           const std::vector<Eigen::Vector2d>& uv);

/// Number of triangles whose uv signed area is <= 0 (flipped or degenerate); 0 for an embedding whose
/// triangles are all counter-clockwise in uv.
/// \throw InvalidInput if an index is out of range of `uv`.
std::size_t count_flipped(const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Eigen::Vector2d>& uv);

}  // namespace geomip
