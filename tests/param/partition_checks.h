// Property checks of a PartitionResult, written independently of mesh_partition.cpp (they recount everything
// from the triangles), shared by the unit and real-mesh tests of partition_mesh().
#pragma once

#include "param/mesh.h"
#include "param/mesh_partition.h"
#include "param/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace geomip::test {

inline double surface_area(const TriMesh& m) {
  double a = 0.0;
  for (const auto& t : m.triangles) {
    a += 0.5 * (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm();
  }
  return a;
}

/// Every documented property of `r` = partition_mesh(input, points, aux). Returns "" when all hold, else a
/// description of the first problems found.
inline std::string check_partition(const TriMesh& input, const std::vector<int>& points, const PartitionResult& r) {
  std::ostringstream err;
  const TriMesh& m = r.mesh;
  const int nf = static_cast<int>(m.triangles.size());
  const TopologyReport in_topo = analyze_topology(input);
  const TopologyReport topo = analyze_topology(m);

  // The mesh: input vertices kept, splits appended, same surface.
  if (m.positions.size() != input.positions.size() + r.split_vertices) err << "vertex count; ";
  for (std::size_t v = 0; v < input.positions.size() && v < m.positions.size(); ++v) {
    if (m.positions[v] != input.positions[v]) {
      err << "vertex " << v << " moved; ";
      break;
    }
  }
  if (!topo.manifold || topo.boundary_edges || topo.components != 1 || topo.genus != in_topo.genus) {
    err << "output mesh topology differs from the input; ";
  }
  const double a0 = surface_area(input), a1 = surface_area(m);
  if (std::abs(a0 - a1) > 1e-9 * a0) err << "area changed " << a0 << " -> " << a1 << "; ";

  const std::size_t np = r.patches.size();
  const std::size_t expected = in_topo.genus == 0 ? 2 : 4;
  if (np != expected) {
    err << np << " patches, expected " << expected << "; ";
    return err.str();
  }
  // Every face in exactly one patch.
  if (static_cast<int>(r.face_patch.size()) != nf) err << "face_patch size; ";
  std::vector<int> owner(nf, -1);
  for (std::size_t p = 0; p < np; ++p) {
    for (int f : r.patches[p].faces) {
      if (f < 0 || f >= nf) {
        err << "face id out of range; ";
        continue;
      }
      if (owner[f] >= 0) err << "face " << f << " in two patches; ";
      owner[f] = static_cast<int>(p);
    }
  }
  for (int f = 0; f < nf; ++f) {
    if (owner[f] < 0) err << "face " << f << " in no patch; ";
    if (f < static_cast<int>(r.face_patch.size()) && r.face_patch[f] != owner[f]) err << "face_patch[" << f << "]; ";
    if (err.tellp() > 2000) return err.str();
  }

  // Corners.
  const std::set<int> point_set(points.begin(), points.end());
  for (std::size_t p = 0; p < np; ++p) {
    const auto& c = r.patches[p].corners;
    if (std::set<int>(c.begin(), c.end()) != point_set) err << "patch " << p << " corners are not the 4 points; ";
    // Genus 0: P0; genus 1: patch 2a+b starts at P_{a+2b}.
    const int first = in_topo.genus == 0 ? points[0] : points[p / 2 + 2 * (p % 2)];
    if (c[0] != first) err << "patch " << p << " corner 0 is not the documented one; ";
  }
  if (in_topo.genus == 0) {
    const std::array<int, 4> c0 = {points[0], points[1], points[2], points[3]};
    const std::array<int, 4> c1 = {points[0], points[3], points[2], points[1]};
    if (r.patches[0].corners != c0 || r.patches[1].corners != c1) err << "genus-0 corner convention; ";
  }

  // Sides and the cut.
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
  };
  std::set<std::uint64_t> mesh_halfedges;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) mesh_halfedges.insert(key(t[k], t[(k + 1) % 3]));
  }
  std::set<int> cut_vertices;
  for (std::size_t p = 0; p < np; ++p) {
    const Patch& patch = r.patches[p];
    std::set<std::uint64_t> side_halfedges;
    std::vector<int> loop;
    for (int s = 0; s < 4; ++s) {
      const auto& v = patch.sides[s].vertices;
      if (v.size() < 2 || v.front() != patch.corners[s] || v.back() != patch.corners[(s + 1) % 4]) {
        err << "patch " << p << " side " << s << " does not run between its corners; ";
        continue;
      }
      for (std::size_t i = 0; i + 1 < v.size(); ++i) {
        if (!mesh_halfedges.count(key(v[i], v[i + 1]))) err << "patch " << p << " side " << s << " not an edge path; ";
        side_halfedges.insert(key(v[i], v[i + 1]));
      }
      loop.insert(loop.end(), v.begin(), v.end() - 1);
      cut_vertices.insert(v.begin(), v.end());
    }
    if (std::set<int>(loop.begin(), loop.end()).size() != loop.size()) err << "patch " << p << " loop not simple; ";
    // Disk: boundary half-edges of the patch's faces are exactly the sides' (same direction: CCW), V−E+F = 1.
    std::map<std::uint64_t, int> edge_use;
    std::set<int> verts;
    std::set<std::uint64_t> boundary;
    for (int f : patch.faces) {
      const auto& t = m.triangles[f];
      for (int k = 0; k < 3; ++k) {
        verts.insert(t[k]);
        ++edge_use[key(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]))];
      }
    }
    for (int f : patch.faces) {
      const auto& t = m.triangles[f];
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        if (edge_use[key(std::min(a, b), std::max(a, b))] == 1) boundary.insert(key(a, b));
      }
    }
    if (boundary != side_halfedges) err << "patch " << p << " boundary is not its 4 sides walked CCW; ";
    const long long euler = static_cast<long long>(verts.size()) - static_cast<long long>(edge_use.size()) +
                            static_cast<long long>(patch.faces.size());
    if (euler != 1) err << "patch " << p << " V-E+F = " << euler << "; ";
  }
  // No triangle with all three vertices on the cut (so none with all three on one side).
  for (int f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    if (cut_vertices.count(t[0]) && cut_vertices.count(t[1]) && cut_vertices.count(t[2])) {
      err << "triangle " << f << " has all vertices on the cut; ";
      break;
    }
  }
  // Gluing: one link per (patch, side), symmetric, the other side is this one reversed, in another patch.
  if (r.adjacency.size() != 4 * np) {
    err << "adjacency size " << r.adjacency.size() << "; ";
    return err.str();
  }
  for (std::size_t i = 0; i < r.adjacency.size(); ++i) {
    const SideLink& l = r.adjacency[i];
    if (l.patch != static_cast<int>(i / 4) || l.side != static_cast<int>(i % 4)) err << "adjacency order; ";
    if (l.other_patch < 0 || l.other_patch >= static_cast<int>(np) || l.other_side < 0 || l.other_side > 3) {
      err << "adjacency out of range; ";
      continue;
    }
    if (l.other_patch == l.patch) err << "side glued to its own patch; ";
    const SideLink& back = r.adjacency[4 * l.other_patch + l.other_side];
    if (back.other_patch != l.patch || back.other_side != l.side) err << "adjacency not symmetric; ";
    auto a = r.patches[l.patch].sides[l.side].vertices;
    const auto& b = r.patches[l.other_patch].sides[l.other_side].vertices;
    if (!l.reversed) err << "a link is not reversed on an oriented surface; ";
    std::reverse(a.begin(), a.end());
    if (a != b) err << "glued sides differ; ";
  }
  return err.str();
}

}  // namespace geomip::test
