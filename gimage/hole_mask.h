// Which quads of a geometry image cover a hole of the source mesh that `geomip repair` filled.
//
// The parameterization needs a closed surface, so an open mesh is repaired (holes triangulated and faired)
// first, and its geometry images cover the fills too. A user of an open scan expects the holes back: the
// decoded meshes leave out the quads flagged here (the pack stores the mask; it costs a few bytes per hole).
#pragma once

#include "gimage/resample.h"
#include "mesh/mesh.h"
#include "param/consistent_parameterization.h"

#include <cstdint>
#include <vector>

namespace geomip {

struct HoleMaskOptions {
  /// A parameterized triangle is a fill triangle when its centroid lies farther than
  /// relative_tolerance · (its longest edge) from the ORIGINAL surface; triangles of the original (and the
  /// pieces of those the partition split) lie on it up to rounding.
  double relative_tolerance = 1e-6;
  /// A quad is masked when at least this many of its 4 corner samples lie in fill triangles. 3 (a majority)
  /// balances the two directions of the surface distance on the hole borders (the choice was measured: README).
  int min_fill_corners = 3;
};

struct HoleMaskResult {
  /// Per patch, per quad (i, j) of the level-`level` grid at index j·2^level + i: 1 = at least
  /// min_fill_corners of its corner samples lie in fill triangles. Empty when no triangle is a fill triangle.
  std::vector<std::vector<std::uint8_t>> quads;
  /// Per patch, per sample (i, j) of the level-`level` grid at index j·(2^level + 1) + i: 1 = the sample lies
  /// in a fill triangle. Empty when `quads` is.
  std::vector<std::vector<std::uint8_t>> fill_samples;
  std::size_t fill_triangles = 0;  ///< parameterized triangles found off the original surface
  std::size_t masked_quads = 0;
};

/// \param model     the parameterization of the repaired mesh
/// \param original  the mesh before repair (its triangles define what is "on the surface")
/// \param level     grid level of the geometry images
/// \throw InvalidInput for a level outside [0, kMaxGeometryImageLevel] or an original without triangles.
HoleMaskResult hole_mask(const ModelParameterization& model, const TriMesh& original, int level,
                         const HoleMaskOptions& options = {});

/// `quads` (per patch, a level-`from_level` quad mask as HoleMaskResult::quads) on the finer level-`to_level`
/// grid: each fine quad takes the flag of the coarse quad that holds it (what a decoder does with a coarse
/// mask). \pre from_level ≤ to_level.
std::vector<std::vector<std::uint8_t>> refine_hole_quads(const std::vector<std::vector<std::uint8_t>>& quads,
                                                         int from_level, int to_level);

/// Moves every fill sample that is a corner of a kept (unmasked) quad to its closest point on `original`, so
/// that the faces along a hole's border end on the border instead of hanging over the fill by up to a quad
/// (on the bunny those faces held a third of the decoded surface's squared distance to the original). Only
/// samples of the fill move, and those only touch the border's kept quads and masked ones; a sample that
/// several patches share (a seam) moves in all of them alike, so the seams stay bit-identical.
/// \pre `mask`'s fill_samples and quads are on the grid of `images.geometry` (hole_mask() at that level; for
/// a coarser mask, its quads through refine_hole_quads()); otherwise nothing moves and 0 is returned. \return
/// the number of distinct sample positions moved.
std::size_t snap_hole_borders(GeometryImages& images, const HoleMaskResult& mask, const TriMesh& original);

}  // namespace geomip
