// Automatic choice of the partition points (and, for genus 1, the auxiliary points) that partition_mesh()
// connects (§3.2 of Lin, Lee et al., "Consistent mesh parameterizations"). The paper has the user place them;
// these choices are for one model on its own, or as a starting point the user then edits. They are not in
// correspondence between different models.
#pragma once

#include "param/mesh.h"

#include <vector>

namespace geomip {

/// Points to pass to partition_mesh().
struct PartitionPoints {
  std::vector<int> partition_points;  ///< 4 vertex ids, P0..P3
  std::vector<int> auxiliary_points;  ///< genus 0: empty; genus 1: 8 vertex ids in partition_mesh()'s order
};

struct PartitionPointsOptions {
  /// Genus 1 only: the grid of corner offsets tried is offsets × offsets (see choose_partition_points()).
  /// 4 tries 16 placements; more gives better balance at a proportional cost.
  int offsets = 4;
};

/// Chooses partition points for `closed_manifold` (same preconditions as partition_mesh()) such that the
/// partition is balanced and each patch is easy to flatten onto a square. The result is checked by running
/// partition_mesh() on it.
///
/// Genus 0 — the loop is the outline of the shape seen along its thinnest direction:
/// 1. principal axes e1, e2, e3 (largest to smallest variance, e3 = e1 × e2) of the surface with area
///    weights (exact second moments of the triangles about the area centroid);
/// 2. the cutting plane has normal e3 and passes through the area median along e3 (half the triangle area,
///    counted at triangle centroids, on each side);
/// 3. among "section vertices" (the endpoint nearer the plane of each edge crossing it) P0..P3 are the
///    extremes in the directions +e1, +e2, −e1, −e2: CCW around e3, so patch 0 is the +e3 half.
///   Why: the two halves are the front and back of the shape seen along e3, the direction in which it is
///   thinnest, so each half is close to a height field over the (e1,e2) plane: it flattens onto a square with
///   little stretch (a cut across the longest axis would instead make two deep caps, tubes closed at one end,
///   that need strong radial stretch). The median plane balances the areas; extreme points in 4 directions 90°
///   apart spread the corners evenly along the outline, so the 4 sides have similar lengths. If that loop
///   fails to partition (possible on very coarse meshes), the planes with normals e2 then e1 are tried.
///
/// Genus 1 — the 2×2 grid follows the torus's flat (conformal) coordinates:
/// 1. a homology basis by tree–cotree (Eppstein 2003) gives two closed, non-exact 1-forms on the edges;
///    removing their exact parts (cotangent Laplacian solves) leaves two harmonic 1-forms, whose integrals
///    are coordinates θ = (θ1, θ2) ∈ R²/Z² of a discrete-harmonic map of the torus onto a flat torus
///    (Gu & Yau 2003; for genus 1 this map is conformal);
/// 2. the basis is Gauss-reduced with the forms' Dirichlet Gram matrix so grid lines θ1 = c and θ2 = c cross
///    as close to right angles as the torus's conformal shape allows;
/// 3. for an offset o, corners are the vertices nearest (in the flat metric) to o + {(0,0), (½,0), (0,½),
///    (½,½)} and the auxiliary points those nearest to the midpoints of the grid edges between them, in
///    partition_mesh()'s order: e0 at (¼,0), e1 (¾,0), e2 (¼,½), e3 (¾,½), e4 (0,¼), e5 (0,¾), e6 (½,¼),
///    e7 (½,¾);
/// 4. of the offsets o ∈ {0, ½/n, …}² (n = options.offsets) whose points partition successfully, the one with
///    the best area balance (smallest / largest patch) is returned.
///
/// \throw InvalidInput for a mesh partition_mesh() rejects, or genus ≥ 2.
/// \throw SolverFailure when no candidate partitions (a degenerate mesh, or a limitation of this method).
PartitionPoints choose_partition_points(const TriMesh& closed_manifold, const PartitionPointsOptions& options = {});

}  // namespace geomip
