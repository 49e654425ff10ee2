// Between gimage/ and codec/ values: geometry images → pack inputs, decoded pack models → triangle meshes.
#pragma once

#include "codec/pack.h"
#include "gimage/hole_mask.h"
#include "gimage/resample.h"
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

}  // namespace geomip::tools
