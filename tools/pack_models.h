// Between gimage/ and codec/ values: geometry images → pack inputs, decoded pack models → triangle meshes.
#pragma once

#include "codec/pack.h"
#include "gimage/hole_mask.h"
#include "gimage/resample.h"
#include "gimage/uniform_remesh.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh.h"

#include <span>
#include <string>
#include <vector>

namespace geomip::tools {

/// The pack input of one model: its geometry images (and normal maps unless `normals` is false), its seams,
/// and the hole mask when the model was repaired (`mask` may be null or empty).
codec::PackModelInput pack_model_input(const std::string& name, const GeometryImages& images,
                                       const HoleMaskResult* mask, bool normals);

/// How decoded_mesh() splits the grid's quads into triangles.
struct QuadSplitOptions {
  /// kShorter (default): along the shorter diagonal (gimage/uniform_remesh.h split_along_shorter_diagonals;
  /// measured 2026-12-03: +0.6…+0.85 dB at full decode and at 32 KB, +0.15 at 8.8 KB on bunny, horse and
  /// armadillo, docs/measurements.md). kFixed: uniform_remesh_connectivity()'s rule, as `geomip remesh`.
  QuadSplit split = QuadSplit::kShorter;
  /// The models whose grids choose the diagonals, their squared lengths summed (empty: the model itself).
  /// Give every model of a consistent pack (or a morph's two ends) so that all share one face list; each
  /// needs the same patch count and grid level as the model.
  std::span<const codec::DecodedModel* const> chosen_by = {};
};

/// The level-`level` mesh of a decoded model (level ≤ its grid level; -1 = the grid level): the nested grid
/// triangulated (gimage/uniform_remesh.h; the quads split as `split` says), seams welded, quads over filled
/// holes left out (a coarse quad is left out when all the grid quads it covers are masked) and unreferenced
/// vertices dropped. Every triangle is oriented as with the fixed split, and the face list depends only on the
/// layout, the level, the hole mask and (kShorter) the grids of `split.chosen_by`.
/// \throw InvalidInput for a level outside [0, grid level], a model without patches, or a `chosen_by` model
///   of another patch count or grid level.
TriMesh decoded_mesh(const codec::DecodedModel& model, int level = -1, const QuadSplitOptions& split = {});

struct UntangleOptions {
  int normal_rings = 20;   ///< rings over which the reference normals are averaged at level 8 (scaled by
                           ///< 2^(N−8), at least 2, on a level-N grid)
  double max_slide = 1.0;  ///< no sample moves farther than this many of its mean edge lengths
  /// Grids coarser than this are left as decoded: there a sample's slide moves the surface (a level-4 horse
  /// lost 3–7 dB, a level-5 bunny 1 dB; level 6 at most 0.52 dB, levels 7–8 at most 0.23 dB).
  int min_level = 6;
  /// Models with more samples than this are left as decoded too: the sweeps' state takes about 240 bytes a
  /// sample (a crafted 1 KB pack claiming 32 M samples took 7.6 GB and minutes), and 2^22 is above every
  /// pack `convert` writes by default (16 patches at level 8: 1.05 M; two squares at level 10: 2.1 M).
  std::size_t max_samples = std::size_t{1} << 22;
  double max_fan_gap =
      0.1;  ///< a move is refused when a centroid of the sample's triangles lands farther than this
            ///< many mean edge lengths from the decoded surface as it was (0 = no check)
  int max_sweeps = 100;   ///< sweeps over the folded samples at most
  double step = 0.5;      ///< fraction of the way to the neighbours' centroid per sweep
};

struct UntangleStats {
  std::size_t folded_before = 0, folded_after = 0;  ///< triangles facing against their reference normal
  std::size_t moved = 0;                            ///< samples moved (seam samples once)
  double max_move = 0;                              ///< the largest move, model units
  int sweeps = 0;
  bool applied = false;  ///< false: the grid is coarser than UntangleOptions::min_level, left as decoded
};

/// Opens the folds of a decoded model's finest grids in place (grids of level ≥ `min_level` with at most
/// `max_samples` samples in all; others are left as they are). A triangle of the welded level-N mesh (quads
/// split as `split` says, as decoded_mesh() splits them) is folded when it faces against the area-weighted
/// vertex normals averaged over 20·2^(N−8) rings around it (wider than a fold, narrower than a limb). Each
/// sweep moves every sample of a folded triangle half-way towards its neighbours' centroid within that
/// normal's tangent plane, then onto the nearest point of the decoded surface as it was (its triangles two
/// rings around); a move is refused when the sample would end more than `max_slide` mean edge lengths from
/// where it was decoded or its triangles' centroids more than `max_fan_gap` of them off that surface. Sweeps
/// stop when no triangle is folded or after `max_sweeps`; some folds stay. Seam samples move once, into every
/// patch that has them (bit-identical across seams, as decoded). Measured (docs/measurements.md, "Folds and
/// self-intersections in decoded meshes"): self-intersecting faces −20…−93 % on spot, bunny, horse and cow
/// (levels 6–8, 8.8 KB and whole packs), PSNR −0.52…+0.28 dB. O(rings · F).
UntangleStats untangle_decoded_model(codec::DecodedModel& model, const QuadSplitOptions& split = {},
                                     const UntangleOptions& options = {});

/// decoded_mesh() and, in `normals`, each of its vertices' unit normal from the decoded normal maps at its
/// sample (for OBJ/PLY/OFF output: `vn`, nx/ny/nz); `normals` is left empty when the model has no normal maps
/// complete to `level` (a geometry-only pack, or a prefix before they arrive: +z where a texel is still
/// zero).
TriMesh decoded_mesh_with_map_normals(const codec::DecodedModel& model, int level,
                                      const QuadSplitOptions& split, std::vector<Eigen::Vector3f>& normals);

/// A mesh with per-vertex attributes for texture-mapped formats (glTF).
struct TexturedMesh {
  TriMesh mesh;
  MeshAttributes attributes;  ///< normals and uv, one per vertex of `mesh`
};

/// decoded_mesh()'s surface for formats with texture coordinates: the same triangles in the same order, but
/// seams not welded — every patch has its own vertices, so each carries its patch's (u,v) = (i, j) / 2^level
/// (TEXCOORD_0) — and unit normals from the decoded normal maps at those (u,v) (the mesh's area-weighted
/// vertex normals when the model has no normal maps; +z where a texel is still zero). Vertices on a seam
/// appear once per patch with bit-identical positions (the codec keeps seam samples identical), so the
/// surface does not crack.
TexturedMesh decoded_textured_mesh(const codec::DecodedModel& model, int level = -1,
                                   const QuadSplitOptions& split = {});

/// The same for geometry images that were not coded (`geomip remesh --glb`): decoded_textured_mesh() of the
/// images as they are, at their own level, the quads split as `split` says (kShorter: chosen by the images
/// of `chosen_by` together, or by `images` alone when it is empty); normals from their normal maps when they
/// have them.
TexturedMesh textured_mesh(const GeometryImages& images, QuadSplit split = QuadSplit::kShorter,
                           const std::vector<const GeometryImages*>& chosen_by = {});

/// untangle_decoded_model() for geometry images that were not coded (`geomip remesh --untangle`): `images` in
/// place, the quads split as `split` says, chosen by the images of `chosen_by` (give the set's images as they
/// were before any untangling, so the face list stays) or by `images` alone when it is empty.
UntangleStats untangle_geometry_images(GeometryImages& images, QuadSplit split = QuadSplit::kShorter,
                                       const std::vector<const GeometryImages*>& chosen_by = {});

}  // namespace geomip::tools
