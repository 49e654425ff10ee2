// The only translation unit of geomip::param that includes CGAL's Polygon Mesh Processing (compile time).
#include "mesh/mesh_repair.h"

#include "mesh/errors.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>

namespace geomip {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

void report(const RepairOptions& o, const char* stage, double f) {
  if (o.progress) o.progress(stage, f);
}

struct PositionHash {
  std::size_t operator()(const Eigen::Vector3d& p) const {
    std::size_t h = std::hash<double>()(p.x());
    h ^= std::hash<double>()(p.y()) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= std::hash<double>()(p.z()) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    return h;
  }
};
struct PositionEqual {
  bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const { return a == b; }
};

// Keeps the largest edge-connected component of `polygons` (by faces; the one with the first face on a tie),
// then drops the points no kept face references, keeping the survivors' order.
void keep_largest_component(std::vector<Point>& points, std::vector<std::array<std::size_t, 3>>& polygons,
                            RepairResult& result) {
  const std::size_t nf = polygons.size();
  std::vector<std::size_t> parent(nf);
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  // Faces sharing an undirected edge are joined (as analyze_topology() counts components).
  std::vector<std::array<std::size_t, 3>> edges;  // (min vertex, max vertex, face)
  edges.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t a = polygons[f][k], b = polygons[f][(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges[i][0] == edges[i - 1][0] && edges[i][1] == edges[i - 1][1]) {
      const std::size_t a = find(edges[i][2]), b = find(edges[i - 1][2]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<std::size_t> size(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) ++size[find(f)];
  std::size_t best = 0, components = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    if (size[f] == 0) continue;
    ++components;
    if (size[f] > size[best]) best = f;
  }
  if (components <= 1) return;
  result.removed_components = components - 1;
  result.removed_component_faces = nf - size[best];

  std::vector<std::array<std::size_t, 3>> kept;
  kept.reserve(size[best]);
  std::vector<char> used(points.size(), 0);
  for (std::size_t f = 0; f < nf; ++f) {
    if (find(f) != best) continue;
    kept.push_back(polygons[f]);
    for (std::size_t v : polygons[f]) used[v] = 1;
  }
  std::vector<std::size_t> remap(points.size(), 0);
  std::vector<Point> kept_points;
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (!used[v]) continue;
    remap[v] = kept_points.size();
    kept_points.push_back(points[v]);
  }
  for (auto& t : kept) {
    for (std::size_t& v : t) v = remap[v];
  }
  points = std::move(kept_points);
  polygons = std::move(kept);
}

}  // namespace

RepairResult repair_mesh(const TriMesh& input, const RepairOptions& options) {
  if (input.triangles.empty()) throw InvalidInput("repair_mesh: the mesh has no triangles");
  const std::size_t nv = input.positions.size();
  RepairResult result;

  // 1. Referenced vertices, duplicates merged, original order kept.
  report(options, "cleaning", 0.0);
  std::vector<char> referenced(nv, 0);
  for (const auto& t : input.triangles) {
    for (int v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) throw InvalidInput("repair_mesh: vertex index out of range");
      referenced[v] = 1;
    }
  }
  std::vector<int> remap(nv, -1);
  std::vector<Point> points;
  std::unordered_map<Eigen::Vector3d, int, PositionHash, PositionEqual> first_at;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!referenced[v]) {
      ++result.removed_unreferenced_vertices;
      continue;
    }
    const Eigen::Vector3d& p = input.positions[v];
    if (!p.allFinite()) throw InvalidInput("repair_mesh: vertex " + std::to_string(v) + " is not finite");
    auto [it, inserted] = first_at.emplace(p, static_cast<int>(points.size()));
    if (inserted) {
      points.emplace_back(p.x(), p.y(), p.z());
    } else {
      ++result.merged_duplicate_vertices;
    }
    remap[v] = it->second;
  }

  // 2. Faces with a repeated vertex and duplicate faces (either orientation).
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(input.triangles.size());
  std::set<std::array<int, 3>> seen;
  for (const auto& t : input.triangles) {
    const std::array<int, 3> r{remap[t[0]], remap[t[1]], remap[t[2]]};
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) {
      ++result.removed_degenerate_faces;
      continue;
    }
    std::array<int, 3> key = r;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++result.removed_degenerate_faces;
      continue;
    }
    polygons.push_back({std::size_t(r[0]), std::size_t(r[1]), std::size_t(r[2])});
  }
  if (polygons.empty()) throw InvalidInput("repair_mesh: every face is degenerate");
  if (options.largest_component_only) keep_largest_component(points, polygons, result);

  // 3. Non-manifold vertices and edges: orient_polygon_soup duplicates the points it must split (appended).
  report(options, "splitting non-manifold vertices", 0.2);
  const std::size_t points_before = points.size();
  PMP::orient_polygon_soup(points, polygons);
  result.split_non_manifold_vertices = points.size() - points_before;

  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  if (!CGAL::is_triangle_mesh(sm) || !sm.is_valid(false)) {
    throw SolverFailure("repair_mesh: the oriented polygon soup did not form a valid surface mesh");
  }

  // Zero-area faces: collapse them away (only if there are any; the collapse can remove vertices).
  const std::size_t faces_before = sm.number_of_faces();
  bool has_degenerate = false;
  for (auto f : sm.faces()) {
    if (PMP::is_degenerate_triangle_face(f, sm)) {
      has_degenerate = true;
      break;
    }
  }
  if (has_degenerate) {
    PMP::remove_degenerate_faces(sm);
    result.removed_degenerate_faces += faces_before - sm.number_of_faces();
  }

  // 4. Holes.
  if (options.fill_holes) {
    std::vector<SurfaceMesh::Halfedge_index> holes;
    PMP::extract_boundary_cycles(sm, std::back_inserter(holes));
    for (std::size_t i = 0; i < holes.size(); ++i) {
      report(options, "filling holes", 0.3 + 0.6 * double(i) / double(holes.size()));
      std::vector<SurfaceMesh::Face_index> new_faces;
      std::vector<SurfaceMesh::Vertex_index> new_vertices;
      const auto filled = PMP::triangulate_refine_and_fair_hole(
          sm, holes[i], std::back_inserter(new_faces), std::back_inserter(new_vertices),
          CGAL::parameters::density_control_factor(options.hole_density)
              .fairing_continuity(options.fairing_continuity));
      ++result.filled_holes;
      if (!std::get<0>(filled)) ++result.unfaired_holes;
      result.added_vertices += new_vertices.size();
    }
  }

  // 5. Outward orientation of a closed result.
  if (CGAL::is_closed(sm) && !PMP::is_outward_oriented(sm)) {
    PMP::reverse_face_orientations(sm);
    result.reoriented = true;
  }

  // Export in vertex index order (removed vertices skipped, so surviving originals keep their order).
  report(options, "exporting", 0.95);
  std::vector<int> index(sm.num_vertices(), -1);
  TriMesh& out = result.mesh;
  out.positions.reserve(sm.number_of_vertices());
  for (auto v : sm.vertices()) {
    index[v.idx()] = static_cast<int>(out.positions.size());
    const Point& p = sm.point(v);
    out.positions.emplace_back(p.x(), p.y(), p.z());
  }
  out.triangles.reserve(sm.number_of_faces());
  for (auto f : sm.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) t[k++] = index[v.idx()];
    out.triangles.push_back(t);
  }
  report(options, "done", 1.0);
  return result;
}

