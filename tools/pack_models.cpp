#include "tools/pack_models.h"

#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"

#include <algorithm>

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

namespace {

/// Where an output vertex of decoded_mesh() comes from: patch p, sample (i, j) of the level-`level` grid.
struct GridSample {
  int patch, i, j;
};

/// The level-`level` samples of `model`'s grids in `remesh`'s vertex numbering (seam samples written once per
/// patch; the codec keeps them bit-identical).
std::vector<Eigen::Vector3d> grid_positions(const UniformRemeshResult& remesh, const codec::DecodedModel& model,
                                            int level) {
  const int grid_level = model.geometry.front().level;
  const int stride = 1 << (grid_level - level);
  const int n = (1 << level) + 1;
  const int grid_n = (1 << grid_level) + 1;
  std::vector<Eigen::Vector3d> positions(remesh.mesh.positions.size(), Eigen::Vector3d::Zero());
  for (std::size_t p = 0; p < model.geometry.size(); ++p) {
    const codec::Grid3& grid = model.geometry[p];
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float* v = grid.values.data() + 3 * (static_cast<std::size_t>(j * stride) * grid_n + i * stride);
        positions[remesh.grid_vertex[p][static_cast<std::size_t>(j) * n + i]] = {v[0], v[1], v[2]};
      }
    }
  }
  return positions;
}

/// decoded_mesh() with `weld` choosing whether seams are welded (the model's seams) or not (every patch its
/// own vertices; the quads split as in the welded mesh: each split depends only on the quad's corners);
/// `origin`, if given, receives each output vertex's first grid sample.
TriMesh decoded_mesh_impl(const codec::DecodedModel& model, int level, bool weld, const QuadSplitOptions& split,
                          std::vector<GridSample>* origin) {
  if (model.geometry.empty()) throw InvalidInput("decoded_mesh: the model has no patches");
  const int grid_level = model.geometry.front().level;
  if (level < 0) level = grid_level;
  if (level > grid_level) {
    throw InvalidInput("decoded_mesh: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(grid_level) + "]");
  }
  std::vector<SideLink> adjacency;
  if (weld) {
    for (const codec::PatchSeam& s : model.seams)
      adjacency.push_back({s.patch, s.side, s.other_patch, s.other_side, s.reversed});
  }
  UniformRemeshResult remesh = uniform_remesh_connectivity(model.geometry.size(), adjacency, level);
  remesh.mesh.positions = grid_positions(remesh, model, level);
  if (split.split == QuadSplit::kShorter) {
    // The model's own positions are used as they are; the other choosing models' are gathered.
    std::vector<std::vector<Eigen::Vector3d>> others;
    std::vector<const std::vector<Eigen::Vector3d>*> views;
    if (split.chosen_by.empty()) views.push_back(&remesh.mesh.positions);
    others.reserve(split.chosen_by.size());
    for (const codec::DecodedModel* other : split.chosen_by) {
      if (other == nullptr || other->geometry.size() != model.geometry.size() ||
          other->geometry.front().level != grid_level) {
        throw InvalidInput("decoded_mesh: a model choosing the quad split has another layout or grid level");
      }
      if (other == &model) {
        views.push_back(&remesh.mesh.positions);
      } else {
        others.push_back(grid_positions(remesh, *other, level));
        views.push_back(&others.back());
      }
    }
    split_along_shorter_diagonals(remesh, level, views);
  }

  const int n = (1 << level) + 1;
  std::vector<GridSample> first(origin ? remesh.mesh.positions.size() : 0, GridSample{-1, 0, 0});
  for (std::size_t p = 0; origin && p < model.geometry.size(); ++p) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int id = remesh.grid_vertex[p][static_cast<std::size_t>(j) * n + i];
        if (first[id].patch < 0) first[id] = {static_cast<int>(p), i, j};
      }
    }
  }
  if (model.hole_mask.empty()) {
    if (origin) *origin = std::move(first);
    return std::move(remesh.mesh);
  }

  // Quad q of patch p at this level → triangles 2q, 2q+1 (uniform_remesh_connectivity's order).
  // A quad of this level is left out when every mask quad it overlaps is masked (a finer mask), or when the
  // mask quad containing it is (a coarser mask).
  const int intervals = 1 << level;
  const int mask_level = model.hole_mask_level;
  const int mask_intervals = 1 << mask_level;
  const int span = mask_level >= level ? 1 << (mask_level - level) : 1;
  const int shrink = mask_level >= level ? 0 : level - mask_level;
  TriMesh out;
  if (origin) origin->clear();
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
              if (origin) origin->push_back(first[v]);
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

}  // namespace

