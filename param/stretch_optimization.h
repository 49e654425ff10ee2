// Stretch optimization of a parameterization with fixed connectivity: section 3.3.2 "Stretch optimization" of
// the consistent-parameterization paper, which follows Sander, Snyder, Gortler, Hoppe 2001 ("Texture mapping
// progressive meshes", §4 and §5) but replaces Sander's binary line search by bracketed parabolic
// minimization (Brent's method) along random search directions in the (s,t) domain.
//
// Local objective of a vertex v with ring R(v) (its incident triangles), for a blend weight w ∈ [0,1]:
//   E(v) = (1−w) · Σ_{T∈R} A3(T)·(Γ_T²+γ_T²)/2 / Σ_{T∈R} A3(T)  +  w · max_{T∈R} Γ_T²
// w = 0 (StretchNorm::kL2) is Sander's un-normalized L2 energy Σ A3·L2(T)² (divided by the ring's 3D area, a
// constant while v moves, so the minimizer is the same). It is deliberately *not* normalized by the
// parametric area: shrinking a uv triangle raises its stretch, so the energy also penalizes undersampling
// (Sander 2001 §4). w = 1 (StretchNorm::kLinf) minimizes the ring's largest singular value, the L∞ metric.
// All functions here return sqrt(E), a stretch (3D units per uv unit): the ring's area-weighted RMS L2
// stretch for kL2, its largest Γ for kLinf.
//
// Along a line p(t) = p + t·d every ring triangle's uv area is affine in t, and Γ²+γ² = ‖J‖_F² is a quadratic
// over the squared area (the cotangent form of the Dirichlet energy), so each line search evaluates E in
// closed form from a handful of coefficients per ring triangle, and the interval of t in which no ring
// triangle flips is known exactly: that interval (shrunk by `bracket_fraction`) is the bracket of the
// parabolic minimization.
#pragma once

#include "param/stretch.h"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <random>
#include <vector>