std::optional<std::vector<std::size_t>> self_intersecting_faces(const TriMesh& mesh,
                                                                SelfIntersections* counts) {
  std::vector<Point> points;
  points.reserve(mesh.num_vertices());
  for (const auto& p : mesh.positions) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::array<std::size_t, 3>> polygons;
  std::vector<std::size_t> original;  // polygons[k] is mesh.triangles[original[k]]
  polygons.reserve(mesh.num_triangles());
  original.reserve(mesh.num_triangles());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const std::array<std::size_t, 3> f{std::size_t(tri[0]), std::size_t(tri[1]), std::size_t(tri[2])};
    if (f[0] >= points.size() || f[1] >= points.size() || f[2] >= points.size())
      throw InvalidInput("count_self_intersections: a triangle index is out of range");
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] ||
        CGAL::collinear(points[f[0]], points[f[1]], points[f[2]]))
      continue;
    polygons.push_back(f);
    original.push_back(t);
  }
  if (polygons.empty() || !PMP::is_polygon_soup_a_polygon_mesh(polygons)) return std::nullopt;
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
  PMP::self_intersections(sm, std::back_inserter(pairs));
  // polygon_soup_to_polygon_mesh adds the faces in the soup's order.
  std::vector<std::size_t> faces;
  faces.reserve(2 * pairs.size());
  for (const auto& [a, b] : pairs) faces.push_back(original[a.idx()]), faces.push_back(original[b.idx()]);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  if (counts) {
    counts->pairs = pairs.size();
    counts->faces = faces.size();
  }
  return faces;
}

std::optional<SelfIntersections> count_self_intersections(const TriMesh& mesh) {
  SelfIntersections counts;
  if (!self_intersecting_faces(mesh, &counts)) return std::nullopt;
  return counts;
}

}  // namespace geomip