TriMesh decoded_mesh(const codec::DecodedModel& model, int level, const QuadSplitOptions& split) {
  return decoded_mesh_impl(model, level, /*weld=*/true, split, nullptr);
}

TexturedMesh decoded_textured_mesh(const codec::DecodedModel& model, int level, const QuadSplitOptions& split) {
  std::vector<GridSample> origin;
  TexturedMesh result;
  result.mesh = decoded_mesh_impl(model, level, /*weld=*/false, split, &origin);
  const int grid_level = model.geometry.front().level;
  if (level < 0) level = grid_level;
  const double intervals = static_cast<double>(1 << level);
  const bool has_normal_maps = model.normals.size() == model.geometry.size() &&
                               std::all_of(model.normals.begin(), model.normals.end(),
                                           [&](const codec::Grid3& g) {
                                             // A map still all zero: its passes have not arrived yet.
                                             return g.level >= level &&
                                                    std::any_of(g.values.begin(), g.values.end(),
                                                                [](float x) { return x != 0; });
                                           });
  const std::vector<Eigen::Vector3d> geometry_normals =
      has_normal_maps ? std::vector<Eigen::Vector3d>() : vertex_normals(result.mesh);
  result.attributes.uv.reserve(origin.size());
  result.attributes.normals.reserve(origin.size());
  for (std::size_t v = 0; v < origin.size(); ++v) {
    const GridSample& s = origin[v];
    result.attributes.uv.emplace_back(static_cast<float>(s.i / intervals), static_cast<float>(s.j / intervals));
    Eigen::Vector3d n;
    if (has_normal_maps) {
      const codec::Grid3& map = model.normals[static_cast<std::size_t>(s.patch)];
      const int stride = 1 << (map.level - level);
      const float* t = map.values.data() + 3 * (static_cast<std::size_t>(s.j * stride) * map.size() + s.i * stride);
      n = Eigen::Vector3d(t[0], t[1], t[2]);
    } else {
      n = geometry_normals[v];
    }
    // Decoded normal-map texels are not exactly unit (quantized); a zero one (a prefix before the normal
    // maps arrive) falls back to +z rather than NaN.
    const double length = n.norm();
    result.attributes.normals.push_back(length > 0 ? Eigen::Vector3f((n / length).cast<float>())
                                                   : Eigen::Vector3f(0, 0, 1));
  }
  return result;
}

namespace {

codec::DecodedModel model_of(const GeometryImages& images, bool normals) {
  const codec::PackModelInput input = pack_model_input("", images, nullptr, normals && !images.normals.empty());
  codec::DecodedModel model;
  model.geometry = input.geometry;
  model.normals = input.normals;
  model.seams = input.seams;
  return model;
}

}  // namespace

TexturedMesh textured_mesh(const GeometryImages& images, QuadSplit split,
                           const std::vector<const GeometryImages*>& chosen_by) {
  std::vector<codec::DecodedModel> others;
  for (const GeometryImages* g : chosen_by) others.push_back(model_of(*g, false));
  std::vector<const codec::DecodedModel*> views;
  for (const auto& m : others) views.push_back(&m);
  return decoded_textured_mesh(model_of(images, true), -1, {.split = split, .chosen_by = views});
}

}  // namespace geomip::tools
