#include "tools/pack_models.h"

#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"

namespace geomip::tools {

codec::PackModelInput pack_model_input(const std::string& name, const GeometryImages& images,
                                       const HoleMaskResult* mask, bool normals) {
  codec::PackModelInput input;
  input.name = name;
  for (const GeometryImage& g : images.geometry) input.geometry.push_back({g.level, g.values});
  if (normals)
    for (const GeometryImage& g : images.normals) input.normals.push_back({g.level, g.values});
  for (const SideLink& link : images.adjacency)
    input.seams.push_back({link.patch, link.side, link.other_patch, link.other_side, link.reversed});
  if (mask) input.hole_mask = mask->quads;
  return input;
}

TriMesh decoded_mesh(const codec::DecodedModel& model, int level) {
  if (model.geometry.empty()) throw InvalidInput("decoded_mesh: the model has no patches");
  const int grid_level = model.geometry.front().level;
  if (level < 0) level = grid_level;
  if (level > grid_level) {
    throw InvalidInput("decoded_mesh: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(grid_level) + "]");
  }
  std::vector<SideLink> adjacency;
  for (const codec::PatchSeam& s : model.seams)
    adjacency.push_back({s.patch, s.side, s.other_patch, s.other_side, s.reversed});
  UniformRemeshResult remesh = uniform_remesh_connectivity(model.geometry.size(), adjacency, level);

  const int stride = 1 << (grid_level - level);
  const int n = (1 << level) + 1;
  const int grid_n = (1 << grid_level) + 1;
  for (std::size_t p = 0; p < model.geometry.size(); ++p) {
    const codec::Grid3& grid = model.geometry[p];
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float* v = grid.values.data() + 3 * (static_cast<std::size_t>(j * stride) * grid_n + i * stride);
        remesh.mesh.positions[remesh.grid_vertex[p][static_cast<std::size_t>(j) * n + i]] = {v[0], v[1], v[2]};
      }
    }
  }
  if (model.hole_mask.empty()) return std::move(remesh.mesh);

  // Quad q of patch p at this level → triangles 2q, 2q+1 (uniform_remesh_connectivity's order).
  // A quad of this level is left out when every mask quad it overlaps is masked (a finer mask), or when the
  // mask quad containing it is (a coarser mask).
  const int intervals = 1 << level;
  const int mask_level = model.hole_mask_level;
  const int mask_intervals = 1 << mask_level;
  const int span = mask_level >= level ? 1 << (mask_level - level) : 1;
  const int shrink = mask_level >= level ? 0 : level - mask_level;
  TriMesh out;
  std::vector<int> new_id(remesh.mesh.positions.size(), -1);
  for (std::size_t p = 0; p < model.geometry.size(); ++p) {
    const std::vector<std::uint8_t>& mask = model.hole_mask[p];
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i) {
        bool masked = true;
        const int i0 = (i >> shrink) * span, j0 = (j >> shrink) * span;
        for (int jj = j0; jj < j0 + span && masked; ++jj)
          for (int ii = i0; ii < i0 + span && masked; ++ii)
            masked = mask[static_cast<std::size_t>(jj) * mask_intervals + ii] != 0;
        if (masked) continue;
        const std::size_t q = (p * intervals + j) * static_cast<std::size_t>(intervals) + i;
        for (std::size_t t = 2 * q; t < 2 * q + 2; ++t) {
          std::array<int, 3> tri = remesh.mesh.triangles[t];
          for (int& v : tri) {
            if (new_id[v] < 0) {
              new_id[v] = static_cast<int>(out.positions.size());
              out.positions.push_back(remesh.mesh.positions[v]);
            }
            v = new_id[v];
          }
          out.triangles.push_back(tri);
        }
      }
    }
  }
  return out;
}

}  // namespace geomip::tools
