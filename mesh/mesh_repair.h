// Repair of scanned meshes so that they can be parameterized: a closed, manifold, consistently oriented
// triangle mesh.
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace geomip {

struct RepairOptions {
  /// Keep only the largest edge-connected component (by face count; the first one on a tie) and drop the
  /// others before repairing: for scans with stray fragments, which cannot be parameterized as one surface.
  bool largest_component_only = false;
  /// Close holes (CGAL Polygon Mesh Processing: triangulate, refine, fair; Liepa 2003).
  bool fill_holes = true;
  /// Refinement density of the hole patches (CGAL's density_control_factor: larger is denser, CGAL's own
  /// default is √2). 0.5 adds a few interior vertices to each large hole, enough to fair it without inventing
  /// detail (figures on the bunny: docs/measurements.md).
  double hole_density = 0.5;
  /// Fairing continuity of the hole patches: 0 = C0 (flat), 1 = tangent, 2 = curvature continuous.
  unsigned int fairing_continuity = 1;
  /// Called between stages (see ProgressCallback).
  ProgressCallback progress;
};

/// What `repair_mesh()` did, so tools can tell the user.
struct RepairResult {
  TriMesh mesh;
  std::size_t removed_unreferenced_vertices = 0;
  std::size_t merged_duplicate_vertices = 0;  ///< vertices at exactly the same position as an earlier one
  std::size_t removed_degenerate_faces = 0;   ///< repeated index, zero area, or a duplicate face
  std::size_t split_non_manifold_vertices = 0;  ///< vertex copies added to separate fans ("pinches")
  std::size_t filled_holes = 0;
  std::size_t unfaired_holes = 0;             ///< holes only triangulated and refined (fairing failed)
  std::size_t added_vertices = 0;             ///< appended by hole filling
  bool reoriented = false;                    ///< faces flipped so a closed mesh points outward
  std::size_t removed_components = 0;         ///< components dropped by largest_component_only
  std::size_t removed_component_faces = 0;    ///< their faces (not counted in removed_degenerate_faces)
};

/// Repairs `mesh`:
/// 1. drops unreferenced vertices and merges vertices at identical positions (the first one is kept);
/// 2. drops faces with a repeated vertex, duplicate faces, and zero-area faces (CGAL edge collapses); with
///    `largest_component_only`, the faces (and then vertices) of every edge-connected component but the
///    largest;
/// 3. splits non-manifold vertices and edges (CGAL orient_polygon_soup duplicates them);
/// 4. fills every hole with CGAL's triangulate_refine_and_fair_hole;
/// 5. orients a closed result outward.
/// The surviving original vertices keep their positions and their relative order; new vertices are appended.
/// \throw InvalidInput when `mesh` has no triangles, or non-finite coordinates.
RepairResult repair_mesh(const TriMesh& mesh, const RepairOptions& options = {});

/// Triangles of a mesh that cross other triangles of it (self-intersections: booleans, 3D printing and
/// physics engines refuse such meshes; `geomip info --self-intersections`).
struct SelfIntersections {
  std::size_t pairs = 0;  ///< pairs of triangles that intersect other than in the edge or vertex they share
  std::size_t faces = 0;  ///< distinct triangles in at least one such pair
};

/// Counts the self-intersections of `mesh` with CGAL's exact predicates (PMP::self_intersections; boxes
/// first, O(n log n + k)). Faces with a repeated vertex or zero area are left out (analyze_topology() counts
/// those). Empty when the other faces do not form a polygon mesh (non-manifold edges or vertices, or
/// inconsistent orientation: `geomip repair` first), where "crossing" has no single answer.
std::optional<SelfIntersections> count_self_intersections(const TriMesh& mesh);

/// The same check, giving the crossing triangles themselves: indices into mesh.triangles, ascending, each
/// once; `counts`, when given, receives the counts. Empty optional where count_self_intersections() is.
std::optional<std::vector<std::size_t>> self_intersecting_faces(const TriMesh& mesh,
                                                                SelfIntersections* counts = nullptr);

}  // namespace geomip
