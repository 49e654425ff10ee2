// Mean value coordinates embedding of a disk with a fixed convex boundary (Floater 2003), as used for the
// initial embedding of base meshes in ../shared/seed/consistent-mesh-parameterizations.txt, section 3.3.2.
#pragma once

#include "mesh/predicates.h"  // signed_uv_area2, count_flipped_triangles (used with the embedding)

#include "mesh/mesh.h"

#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

namespace geomip {

/// A vertex id and its fixed parameter (u, v).
using FixedUv = std::pair<int, Eigen::Vector2d>;

/// Parameters of the boundary vertices of a quadrilateral patch on the unit square: side k (vertex ids from
/// corner k to corner k+1, see `PatchSides` in progressive_mesh.h) goes from (0,0)→(1,0), (1,0)→(1,1),
/// (1,1)→(0,1), (0,1)→(0,0) for k = 0..3, each vertex at its normalised chord length (cumulative 3D edge
/// length from the side's first corner divided by the side's length). One entry per boundary vertex (corners
/// once), in side order.
/// \param positions  3D positions (any unit) indexed by the ids in `sides`
/// \param metrics    optional metric tensors indexed like `positions`: chord lengths measured in them
///                   (metric_edge_length(); ParameterizationOptions::curvature_metric); null = Euclidean
/// \throw InvalidInput if a side has fewer than 2 vertices, does not end where the next begins, has an id out
///        of range, or has zero length, or if `metrics` has another size than `positions`.
std::vector<FixedUv> square_boundary_uv(const std::vector<Eigen::Vector3d>& positions,
                                        const std::array<std::vector<int>, 4>& sides,
                                        const std::vector<Eigen::Matrix3d>* metrics = nullptr);

struct MeanValueEmbeddingOptions {
  /// Upper bound on tan(α/2) in eq. (3), reached only by triangles with an angle within ~1e-6 rad of π
  /// (nearly flat in 3D). Keeps the weights finite and positive, which is all Floater's theorem needs.
  double max_half_angle_tangent = 1e6;
};

struct MeanValueEmbeddingResult {
  /// (u, v) per entry of `positions`: fixed vertices as given, free vertices referenced by a triangle solved
  /// from eq. (1), NaN for free vertices no triangle references (so a base mesh can be embedded in the
  /// patch's id space without renumbering).
  std::vector<Eigen::Vector2d> uv;
  std::size_t free_vertices = 0;  ///< number of unknowns solved for
  double residual = 0.0;          ///< max over free vertices of |u(v_i) − Σ λ_ik u(v_k)| after the solve
};

/// Solves eq. (1)–(2) with the mean value weights of eq. (3),
///   w_ik = (tan(α_{k−1}/2) + tan(α_k/2)) / ‖v_k − v_i‖,  λ_ik = w_ik / Σ_l w_il,
/// where α are the 3D angles at v_i of the two triangles on edge (v_i, v_k), for every vertex that is not
/// fixed, with a sparse LU factorisation (Eigen::SparseLU, two right-hand sides). If the fixed vertices are
/// the boundary of a disk mapped one-to-one onto a convex polygon, and no interior edge joins two fixed
/// vertices on one straight side, the result is an embedding (Floater 2003): no flipped triangle, every free
/// vertex strictly inside.
///
/// \param positions  3D positions (any unit)
/// \param triangles  counter-clockwise triangles indexing `positions`; need not reference every vertex
/// \param fixed      fixed parameters; ids not referenced by `triangles` are copied to the result as well
/// \pre every vertex on a boundary edge of `triangles` is fixed; no triangle has two coincident corners in
/// 3D. \throw InvalidInput if an id is out of range, a vertex is fixed twice, a boundary vertex is free, or a
///        triangle has a zero-length edge; SolverFailure if the factorisation fails.
MeanValueEmbeddingResult mean_value_embedding(const std::vector<Eigen::Vector3d>& positions,
                                              const std::vector<std::array<int, 3>>& triangles,
                                              const std::vector<FixedUv>& fixed,
                                              const MeanValueEmbeddingOptions& options = {});

}  // namespace geomip
