// Adaptive consistent remeshing (§4 of ../shared/seed/consistent-mesh-parameterizations.txt, "Adaptive
// remeshing", eq. 4–6): a quadtree per patch whose root is the whole patch square (the base quad); a quad q
// at depth d covers a 2^(n−d)-sample block of the patch's level-n geometry image. q is split while its error
// E_N(q) > ε and d < n; for a consistent set the error of a quad is the maximum over the models (eq. 6), so
// every model gets the same quadtree and hence the same face list. The tree is then restricted (edge-adjacent
// leaves differ by at most one level, across seams too) and triangulated without T-vertices.
//
// Three steps, each usable (and tested) alone:
//   adaptive_quad_errors()  one model's E_N of every quad (eq. 4–5);
//   adaptive_quadtree()     split by the maximum over the models (eq. 6), then restrict_quadtree();
//   adaptive_remesh()       the leaves triangulated on one model's geometry images, seams welded by the
//                           layout (SideLinks) as uniform_remesh() does, not by position.
#pragma once

#include "gimage/resample.h"
#include "mesh/mesh.h"
#include "param/consistent_parameterization.h"
#include "param/mesh_partition.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

/// E_N of every quad of every patch of one model, for depths 0..max_depth.
struct AdaptiveQuadErrors {
  int max_depth = 0;
  /// errors[p][d][j·2^d + i]: quad (i, j) at depth d of patch p, covering (u,v) ∈ [i, i+1]·2^−d × [j,
  /// j+1]·2^−d. Dimensionless (a distance over the bounding-box diagonal of the input mesh).
  std::vector<std::vector<std::vector<double>>> errors;
};

struct AdaptiveErrorOptions {
  /// Also measure every quad's (2^(n−d)+1)² level-n samples against its plane, not only its vertices (a
  /// stricter bound than the paper's: it sees surface that the quad's triangles stand for but whose vertices
  /// lie outside the quad, where the (u,v) triangles are large). Off = eq. 4–5 as published.
  bool measure_samples = false;
};

/// One model's quad errors, eq. 4–5 of the paper: for quad q, the vertices of the patch (positions of
/// `model.mesh`) whose (u,v) lie in q — half-open cells [i, i+1)·2^−d, closed at u = 1 and v = 1 — get a
/// least squares plane (through their centroid, normal = the covariance's smallest eigenvector); E_N(q) is
/// their largest distance to it over the diagonal of `model.mesh`'s bounding box. A quad with at most 3
/// vertices (the paper says fewer than 3; but 3 vertices always lie on their plane, error 0 whatever the
/// surface) uses the least-squares plane of its four corner samples of `images`, and measures its vertices
/// and its (2^(n−d)+1)² level-n samples to it — so a curved quad is never error-free and ε → 0 gives the
/// uniform level-n mesh.
/// \param images  resample_geometry(model, n): n is the maximum depth.
/// \throw InvalidInput when `images` does not have one geometry image per patch, all of one level, or the
///   mesh's bounding box is a point.
AdaptiveQuadErrors adaptive_quad_errors(const ModelParameterization& model, const GeometryImages& images,
                                        const AdaptiveErrorOptions& options = {});

/// The leaves of the quadtrees of all patches, as a depth per finest cell.
struct AdaptiveQuadtree {
  int max_depth = 0;  ///< n: a cell is one quad of the level-n grid
  /// depth[p][cj·2^n + ci]: the depth of the leaf of patch p that contains finest cell (ci, cj).
  std::vector<std::vector<std::uint8_t>> depth;
  std::vector<SideLink> adjacency;  ///< the layout, as in GeometryImages::adjacency

  /// One leaf: quad (i, j) at depth d of a patch, covering cells [i·2^(n−d), (i+1)·2^(n−d)) × likewise j.
  struct Leaf {
    int patch, depth, i, j;
  };
  /// Every leaf, ordered by patch, then by the row and column of its first cell (a function of the tree
  /// alone, so equal trees list equal leaves).
  std::vector<Leaf> leaves() const;
};

struct AdaptiveRemeshOptions {
  double epsilon = 0.002;       ///< ε: split while E_N(q) > ε (a fraction of the bounding-box diagonal)
  bool restrict_levels = true;  ///< balance the tree (needed for a crack-free mesh; off only for tests)
};

/// Splits each patch's root quad while the maximum of `errors` over the models (eq. 6) exceeds ε and the
/// depth is below n, then (when options.restrict_levels) restrict_quadtree(). A layout whose level-0 mesh
/// repeats edges (a genus-1 2×2 grid; see uniform_remesh_connectivity()) starts at depth 1.
/// \throw InvalidInput when `errors` is empty, the models disagree in n or patch count, ε < 0, or the
///   adjacency does not have 4 entries per patch (or none).
AdaptiveQuadtree adaptive_quadtree(const std::vector<AdaptiveQuadErrors>& errors,
                                   const std::vector<SideLink>& adjacency,
                                   const AdaptiveRemeshOptions& options = {});

/// Refines leaves until every two edge-adjacent leaves differ by at most one level, within a patch and across
/// the seams (a side's cells map to the linked side's cells, reversed as the SideLink says). Only splits.
/// Returns the number of splits.
std::size_t restrict_quadtree(AdaptiveQuadtree& tree);

/// Triangulates the leaves of a restricted `tree` on `images` (level n = tree.max_depth): a leaf with no
/// finer neighbour is split in two along the diagonal rule of uniform_remesh_connectivity() (so a tree of
/// depth-n leaves gives the uniform level-n triangles, vertices numbered in order of first use); a leaf with
/// finer neighbours on some sides gets a fan from its centre sample over its corners and the midpoints of
/// those sides. Vertices are geometry image samples, seam samples welded by the layout; triangles
/// counter-clockwise in (u,v) as in uniform_remesh(). Watertight, without T-vertices, and a function of the
/// tree alone in its connectivity: models of a consistent set get one face list.
/// \throw InvalidInput when the images do not match the tree (patch count, level) or the tree is not
///   restricted.
TriMesh adaptive_remesh(const GeometryImages& images, const AdaptiveQuadtree& tree);

}  // namespace geomip
