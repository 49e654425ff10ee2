// Decimation of a triangle mesh to a target face count by edge collapses, for the rate–distortion baseline
// "decimate, then Draco" (`geomip rd`), which trades faces for quantization bits. Two simplifiers:
//
// kMeshopt (default): meshoptimizer's simplifier (Debian libmeshoptimizer-dev 0.18). meshopt_simplify is an
// edge-collapse simplifier in the manner of Garland & Heckbert, "Surface simplification using quadric error
// metrics", SIGGRAPH 1997: it collapses the edge whose quadric error is
// smallest, keeping the surviving vertex in place (half-edge collapse: no optimal vertex placement, so every
// output position is an input position), and respects topology (it does not collapse across borders
// or seams in ways that would change them). When topology stops it above the target, meshopt_simplifySloppy
// (vertex clustering on a grid, topology not preserved) takes over, optionally; the result says which ran.
//
// kLindstromTurk: CGAL's Surface_mesh_simplification::edge_collapse with its default policies, Lindstrom &
// Turk, "Fast and memory efficient polygonal simplification", IEEE Visualization 1998 (volume- and
// boundary-preserving cost, optimal vertex placement). Slower than meshoptimizer's simplifier but much closer
// to the original at equal face count (figures: docs/measurements.md). Needs an oriented 2-manifold input.
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <optional>
#include <string>

namespace geomip {

enum class DecimationMethod {
  kMeshopt,        ///< meshopt_simplify (QEM, half-edge collapses, vertices kept in place), sloppy fallback
  kLindstromTurk,  ///< CGAL edge_collapse, Lindstrom–Turk cost and placement
};

struct DecimationOptions {
  DecimationMethod method = DecimationMethod::kMeshopt;
  /// kMeshopt: error bound relative to the mesh's extent handed to the simplifier (meshopt's target_error; 1
  /// = 100 % of the extent). Large by default so that the face count, not the error, stops the decimation.
  double target_error = 1.0;
  /// kMeshopt: when meshopt_simplify stops with more than `(1 + tolerance)·target_faces` faces, run
  /// meshopt_simplifySloppy on the original instead (if its result is closer to the target).
  bool sloppy_fallback = true;
  /// Relative tolerance on the face count for the fallback decision.
  double tolerance = 0.05;
};

struct DecimationResult {
  TriMesh mesh;              ///< the decimated mesh, compacted (only referenced vertices, in first-use order)
  bool used_sloppy = false;  ///< true when meshopt_simplifySloppy produced `mesh`
  double relative_error = 0;  ///< kMeshopt: meshoptimizer's own error estimate, relative to the mesh extent
};

/// Decimates `mesh` to about `target_faces` triangles. A `target_faces` at or above the input's face count
/// returns the input's referenced part unchanged. Faces with a repeated corner are never produced (such input
/// faces are removed first). kLindstromTurk stops at the edge count that corresponds to `target_faces`
/// (E = (3F + boundary edges)/2, repeated while the boundary shrinks), so its face count lands within about
/// 1 % above the target (or below it by the few faces one collapse removes).
///
/// \param mesh #V×3 positions, #F triangles.
/// \param target_faces the wanted face count (≥ 1).
/// \pre at least one triangle, indices in range, finite coordinates; for kLindstromTurk also an oriented
///      2-manifold (possibly with boundary).
/// \throw InvalidInput naming `decimate_mesh` when a precondition fails.
DecimationResult decimate_mesh(const TriMesh& mesh, std::size_t target_faces,
                               const DecimationOptions& options = {});

/// Why decimate_mesh() with kLindstromTurk would refuse `mesh` (one line: no triangles, or the first triangle
/// that makes it non-manifold or flips its orientation), or nothing when it takes it. Linear in the mesh.
/// \throw InvalidInput for a triangle index out of range.
std::optional<std::string> lindstrom_turk_refusal(const TriMesh& mesh);

}  // namespace geomip
