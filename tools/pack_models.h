// Between gimage/ and codec/ values: geometry images → pack inputs, decoded pack models → triangle meshes.
#pragma once

#include "codec/pack.h"
#include "gimage/hole_mask.h"
#include "gimage/resample.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh.h"

#include <string>
#include <vector>

namespace geomip::tools {

/// The pack input of one model: its geometry images (and normal maps unless `normals` is false), its seams,
/// and the hole mask when the model was repaired (`mask` may be null or empty).
codec::PackModelInput pack_model_input(const std::string& name, const GeometryImages& images,
                                       const HoleMaskResult* mask, bool normals);

/// The level-`level` mesh of a decoded model (level ≤ its grid level; -1 = the grid level): the nested grid
/// triangulated as `geomip remesh` does (gimage/uniform_remesh.h: same face list for every model of a
/// consistent pack), seams welded, quads over filled holes left out (a coarse quad is left out when all the
/// grid quads it covers are masked) and unreferenced vertices dropped.
/// \throw InvalidInput for a level outside [0, grid level] or a model without patches.
TriMesh decoded_mesh(const codec::DecodedModel& model, int level = -1);

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
TexturedMesh decoded_textured_mesh(const codec::DecodedModel& model, int level = -1);

/// The same for geometry images that were not coded (`geomip remesh --glb`): decoded_textured_mesh() of the
/// images as they are, at their own level; normals from their normal maps when they have them.
TexturedMesh textured_mesh(const GeometryImages& images);

}  // namespace geomip::tools
