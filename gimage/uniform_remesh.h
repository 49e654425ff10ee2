// Uniform consistent remeshing (§4 of ../shared/seed/consistent-mesh-parameterizations.txt, "Uniform
// remeshing"; Gu et al. 2002's geometry image triangulation): the level-K grid of every patch triangulated,
// (2^K)² quads per patch (the default genus-0 layout: 2·4^K quads; a quad layout of P patches: P·4^K), each
// split in two along a fixed diagonal rule, seam samples welded by the patch layout (SideLinks), not by
// position. Any layout works (param/mesh_partition.h QuadLayout, any genus); check_quad_layout() refuses the
// layouts whose corners would get an edge of four triangles under the diagonal rule.
//
// The face list and the vertex numbering depend only on K and the layout (number of patches and their
// adjacency): every model of a consistent set gets the identical face list.
#pragma once

#include "gimage/resample.h"
#include "mesh/mesh.h"
#include "param/mesh_partition.h"

#include <vector>

namespace geomip {

struct UniformRemeshResult {
  /// Vertices: one per distinct sample (seam samples once); triangles counter-clockwise in (u,v), so outward
  /// when the parameterization is (patches map to the square without a flip). 2·(2^K)² triangles per patch.
  TriMesh mesh;
  /// Per patch, the mesh vertex of each level-K sample (i, j), at grid_vertex[p][j·(2^K+1) + i].
  std::vector<std::vector<int>> grid_vertex;
};

/// The connectivity alone: vertex numbering and triangles of the level-`level` remesh of a layout of
/// `num_patches` patches glued by `adjacency` (adjacency[4·p + s] = side s of patch p; empty = no gluing).
///
/// Quad (i, j) of patch p, corners a = (i, j), b = (i+1, j), c = (i+1, j+1), d = (i, j+1), is split along a–c
/// when (i + j + p) is even, along b–d otherwise: the 4-8 pattern within a patch; alternating the rule
/// between patches makes genus-0 level 0 a tetrahedron rather than four triangles on one diagonal. A genus-1
/// layout at level 0 has only 4 vertices and repeats edges; use level ≥ 1 there.
/// Vertices are numbered in order of first appearance over patches, rows j, columns i.
/// \throw InvalidInput for a level outside [0, kMaxGeometryImageLevel] or an adjacency of the wrong size or
///   out of range.
UniformRemeshResult uniform_remesh_connectivity(std::size_t num_patches,
                                                const std::vector<SideLink>& adjacency, int level);

/// How each grid quad of a remesh is split into two triangles.
enum class QuadSplit {
  /// uniform_remesh_connectivity()'s rule: (i + j + p) even → a–c, else b–d. Depends on the layout alone.
  kFixed,
  /// Along the shorter 3D diagonal (Gu et al. 2002): the piecewise-linear surface then follows ridges and
  /// valleys that cross the grid's diagonals instead of zig-zagging across them.
  kShorter,
};

/// Re-splits the quads of `remesh` — uniform_remesh_connectivity() at `level`, triangles 2q and 2q + 1 of quad
/// q = (p · 2^level + j) · 2^level + i, in that numbering — along their shorter diagonal. `models` holds the
/// vertex positions of one or more models in remesh's vertex numbering (a consistent set: the squared
/// diagonal lengths are summed over the models, so all of them keep one face list). A quad keeps the fixed
/// rule when both diagonals are equally long, and always when it touches a patch corner: only corner quads of
/// two patches can share three vertices, and check_quad_layout() accepts a layout for the fixed rule's corner
/// splits, so the result is as manifold and as oriented as the fixed split. Below level 2 every quad touches a
/// corner: nothing changes. Deterministic (no tolerance, one comparison of sums of squares per quad).
/// \throw InvalidInput when `models` is empty or a model's size differs from remesh's vertex count, or the
///   triangle count does not match `level`.
void split_along_shorter_diagonals(UniformRemeshResult& remesh, int level,
                                   const std::vector<const std::vector<Eigen::Vector3d>*>& models);

/// Uniform remesh of `images` at `level` ≤ the images' level: the connectivity above with the positions of
/// the nested level-`level` grid samples (every 2^(n−level)-th sample of the level-n images).
/// \throw InvalidInput when there are no images, they differ in level, `level` is above it or negative, or
///   the adjacency does not fit.
UniformRemeshResult uniform_remesh(const GeometryImages& images, int level);

}  // namespace geomip
