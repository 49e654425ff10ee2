// Quadric-error-metric decimation of a triangle mesh to a target face count, with meshoptimizer's simplifier
// (Debian libmeshoptimizer-dev 0.18). A baseline tool: the rate–distortion curve "decimate, then Draco"
// (`geomip rd`) uses it to trade faces for quantization bits.
//
// meshopt_simplify is an edge-collapse simplifier in the manner of Garland & Heckbert, "Surface
// simplification using quadric error metrics", SIGGRAPH 1997: it collapses the edge whose quadric error is
// smallest, keeping the surviving vertex in place (half-edge collapse: no optimal vertex placement, so every
// output position is an input position), and respects topology (it does not collapse across borders
// or seams in ways that would change them). When topology stops it above the target, meshopt_simplifySloppy
// (vertex clustering on a grid, topology not preserved) takes over, optionally; the result says which ran.
#pragma once

#include "param/mesh.h"

#include <cstddef>

namespace geomip {

struct DecimationOptions {
  /// Error bound relative to the mesh's extent handed to the simplifier (meshopt's target_error; 1 = 100 % of
  /// the extent). Large by default so that the face count, not the error, stops the decimation.
  double target_error = 1.0;
  /// When meshopt_simplify stops with more than `(1 + tolerance)·target_faces` faces, run
  /// meshopt_simplifySloppy on the original instead (if its result is closer to the target).
  bool sloppy_fallback = true;
  /// Relative tolerance on the face count for the fallback decision.
  double tolerance = 0.05;
};

struct DecimationResult {
  TriMesh mesh;               ///< the decimated mesh, compacted (only referenced vertices, in first-use order)
  bool used_sloppy = false;   ///< true when meshopt_simplifySloppy produced `mesh`
  double relative_error = 0;  ///< meshoptimizer's own error estimate, relative to the mesh extent
};

/// Decimates `mesh` to about `target_faces` triangles. A `target_faces` at or above the input's face count
/// returns the input's referenced part unchanged. Faces with a repeated corner are never produced (such input
/// faces are removed first).
///
/// \param mesh #V×3 positions, #F triangles.
/// \param target_faces the wanted face count (≥ 1).
/// \pre at least one triangle, indices in range, finite coordinates.
/// \throw InvalidInput naming `decimate_mesh` when a precondition fails.
DecimationResult decimate_mesh(const TriMesh& mesh, std::size_t target_faces, const DecimationOptions& options = {});

}  // namespace geomip
