// Automatic choice of the partition points (and, for genus 1, the auxiliary points) that partition_mesh()
// connects (§3.2 of Lin, Lee et al., "Consistent mesh parameterizations"). The paper has the user place them;
// these choices are for one model on its own, or as a starting point the user then edits. They are not in
// correspondence between different models.
#pragma once

#include "mesh/mesh.h"

#include <vector>

namespace geomip {

/// Points to pass to partition_mesh().
struct PartitionPoints {
  std::vector<int> partition_points;  ///< 4 vertex ids, P0..P3
  /// genus 0: 4 vertex ids guiding the 4 paths (empty when the outline is too short for them); genus 1: 8.
  /// In partition_mesh()'s order.
  std::vector<int> auxiliary_points;
  /// genus 0 with a loop through the shape's tips (PartitionPointsOptions::tip_loop): the guides of
  /// each of the 4 paths, for partition_mesh_guided(); auxiliary_points is then empty. Otherwise empty.
  std::vector<std::vector<int>> side_guides;
};

struct PartitionPointsOptions {
  /// Genus 0 only: the cutting plane's normal is principal axis e_cut_axis (1 = longest, 3 = thinnest, the
  /// default; see choose_partition_points() for why). 1 cuts across the longest axis (the "equator").
  int cut_axis = 3;
  /// Genus 0 only: route the loop through the tips of the shape's protrusions (see choose_partition_points()).
  /// Off by default: measured mixed (docs/measurements.md, "A loop through the tips").
  bool tip_loop = false;
  /// With tip_loop: a protrusion counts when its tip stands at least tip_prominence · √(surface area)
  /// (geodesic) above where it joins the rest of the shape.
  double tip_prominence = 0.1;
  int max_tips = 12;            ///< with tip_loop: at most this many tips, the most prominent first
  int outline_guides = 16;      ///< with tip_loop: guides along the outline (spacing = its length / this; >= 4)
  /// With tip_loop: a peak is a protrusion's tip when the region above half its depth has an area below
  /// tube_ratio · depth² (a tube of girth c: c / depth, about 0.5–1.5 for legs and ears; a rounded cap: π).
  double tube_ratio = 2.0;
  /// Genus 1 only: grid offsets are tried on an offset_steps × offset_steps lattice of the flat torus
  /// (cheap: one pass over the triangles each).
  int offset_steps = 16;
  /// Genus 1 only: how many placements, best predicted balance first, are actually partitioned
  /// (partition_mesh() each); the best measured one is returned.
  int tries = 4;
};

/// Chooses partition points for `closed_manifold` (same preconditions as partition_mesh()) such that the
/// partition is balanced and each patch is easy to flatten onto a square. The result is checked by running
/// partition_mesh() on it.
///
/// Genus 0 — the loop is the outline of the shape seen along its thinnest direction:
/// 1. principal axes e1, e2, e3 (largest to smallest variance, e3 = e1 × e2) of the surface with area
///    weights (exact second moments of the triangles about the area centroid);
/// 2. the cutting plane has normal e3 and passes through the area median along e3 (half the triangle area,
///    counted at triangle centroids, on each side); the longest closed curve where it cuts the mesh is the
///    outline;
/// 3. P0..P3 are the outline's vertices (of each crossing edge, the endpoint nearer the plane) extreme in the
///    directions +e1, +e2, −e1, −e2: CCW around e3, so patch 0 is the +e3 half. If the extremes do not come
///    in that order along the outline, P1..P3 are at quarters of its length from P0 instead;
/// 4. auxiliary point k is the outline vertex half way (by length) from P_k to P_{k+1}, so that the
///    shortest paths follow the outline instead of cutting across the surface (for a cow, the path from
///    the tail tip to the belly would otherwise run up the tail and diagonally across one flank).
///   Why: the two halves are the front and back of the shape seen along e3, the direction in which it is
///   thinnest, so each half is close to a height field over the (e1,e2) plane: it flattens onto a square with
///   little stretch (a cut across the longest axis would instead make two deep caps, tubes closed at one end,
///   that need strong radial stretch). The median plane balances the areas; extreme points in 4 directions
///   90° apart spread the corners evenly along the outline, so the 4 sides have similar lengths. The guiding
///   points keep the areas balanced (without them the balance drops: docs/measurements.md). If the loop fails to partition (possible on very coarse meshes), the
///   other principal planes are tried (normals e3, e2, e1, after options.cut_axis); on an outline too short
///   for distinct corners the corners are spread over its vertices without guides, and on a mesh of a few
///   triangles (a tetrahedron) the vertices extreme in ±e1, ±e2 are the last resort.
///
/// Genus 0 with options.tip_loop — the same outline, rerouted through the tips of protrusions (legs, ears),
/// as geometry images cut through extremities (Gu, Gortler, Hoppe 2002), so that each protrusion is split
/// lengthwise between the two patches instead of lying whole inside one square as a tube closed at one end:
/// 1. d = geodesic distance from the outline (edge-graph Dijkstra); tips are the peaks of d whose prominence
///    (0-dimensional persistence of its superlevel sets: how far d falls before the peak's region meets a
///    higher one's) is at least tip_prominence · √area, and whose region half way down is a tube (area below
///    tube_ratio · depth², 2 by default), not the rounded middle of a half (a cap, area about π · depth²);
/// 2. the loop follows the outline through outline_guides guides, and at the outline vertex nearest to each
///    tip it runs down to the tip and back up another way (partition_mesh_guided());
/// 3. the 4 corners are waypoints that split the loop's estimated length into quarters within 1/16, with as
///    many tips among them as possible (a corner gives a tip's U-turn 90°); the evenest split otherwise.
/// Without a tip, or when the rerouted loop does not partition, the plain outline's points are returned.
///
/// Genus 1 — the 2×2 grid follows the torus's flat (conformal) coordinates:
/// 1. a homology basis by tree–cotree (Eppstein 2003) gives two closed, non-exact 1-forms on the edges;
///    removing their exact parts (cotangent Laplacian solves) leaves two harmonic 1-forms, whose integrals
///    are coordinates θ = (θ1, θ2) ∈ R²/Z² of a discrete-harmonic map of the torus onto a flat torus
///    (Gu & Yau 2003; for genus 1 this map is conformal);
/// 2. the basis is Gauss-reduced with the forms' Dirichlet Gram matrix so grid lines θ1 = c and θ2 = c cross
///    as close to right angles as the torus's conformal shape allows;
/// 3. a placement is an offset o and band widths s = (s1, s2): corners at o + {0, s1} × {0, s2} (P0 at o,
///    P1 at o + (s1,0), P2 at o + (0,s2), P3 at o + s), auxiliary points at the middles of the grid edges in
///    partition_mesh()'s order (e0 at o + (s1/2, 0), e1 at o + (s1 + (1−s1)/2, 0), e2, e3 likewise at height
///    s2, e4 at o + (0, s2/2), e5 at o + (0, s2 + (1−s2)/2), e6, e7 likewise at s1), each the vertex nearest
///    to its target in the flat metric. For each offset on an offset_steps² lattice, s1 and s2 are chosen so
///    each band of the grid holds half of the area (counted at triangle centroids), which makes diagonally
///    opposite patches equal in area; the 4 patch areas predicted from the triangles' coordinates rank the
///    placements; the first `tries` that partition are measured and the one with the best area balance
///    (smallest / largest patch) is returned.
///
/// \throw InvalidInput for a mesh partition_mesh() rejects, or genus ≥ 2.
/// \throw SolverFailure when no candidate partitions (a degenerate mesh, or a limitation of this method).
PartitionPoints choose_partition_points(const TriMesh& closed_manifold,
                                        const PartitionPointsOptions& options = {});

}  // namespace geomip
