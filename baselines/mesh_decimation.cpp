#include "baselines/mesh_decimation.h"

#include "mesh/errors.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace geomip {
namespace {

// Keeps the referenced vertices of `indices` (a triangle list into `mesh.positions`), renumbered in first-use
// order; drops faces with a repeated corner.
TriMesh compact(const TriMesh& mesh, const std::vector<unsigned int>& indices) {
  TriMesh out;
  std::vector<int> remap(mesh.positions.size(), -1);
  out.triangles.reserve(indices.size() / 3);
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const unsigned a = indices[i], b = indices[i + 1], c = indices[i + 2];
    if (a == b || b == c || a == c) continue;
    std::array<int, 3> t{};
    const unsigned corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      int& r = remap[corners[k]];
      if (r < 0) {
        r = static_cast<int>(out.positions.size());
        out.positions.push_back(mesh.positions[corners[k]]);
      }
      t[k] = r;
    }
    out.triangles.push_back(t);
  }
  return out;
}

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// The triangles `indices` of `mesh` as a CGAL surface mesh; empty (with `why` set) when they do not form an
// oriented 2-manifold, which CGAL's half-edge structure (and so its edge collapse) needs.
std::optional<SurfaceMesh> surface_mesh(const TriMesh& mesh, const std::vector<unsigned int>& indices,
                                        std::string& why) {
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vertex(mesh.positions.size());
  std::vector<bool> used(mesh.positions.size(), false);
  for (unsigned i : indices) used[i] = true;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    if (used[v]) {
      const Eigen::Vector3d& p = mesh.positions[v];
      vertex[v] = sm.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z()));
    }
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3)
    if (sm.add_face(vertex[indices[i]], vertex[indices[i + 1]], vertex[indices[i + 2]]) ==
        SurfaceMesh::null_face()) {
      why = "triangle " + std::to_string(i / 3) + " makes it non-manifold or flips the orientation";
      return std::nullopt;
    }
  return sm;
}

// The triangles of `mesh` without those with a repeated corner (what every decimation works on).
std::vector<unsigned int> proper_triangles(const TriMesh& mesh) {
  const auto nv = mesh.positions.size();
  std::vector<unsigned int> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int i : t)
      if (i < 0 || static_cast<std::size_t>(i) >= nv)
        throw InvalidInput("decimate_mesh: triangle index out of range");
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    indices.insert(indices.end(),
                   {static_cast<unsigned>(t[0]), static_cast<unsigned>(t[1]), static_cast<unsigned>(t[2])});
  }
  return indices;
}

// CGAL edge_collapse with the Lindstrom–Turk defaults on the triangles `indices` of `mesh`.
TriMesh lindstrom_turk(const TriMesh& mesh, const std::vector<unsigned int>& indices,
                       std::size_t target_faces) {
  std::string why;
  std::optional<SurfaceMesh> built = surface_mesh(mesh, indices, why);
  if (!built)
    throw InvalidInput("decimate_mesh: Lindstrom-Turk decimation needs an oriented 2-manifold; " + why);
  SurfaceMesh& sm = *built;
  // Count_stop_predicate stops on the edge count: E = (3F + B)/2 with B the boundary edges, which shrink as
  // the boundary is simplified too; so stop on the current B, then continue while the faces overshoot.
  for (int pass = 0; pass < 4; ++pass) {
    std::size_t boundary_edges = 0;
    for (auto h : sm.halfedges())
      if (!sm.is_removed(h) && sm.is_border(h)) ++boundary_edges;
    if (static_cast<double>(sm.number_of_faces()) <= 1.01 * static_cast<double>(target_faces)) break;
    CGAL::Surface_mesh_simplification::Count_stop_predicate<SurfaceMesh> stop(
        (3 * target_faces + boundary_edges) / 2);
    if (CGAL::Surface_mesh_simplification::edge_collapse(sm, stop) == 0) break;  // no collapse left
  }
  sm.collect_garbage();

  TriMesh out;
  std::vector<int> index(sm.number_of_vertices(), -1);
  for (auto v : sm.vertices()) {
    if (sm.is_isolated(v)) continue;
    index[v.idx()] = static_cast<int>(out.positions.size());
    const auto& p = sm.point(v);
    out.positions.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : sm.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) t[k++] = index[v.idx()];
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace

DecimationResult decimate_mesh(const TriMesh& mesh, std::size_t target_faces,
                               const DecimationOptions& options) {
  const std::string fn = "decimate_mesh: ";
  if (mesh.triangles.empty()) throw InvalidInput(fn + "the mesh has no triangles");
  if (target_faces < 1) throw InvalidInput(fn + "target_faces must be at least 1");
  const auto nv = mesh.positions.size();
  std::vector<float> xyz(3 * nv);
  for (std::size_t v = 0; v < nv; ++v) {
    if (!mesh.positions[v].allFinite()) throw InvalidInput(fn + "non-finite vertex coordinate");
    for (int k = 0; k < 3; ++k) xyz[3 * v + k] = static_cast<float>(mesh.positions[v][k]);
  }
  const std::vector<unsigned int> indices = proper_triangles(mesh);
  DecimationResult result;
  const std::size_t faces = indices.size() / 3;
  if (target_faces >= faces) {
    result.mesh = compact(mesh, indices);
    return result;
  }

  if (options.method == DecimationMethod::kLindstromTurk) {
    result.mesh = lindstrom_turk(mesh, indices, target_faces);
    return result;
  }

  const auto target_error = static_cast<float>(options.target_error);
  std::vector<unsigned int> out(indices.size());
  float error = 0;
  std::size_t count = meshopt_simplify(out.data(), indices.data(), indices.size(), xyz.data(), nv,
                                       3 * sizeof(float), 3 * target_faces, target_error, 0, &error);
  out.resize(count);
  result.relative_error = error;

  const double limit = (1 + options.tolerance) * static_cast<double>(target_faces);
  if (options.sloppy_fallback && static_cast<double>(count / 3) > limit) {
    std::vector<unsigned int> sloppy(indices.size());
    float sloppy_error = 0;
    const std::size_t sloppy_count =
        meshopt_simplifySloppy(sloppy.data(), indices.data(), indices.size(), xyz.data(), nv,
                               3 * sizeof(float), 3 * target_faces, target_error, &sloppy_error);
    const auto gap = [&](std::size_t c) {
      return std::abs(static_cast<double>(c / 3) - double(target_faces));
    };
    if (sloppy_count > 0 && gap(sloppy_count) < gap(count)) {
      sloppy.resize(sloppy_count);
      out.swap(sloppy);
      result.used_sloppy = true;
      result.relative_error = sloppy_error;
    }
  }
  result.mesh = compact(mesh, out);
  return result;
}

std::optional<std::string> lindstrom_turk_refusal(const TriMesh& mesh) {
  if (mesh.triangles.empty()) return "the mesh has no triangles";
  std::string why;
  if (!surface_mesh(mesh, proper_triangles(mesh), why)) return "not an oriented 2-manifold: " + why;
  return std::nullopt;
}

}  // namespace geomip