namespace geomip {

/// Which stretch norm the vertex optimization minimizes (see the objective E(v) at the top of this file).
enum class StretchNorm {
  kL2,    ///< w = 0: area-weighted Σ A3·(Γ²+γ²)/2 over the ring (Sander 2001, the default)
  kLinf,  ///< w = 1: max Γ² over the ring
  kBlend  ///< w = VertexOptimizationOptions::linf_weight
};

struct VertexOptimizationOptions {
  /// The norm minimized.
  StretchNorm norm = StretchNorm::kL2;
  /// Weight w of the L∞ term for StretchNorm::kBlend, in [0, 1].
  double linf_weight = 0.5;
  /// Line searches per call. The first direction has a uniformly random angle θ; direction i has angle
  /// θ + i·π/num_directions, so any two consecutive calls cover the plane evenly (2 = a random orthogonal
  /// pair).
  int num_directions = 2;
  /// Bracket of each line search: this fraction of the interval of t in which every ring triangle keeps
  /// positive uv area. Hence a step never shrinks any ring triangle's uv area below (1 − bracket_fraction) of
  /// its value before the step. In (0, 1).
  double bracket_fraction = 0.9;
  /// Largest step of one line search, relative to the longest uv edge from v to its ring (bounds the bracket
  /// when v is on an unlocked boundary, where the no-flip interval can be unbounded). > 0.
  double max_step = 1.0;
  /// Line-search tolerance in t, relative to the bracket's length. > 0.
  double tolerance = 1e-3;
  /// Function evaluations per line search at most (Brent's method usually needs 8–20).
  int max_evaluations = 40;
  /// Optional sampling weights, one per vertex (indexed like `positions`; not owned, must outlive the call):
  /// each triangle's term of the L2 energy is multiplied by the mean of its corners' weights, so the
  /// optimizer gives weighted triangles more parameter area (a signal-specialized stretch in the spirit of
  /// Sander et al. 2002; see curvature_sampling_weights()). Null = every weight 1 (Sander 2001). The L∞
  /// term is not weighted.
  const std::vector<double>* vertex_weights = nullptr;
  /// Optional metric tensors, one per vertex (indexed like `positions`; not owned): symmetric positive
  /// definite 3×3 matrices M. A triangle's 3D edge lengths and area are measured in the mean of its corners'
  /// M (|e|² = eᵀMe), so the optimizer sees each triangle as it is in that metric: with M = I + λ·D·|S|
  /// (curvature_metric_tensors()) a curved direction is longer and gets more parameter length than a flat
  /// one (anisotropic sampling). Null = the Euclidean metric.
  const std::vector<Eigen::Matrix3d>* vertex_metrics = nullptr;
};

/// Moves `uv[v]` to lower the local stretch objective E(v) (see the top of this file) of its incident
/// triangles `ring` by `options.num_directions` line minimizations (Brent's bracketed parabolic minimization)
/// along random directions drawn from `rng`. Deterministic for a given rng state. Only uv[v] is written.
///
/// Never makes any ring triangle flipped or degenerate: each candidate point is checked with the direct
/// signed-area formula and accepted only if E decreases. Returns sqrt(E) at the final position (3D units per
/// uv unit); uv[v] is unchanged if no improvement was found. If a ring triangle is already flipped or
/// degenerate, v is not moved and +inf is returned.
///
/// \param v          the vertex to move
/// \param ring       indices into `triangles` of the triangles around v (each must contain v); the energy
///                   only sees these, so pass all of v's triangles to keep the whole mesh flip-free
/// \param positions  #V 3D positions (any units)
/// \param triangles  #F triangles, counter-clockwise in uv
/// \param uv         #V parameter coordinates (uv.size() == positions.size()); only uv[v] is written
/// \param rng        source of the random directions, advanced by one draw per call
/// \throw InvalidInput if v or an index is out of range, a ring triangle does not contain v, sizes differ,
///        uv[v] is not finite or the options are invalid.
double optimize_vertex(int v, const std::vector<int>& ring, const std::vector<Eigen::Vector3d>& positions,
                       const std::vector<std::array<int, 3>>& triangles, std::vector<Eigen::Vector2d>& uv,
                       const VertexOptimizationOptions& options, std::mt19937& rng);

/// One triangle's term of the L2 energy the optimizer lowers, A3·(Γ²+γ²)/2, with its 3D lengths and area
/// measured in the metric `metric` (VertexOptimizationOptions::vertex_metrics: the mean of the corners'
/// tensors; the identity gives A3·L2² of triangle_stretch()): to compare two parameterizations of one patch
/// by what an optimization in that metric lowered. +inf for a flipped or degenerate uv triangle.
double triangle_l2_energy(const Eigen::Vector3d q[3], const Eigen::Vector2d uv[3],
                          const Eigen::Matrix3d& metric);

/// sqrt(E(v)) of the current uv (same value optimize_vertex returns), for priorities and tests.
/// \throw InvalidInput as optimize_vertex.
double local_stretch(int v, const std::vector<int>& ring, const std::vector<Eigen::Vector3d>& positions,
                     const std::vector<std::array<int, 3>>& triangles, const std::vector<Eigen::Vector2d>& uv,
                     const VertexOptimizationOptions& options);

struct StretchOptimizationOptions {
  /// Per-vertex line searches.
  VertexOptimizationOptions vertex;
  /// Stop when the largest uv displacement of any vertex during a sweep is below this (uv units; the paper's
  /// 10⁻³ assumes the unit square; scale it with the domain). With kLinf or kBlend the max term is not
  /// smooth, so vertices can keep taking sizeable steps for negligible gains and this criterion may never
  /// trigger: max_sweeps then bounds the run.
  double threshold = 1e-3;
  /// At most this many sweeps over all unlocked vertices (bounds the running time: one sweep costs
  /// O(#F · num_directions · evaluations)).
  std::size_t max_sweeps = 50;
  /// Seed of the random search directions (the result is deterministic for a given seed).
  unsigned seed = 1;
  /// Vertices whose local stretch sqrt(E(v)) (local_stretch(), in 3D units per uv unit, not normalized) is
  /// below this at the start of a sweep are not moved in that sweep; 0 = all unlocked vertices. With
  /// StretchNorm::kLinf this confines the sweeps to the rings of the triangles that set the L∞ stretch, and
  /// leaves the rest of the parameterization (and its L2 stretch) as it is.
  double min_local_stretch = 0;
  /// Record the mesh L2/L∞ stretch after every sweep in StretchOptimizationResult::per_sweep (one O(#F) pass
  /// per sweep).
  bool record_sweeps = false;
};

struct StretchOptimizationResult {
  /// mesh_stretch() of the input (normalized, see stretch.h). Euclidean even when the optimization ran in
  /// VertexOptimizationOptions::vertex_metrics, so `after` may then exceed it.
  StretchValues before;
  StretchValues after;   ///< mesh_stretch() of the output
  std::size_t sweeps = 0;
  std::size_t vertex_moves = 0;      ///< accepted vertex displacements over all sweeps
  double last_max_displacement = 0;  ///< largest uv displacement in the last sweep (uv units)
  /// Unlocked vertices never moved because their ring was flipped or degenerate.
  std::size_t skipped_vertices = 0;
  std::vector<StretchValues> per_sweep;  ///< mesh stretch after each sweep, if options.record_sweeps
};

/// Global stretch optimization (paper §3.3.2, Sander 2001 §5). Each sweep places all unlocked vertices that
/// belong to a triangle in a priority queue ordered by their local stretch sqrt(E(v)) (largest first) and
/// optimizes each in turn as optimize_vertex() does; sweeps stop when the largest uv displacement in a sweep
/// is below `options.threshold`, or after `options.max_sweeps`.
///
/// Guarantees: locked vertices are never written (bit-identical); no triangle becomes flipped or degenerate;
/// every move lowers its vertex's E. With StretchNorm::kLinf a move lowers the largest Γ of the vertex's ring,
/// and every triangle it changes is in that ring, so the largest Γ over the mesh never increases; with a
/// fixed boundary (Σ A2 constant) neither does the normalized mesh L∞ stretch. With StretchNorm::kL2 and a fixed boundary (all boundary vertices
/// locked, so the total uv area Σ A2 is constant) the normalized mesh L2 stretch therefore never increases
/// from sweep to sweep. Unlocked boundary vertices drift outward (the un-normalized energy falls as the uv
/// area grows; each step is bounded by VertexOptimizationOptions::max_step): lock the boundary for a fixed
/// domain. Vertices whose ring contains a triangle that is already flipped or degenerate are left where they
/// are (counted in skipped_vertices); `before`/`after` are then +inf (see mesh_stretch).
///
/// \param positions  #V 3D positions (any units)
/// \param triangles  #F triangles, counter-clockwise in uv
/// \param uv         #V parameter coordinates, optimized in place
/// \param locked     #V flags, nonzero = fixed (boundary, patch corners, feature points)
/// \throw InvalidInput on size mismatches, out-of-range indices, non-finite uv, invalid options, no
///        triangles or zero 3D area.
StretchOptimizationResult optimize_stretch(const std::vector<Eigen::Vector3d>& positions,
                                           const std::vector<std::array<int, 3>>& triangles,
                                           std::vector<Eigen::Vector2d>& uv, const std::vector<char>& locked,
                                           const StretchOptimizationOptions& options = {});

/// Mask (#V, 1 = on a boundary edge) of the vertices on boundary edges (edges used by exactly one triangle),
/// the usual `locked` argument of optimize_stretch() for a patch with a fixed boundary. \throw InvalidInput
/// if an index is out of range.
std::vector<char> boundary_vertex_mask(std::size_t num_vertices,
                                       const std::vector<std::array<int, 3>>& triangles);

}  // namespace geomip
