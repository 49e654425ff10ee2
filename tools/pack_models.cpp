#include "tools/pack_models.h"

#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

/// The point of triangle (a, b, c) closest to p (Ericson, Real-Time Collision Detection, §5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return a;  // degenerate triangle
  return a + ab * (vb / denom) + ac * (vc / denom);
}

/// The level-`level` grids of `model` as one mesh before any hole mask: `remesh`'s numbering (seams welded
/// when `weld`), its positions the model's samples, its quads split as `split` says.
UniformRemeshResult grid_mesh(const codec::DecodedModel& model, int level, bool weld,
                              const QuadSplitOptions& split) {
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
  return remesh;
}

/// decoded_mesh() with `weld` choosing whether seams are welded (the model's seams) or not (every patch its
/// own vertices; the quads split as in the welded mesh: each split depends only on the quad's corners);
/// `origin`, if given, receives each output vertex's first grid sample.
TriMesh decoded_mesh_impl(const codec::DecodedModel& model, int level, bool weld,
                          const QuadSplitOptions& split, std::vector<GridSample>* origin) {
  if (model.geometry.empty()) throw InvalidInput("decoded_mesh: the model has no patches");
  if (level < 0) level = model.geometry.front().level;
  UniformRemeshResult remesh = grid_mesh(model, level, weld, split);

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

UntangleStats untangle_decoded_model(codec::DecodedModel& model, const QuadSplitOptions& split,
                                     const UntangleOptions& options_in) {
  UntangleStats stats;
  if (model.geometry.empty()) return stats;
  const UntangleOptions& options = options_in;
  const int level = model.geometry.front().level;
  std::size_t samples = 0;
  for (const codec::Grid3& g : model.geometry) samples += g.values.size() / 3;
  if (level < options.min_level || samples > options.max_samples) return stats;  // applied = false
  stats.applied = true;
  UniformRemeshResult remesh = grid_mesh(model, level, /*weld=*/true, split);
  std::vector<Eigen::Vector3d>& x = remesh.mesh.positions;
  const std::vector<std::array<int, 3>>& tris = remesh.mesh.triangles;
  const std::size_t nv = x.size();

  // Vertex → triangles and vertex → neighbours (compressed rows).
  std::vector<int> tri_start(nv + 1, 0), tri_of;
  for (const auto& t : tris)
    for (int v : t) ++tri_start[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < nv; ++v) tri_start[v + 1] += tri_start[v];
  tri_of.resize(static_cast<std::size_t>(tri_start[nv]));
  {
    std::vector<int> fill(tri_start.begin(), tri_start.end() - 1);
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int v : tris[t])
        tri_of[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = static_cast<int>(t);
  }
  auto face_normal = [&](std::size_t t) {  // area-weighted (twice the area)
    const auto& f = tris[t];
    return Eigen::Vector3d((x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]));
  };

  // The reference normal: the area-weighted vertex normals smoothed over `options.normal_rings` rings, so the
  // few triangles of a fold do not turn it (a fold is a handful of triangles; the surface around it is not).
  std::vector<Eigen::Vector3d> ref(nv, Eigen::Vector3d::Zero()), next(nv), face_sum(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const Eigen::Vector3d n = face_normal(t);
    for (int v : tris[t]) ref[static_cast<std::size_t>(v)] += n;
  }
  // Rings scale with the grid: 20 at level 8 (8 % of a patch side), fewer on coarser grids, where 20 rings
  // would span patches and average the two sides of a leg.
  const int rings =
      std::clamp(static_cast<int>(std::lround(options.normal_rings * std::ldexp(1.0, level - 8))),
                 std::min(2, options.normal_rings), options.normal_rings);
  for (int ring = 0; ring < rings; ++ring) {
    for (auto& n : ref) n.normalize();               // a zero vector stays zero
    for (std::size_t t = 0; t < tris.size(); ++t) {  // per triangle: the sum of its corners' normals
      const auto& f = tris[t];
      face_sum[t] = ref[f[0]] + ref[f[1]] + ref[f[2]];
    }
    for (std::size_t v = 0; v < nv; ++v) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int k = tri_start[v]; k < tri_start[v + 1]; ++k)
        sum += face_sum[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])];
      next[v] = sum;
    }
    ref.swap(next);
  }
  for (auto& n : ref) {
    const double length = n.norm();
    n = length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
  auto folded = [&](std::size_t t) {
    const auto& f = tris[t];
    const Eigen::Vector3d r = ref[f[0]] + ref[f[1]] + ref[f[2]];
    return face_normal(t).dot(r) < 0;
  };

  // Vertices of folded triangles move towards their neighbours' centroid within the reference tangent plane
  // (the surface stays where it is, the fold opens), sweep after sweep, the set growing with any triangle a
  // move folds; what tangential moves cannot open gets the whole step in the last sweeps.
  std::vector<char> active(nv, 0), fold(tris.size(), 0);
  std::vector<std::size_t> set;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (!folded(t)) continue;
    fold[t] = 1;
    ++stats.folded_before;
    for (int v : tris[t])
      if (!active[static_cast<std::size_t>(v)])
        active[static_cast<std::size_t>(v)] = 1, set.push_back(static_cast<std::size_t>(v));
  }
  const std::vector<Eigen::Vector3d> start = x;
  // Each sample's mean edge length as decoded (over its triangles' other corners): the scale of its limits.
  std::vector<double> mean_edge(nv, 0.0);
  for (std::size_t v = 0; v < nv; ++v) {
    double sum = 0;
    int count = 0;
    for (int k = tri_start[v]; k < tri_start[v + 1]; ++k)
      for (int w : tris[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])])
        if (static_cast<std::size_t>(w) != v)
          sum += (start[static_cast<std::size_t>(w)] - start[v]).norm(), ++count;
    if (count > 0) mean_edge[v] = sum / count;
  }
  for (int sweep = 0; sweep < options.max_sweeps && !set.empty(); ++sweep) {
    for (std::size_t v : set) {
      bool touches_fold = false;  // only the samples of a triangle still folded move
      for (int k = tri_start[v]; k < tri_start[v + 1] && !touches_fold; ++k)
        touches_fold = fold[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])] != 0;
      if (!touches_fold) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      for (int k = tri_start[v]; k < tri_start[v + 1]; ++k)
        for (int w : tris[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])])
          if (static_cast<std::size_t>(w) != v) sum += x[static_cast<std::size_t>(w)], ++count;
      if (count == 0) continue;
      Eigen::Vector3d d = sum / count - x[v];
      d -= d.dot(ref[v]) * ref[v];
      Eigen::Vector3d moved = x[v] + options.step * d;
      {
        // Back onto the decoded surface as it was (its triangles around v, two rings): the fold opens along
        // the surface instead of leaving it.
        double best = std::numeric_limits<double>::infinity();
        Eigen::Vector3d on = moved;
        for (int k = tri_start[v]; k < tri_start[v + 1]; ++k)
          for (int w : tris[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])])
            for (int k2 = tri_start[static_cast<std::size_t>(w)];
                 k2 < tri_start[static_cast<std::size_t>(w) + 1]; ++k2) {
              const auto t2 = static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k2)]);
              const auto& f = tris[t2];
              const Eigen::Vector3d q = closest_on_triangle(moved, start[f[0]], start[f[1]], start[f[2]]);
              const double dist = (q - moved).squaredNorm();
              if (dist < best) best = dist, on = q;
            }
        moved = on;
      }
      // No sample slides farther than `max_slide` of its mean edge length from where it was decoded: a sample
      // that slid far would take its triangles' corners along (a leg's tip samples slid towards the body and
      // the leg shortened; measured on coarse grids).
      const double edge = mean_edge[v];
      if (edge > 0 && (moved - start[v]).norm() > options.max_slide * edge) continue;
      // The fan around v must stay on the decoded surface too, not only v: each of its triangles' centroids
      // within `max_fan_gap` mean edge lengths of the surface as it was (two rings around v).
      if (edge > 0 && options.max_fan_gap > 0) {
        const Eigen::Vector3d keep = x[v];
        x[v] = moved;
        const double limit = options.max_fan_gap * edge;
        bool far = false;
        for (int k = tri_start[v]; k < tri_start[v + 1] && !far; ++k) {
          const auto& f = tris[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])];
          const Eigen::Vector3d c = (x[f[0]] + x[f[1]] + x[f[2]]) / 3.0;
          double best2 = std::numeric_limits<double>::infinity();
          for (int w : f)
            for (int k2 = tri_start[static_cast<std::size_t>(w)];
                 k2 < tri_start[static_cast<std::size_t>(w) + 1]; ++k2) {
              const auto& g = tris[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k2)])];
              best2 = std::min(
                  best2, (closest_on_triangle(c, start[g[0]], start[g[1]], start[g[2]]) - c).squaredNorm());
            }
          far = best2 > limit * limit;
        }
        if (far) {
          x[v] = keep;
          continue;
        }
      }
      x[v] = moved;
    }
    // Re-check the triangles around the set; grow it by the vertices of any folded one.
    std::size_t remaining = 0;
    const std::size_t size = set.size();
    for (std::size_t s = 0; s < size; ++s) {
      const std::size_t v = set[s];
      for (int k = tri_start[v]; k < tri_start[v + 1]; ++k) {
        const auto t = static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)]);
        fold[t] = folded(t);
        if (!fold[t]) continue;
        for (int w : tris[t])
          if (!active[static_cast<std::size_t>(w)])
            active[static_cast<std::size_t>(w)] = 1, set.push_back(static_cast<std::size_t>(w));
      }
    }
    for (std::size_t v : set)
      for (int k = tri_start[v]; k < tri_start[v + 1]; ++k)
        remaining += fold[static_cast<std::size_t>(tri_of[static_cast<std::size_t>(k)])];
    stats.sweeps = sweep + 1;
    if (remaining == 0) break;
  }
  for (std::size_t t = 0; t < tris.size(); ++t) stats.folded_after += folded(t) ? 1 : 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (x[v] == start[v]) continue;
    ++stats.moved;
    stats.max_move = std::max(stats.max_move, (x[v] - start[v]).norm());
  }

  // Back into every patch's grid (a seam sample into each patch that has it: they stay bit-identical).
  const int n = (1 << level) + 1;
  for (std::size_t p = 0; p < model.geometry.size(); ++p) {
    float* values = model.geometry[p].values.data();
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t q = static_cast<std::size_t>(j) * n + i;
        const Eigen::Vector3d& v = x[static_cast<std::size_t>(remesh.grid_vertex[p][q])];
        for (int c = 0; c < 3; ++c) values[3 * q + c] = static_cast<float>(v[c]);
      }
  }
  return stats;
}

