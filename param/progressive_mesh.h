// Per-patch progressive mesh (Hoppe 1996) by half-edge collapses, with the locks of the consistent
// parameterization paper (../shared/seed/consistent-mesh-parameterizations.txt, section 3.3.1).
#pragma once

#include "mesh/mesh.h"

#include <array>
#include <cstddef>
#include <vector>

namespace geomip {

/// The four sides of a quadrilateral patch. `sides[k]` lists the vertex ids (local to the patch) along the
/// boundary from corner k to corner k+1 (mod 4), both corners included, in the direction of the boundary loop
/// that keeps the patch on its left (the direction of the boundary edges of counter-clockwise triangles).
/// Corner k maps to (0,0), (1,0), (1,1), (0,1) for k = 0..3 in the parameter square.
using PatchSides = std::array<std::vector<int>, 4>;

/// The sides of a disk-shaped `patch` cut at the four `corners` (vertex ids on the boundary, in the order in
/// which the boundary loop, oriented with the patch on its left, visits them, starting anywhere).
/// \pre `patch` is a manifold disk (one component, one boundary loop, Euler characteristic 1).
/// \throw InvalidInput if it is not, if a corner is not on the boundary, repeated, or out of loop order.
PatchSides patch_sides(const TriMesh& patch, const std::array<int, 4>& corners);

struct ProgressiveMeshOptions {
  /// Number of vertices the base mesh should have. 0 (default): max(number of locked vertices + 16, 100),
  /// where the locked vertices are the corners and the feature vertices. The simplification stops earlier
  /// when no legal collapse is left (see `ProgressiveMesh::base_vertices`).
  std::size_t target_vertices = 0;
  /// Reject collapses that turn a triangle normal by more than this many degrees (OpenMesh's
  /// ModNormalFlippingT) so that the base mesh stays a faithful, unfolded proxy of the patch, which is what
  /// the mean value weights of the base embedding are computed on. 180 or more disables the test.
  double max_normal_deviation_degrees = 90.0;
};

/// One half-edge collapse (v1, v2) → v1 of the paper, read backwards: the vertex split that undoes it.
/// Vertex ids are the patch's, triangle ids are indices into the patch's `triangles`.
struct HalfEdgeCollapse {
  /// v2 in the paper (OpenMesh's v0): the vertex the collapse removes and the split re-inserts.
  int removed = -1;
  /// v1: the vertex `removed` is merged into; it keeps its position (and parameter).
  int kept = -1;
  /// Wing vertices. The triangle (removed, kept, left) lies left of the half-edge removed→kept and
  /// (kept, removed, right) right of it, both in counter-clockwise order; the collapse deletes them. -1 where
  /// the half-edge (or its opposite) is a boundary half-edge and has no triangle.
  int left = -1;
  int right = -1;
  int left_triangle = -1;   ///< id of the triangle (removed, kept, left), or -1
  int right_triangle = -1;  ///< id of the triangle (kept, removed, right), or -1
  /// Ids of the other triangles around `removed` at collapse time: the collapse replaces `removed` by `kept`
  /// in them, the split replaces `kept` by `removed` again.
  std::vector<int> moved_triangles;
  /// For a boundary `removed`: its boundary neighbour other than `kept`; the split re-inserts `removed` on
  /// the side between `kept` and this vertex. -1 for an interior `removed`.
  int boundary_neighbor = -1;
};

/// A patch's progressive mesh: the base mesh plus the collapses that lead to it.
struct ProgressiveMesh {
  std::size_t num_vertices = 0;    ///< vertices of the full patch
  std::size_t num_triangles = 0;   ///< triangles of the full patch
  std::vector<int> base_vertices;  ///< patch vertex ids that survive in the base mesh, ascending
  std::vector<std::array<int, 3>> base_triangles;  ///< base mesh triangles, counter-clockwise, patch ids
  std::vector<int> base_triangle_ids;  ///< base_triangles[i] is what triangle base_triangle_ids[i] became
  /// The collapses in the order they were applied (fine → coarse). Vertex splits undo them in reverse order.
  std::vector<HalfEdgeCollapse> collapses;
  PatchSides sides;           ///< of the full patch, as given
  std::vector<int> features;  ///< feature vertex ids, as given
};

/// Simplifies `patch` by half-edge collapses ordered by the quadric error metric (Garland–Heckbert 1997,
/// OpenMesh's ModQuadricT), under the locks of section 3.3.1: a corner or feature vertex is never removed; a
/// boundary vertex is removed only along a boundary edge into a neighbour on its own side; a collapse never
/// changes the topology (the base mesh is a disk) and never creates an interior edge between two boundary
/// vertices of one side (such an edge, and any triangle with all three vertices on one side, would be flat in
/// the parameter square).
///
/// Positions are never changed: a half-edge collapse keeps v1 where it is, so every level uses the patch's
/// original 3D positions. Cost O(F log F).
///
/// \param patch  disk-shaped patch, counter-clockwise triangles, positions in any unit
/// \param sides  its four sides (see `patch_sides()`)
/// \param features  vertex ids that must survive (may be empty; corners need not be repeated)
/// \pre `patch` is a manifold disk without unreferenced vertices or zero-area triangles, `sides` covers its
///      boundary loop, and no interior edge joins two vertices of one side.
/// \throw InvalidInput if a precondition is violated (the message names it).
ProgressiveMesh progressive_mesh(const TriMesh& patch, const PatchSides& sides,
                                 const std::vector<int>& features,
                                 const ProgressiveMeshOptions& options = {});

/// Applies the vertex split that undoes `collapse` to `triangles` (indexed by triangle id, {-1,-1,-1} for a
/// triangle that does not exist at the current level): `kept` becomes `removed` in the moved triangles and
/// the wing triangles reappear. O(number of triangles around `removed`). \throw InvalidInput if `triangles`
/// is not at the level right after `collapse` (a moved triangle lacks
///        `kept`, a wing triangle already exists, or an id is out of range).
void apply_vertex_split(const HalfEdgeCollapse& collapse, std::vector<std::array<int, 3>>& triangles);

/// The triangles of the progressive mesh after the first `num_splits` vertex splits (undoing the last
/// `num_splits` collapses), indexed by triangle id: entry i is triangle i at that level, or {-1,-1,-1} where
/// triangle i does not exist yet. `num_splits` = pm.collapses.size() gives the full patch (each triangle up
/// to a rotation of its corners). O(F + number of splits). \throw InvalidInput if `num_splits` exceeds the
/// number of collapses or `pm` is inconsistent.
std::vector<std::array<int, 3>> triangles_after_splits(const ProgressiveMesh& pm, std::size_t num_splits);

}  // namespace geomip