TriMesh decoded_mesh(const codec::DecodedModel& model, int level, const QuadSplitOptions& split) {
  return decoded_mesh_impl(model, level, /*weld=*/true, split, nullptr);
}

namespace {

// Whether `model`'s normal maps can give every level-`level` sample a normal: one per patch, at that level
// or finer, none still all zero (its passes not arrived yet).
bool has_normal_maps(const codec::DecodedModel& model, int level) {
  return model.normals.size() == model.geometry.size() &&
         std::all_of(model.normals.begin(), model.normals.end(), [&](const codec::Grid3& g) {
           return g.level >= level &&
                  std::any_of(g.values.begin(), g.values.end(), [](float x) { return x != 0; });
         });
}

// The normal map texel of level-`level` sample `s` (not normalized).
Eigen::Vector3d map_normal(const codec::DecodedModel& model, const GridSample& s, int level) {
  const codec::Grid3& map = model.normals[static_cast<std::size_t>(s.patch)];
  const int stride = 1 << (map.level - level);
  const float* t =
      map.values.data() + 3 * (static_cast<std::size_t>(s.j * stride) * map.size() + s.i * stride);
  return Eigen::Vector3d(t[0], t[1], t[2]);
}

// Unit length; a zero normal (a prefix before the normal maps arrive) falls back to +z rather than NaN.
Eigen::Vector3f unit_or_z(const Eigen::Vector3d& n) {
  const double length = n.norm();
  return length > 0 ? Eigen::Vector3f((n / length).cast<float>()) : Eigen::Vector3f(0, 0, 1);
}

}  // namespace

TriMesh decoded_mesh_with_map_normals(const codec::DecodedModel& model, int level,
                                      const QuadSplitOptions& split, std::vector<Eigen::Vector3f>& normals) {
  std::vector<GridSample> origin;
  TriMesh mesh = decoded_mesh_impl(model, level, /*weld=*/true, split, &origin);
  if (level < 0) level = model.geometry.front().level;
  normals.clear();
  if (!has_normal_maps(model, level)) return mesh;
  normals.reserve(origin.size());
  // A seam sample's texels are bit-identical in every patch that has it (the codec codes them once).
  for (const GridSample& s : origin) normals.push_back(unit_or_z(map_normal(model, s, level)));
  return mesh;
}

TexturedMesh decoded_textured_mesh(const codec::DecodedModel& model, int level, const QuadSplitOptions& split) {
  std::vector<GridSample> origin;
  TexturedMesh result;
  result.mesh = decoded_mesh_impl(model, level, /*weld=*/false, split, &origin);
  const int grid_level = model.geometry.front().level;
  if (level < 0) level = grid_level;
  const double intervals = static_cast<double>(1 << level);
  const bool maps = has_normal_maps(model, level);
  const std::vector<Eigen::Vector3d> geometry_normals =
      maps ? std::vector<Eigen::Vector3d>() : vertex_normals(result.mesh);
  result.attributes.uv.reserve(origin.size());
  result.attributes.normals.reserve(origin.size());
  for (std::size_t v = 0; v < origin.size(); ++v) {
    const GridSample& s = origin[v];
    result.attributes.uv.emplace_back(static_cast<float>(s.i / intervals), static_cast<float>(s.j / intervals));
    result.attributes.normals.push_back(unit_or_z(maps ? map_normal(model, s, level) : geometry_normals[v]));
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

UntangleStats untangle_geometry_images(GeometryImages& images, QuadSplit split,
                                       const std::vector<const GeometryImages*>& chosen_by) {
  std::vector<codec::DecodedModel> others;
  for (const GeometryImages* g : chosen_by) others.push_back(model_of(*g, false));
  std::vector<const codec::DecodedModel*> views;
  for (const auto& m : others) views.push_back(&m);
  codec::DecodedModel model = model_of(images, false);
  const UntangleStats stats = untangle_decoded_model(model, {.split = split, .chosen_by = views});
  for (std::size_t p = 0; p < images.geometry.size(); ++p)
    images.geometry[p].values = model.geometry[p].values;
  return stats;
}

}  // namespace geomip::tools
