// Property checks of a PartitionResult, written independently of mesh_partition.cpp (they recount everything
// from the triangles), shared by the unit and real-mesh tests of partition_mesh().
#pragma once

#include "mesh/errors.h"
#include "mesh/mesh.h"
#include "mesh/mesh_topology.h"
#include "mesh/predicates.h"
#include "param/mesh_partition.h"

#include <gtest/gtest.h>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace geomip::test {

/// `call()` must throw InvalidInput with a one-line message holding `prefix` (the function's name) and
/// `fragment` (the reason).
template <class Call>
void expect_invalid_input(Call&& call, const std::string& prefix, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one mentioning '" << fragment << "'";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(prefix), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

inline double surface_area(const TriMesh& m) {
  double a = 0.0;
  for (const auto& t : m.triangles) {
    a += 0.5 * (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm();
  }
  return a;
}

/// Result of embedding one patch on the unit square with Tutte's uniform barycentric map (boundary by arc
/// length along the 4 sides, corner s at (0,0), (1,0), (1,1), (0,1)).
struct SquareEmbedding {
  std::size_t flipped = 0;  ///< triangles with signed parameter area <= 0 (none if the patch is fit for §3.3)
};

/// Tutte's theorem (with Floater's 2003 condition) makes this map bijective on a disk with a convex boundary
/// when no interior edge joins two boundary vertices on one side of the square: the partition must allow it.
/// Exact in theory; in floating point, long thin parts (a horse's legs) shrink below double precision, so
/// use it on well-conditioned meshes and rely on the combinatorial check of check_partition() elsewhere.
inline SquareEmbedding tutte_square_embedding(const PartitionResult& r, int p) {
  const TriMesh& m = r.mesh;
  const Patch& patch = r.patches[p];
  std::unordered_map<int, Eigen::Vector2d> uv;  // boundary vertices
  for (int s = 0; s < 4; ++s) {
    const auto& v = patch.sides[s].vertices;
    const Eigen::Vector2d corner[5] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
    std::vector<double> arc(v.size(), 0.0);
    for (std::size_t i = 1; i < v.size(); ++i)
      arc[i] = arc[i - 1] + (m.positions[v[i]] - m.positions[v[i - 1]]).norm();
    for (std::size_t i = 0; i + 1 < v.size(); ++i) {
      const double t = arc.back() > 0.0 ? arc[i] / arc.back() : 0.0;
      uv[v[i]] = (1.0 - t) * corner[s] + t * corner[s + 1];
    }
  }
  std::unordered_map<int, int> index;  // interior vertices
  std::vector<int> interior;
  std::vector<std::set<int>> neighbours;
  auto id = [&](int v) {
    auto [it, fresh] = index.emplace(v, static_cast<int>(interior.size()));
    if (fresh) {
      interior.push_back(v);
      neighbours.emplace_back();
    }
    return it->second;
  };
  for (int f : patch.faces) {
    const auto& t = m.triangles[f];
    for (int k = 0; k < 3; ++k) {
      if (!uv.count(t[k])) {
        const int i = id(t[k]);
        neighbours[i].insert(t[(k + 1) % 3]);
        neighbours[i].insert(t[(k + 2) % 3]);
      }
    }
  }
  const int n = static_cast<int>(interior.size());
  if (n > 0) {
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 2);
    for (int i = 0; i < n; ++i) {
      trip.emplace_back(i, i, static_cast<double>(neighbours[i].size()));
      for (int u : neighbours[i]) {
        const auto b = uv.find(u);
        if (b != uv.end()) {
          rhs.row(i) += b->second.transpose();
        } else {
          trip.emplace_back(i, index.at(u), -1.0);
        }
      }
    }
    Eigen::SparseMatrix<double> a(n, n);
    a.setFromTriplets(trip.begin(), trip.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
    const Eigen::MatrixXd x = solver.solve(rhs);
    for (int i = 0; i < n; ++i) uv[interior[i]] = x.row(i).transpose();
  }
  SquareEmbedding e;
  for (int f : patch.faces) {
    const auto& t = m.triangles[f];
    const Eigen::Vector2d &a = uv.at(t[0]), &b = uv.at(t[1]), &c = uv.at(t[2]);
    if (!((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x() > 0.0)) ++e.flipped;
  }
  return e;
}

/// Every documented property of `r` = partition_mesh(input, points, aux), and Floater's condition for a
/// one-to-one square embedding. Returns "" when all hold, else a description of the problems.
/// With `layout` (a result of partition_mesh_layout()): one patch per quad, patch q's corners those of quad
/// q.
inline std::string check_partition(const TriMesh& input, const std::vector<int>& points,
                                   const PartitionResult& r, const QuadLayout* layout = nullptr) {
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
  const std::size_t expected = layout ? layout->quads.size() : in_topo.genus == 0 ? 2 : 4;
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
    if (f < static_cast<int>(r.face_patch.size()) && r.face_patch[f] != owner[f])
      err << "face_patch[" << f << "]; ";
    if (err.tellp() > 2000) return err.str();
  }

  // Corners.
  const std::set<int> point_set(points.begin(), points.end());
  for (std::size_t p = 0; layout && p < np; ++p) {
    for (int s = 0; s < 4; ++s) {
      if (r.patches[p].corners[s] != layout->corners[layout->quads[p][s]])
        err << "patch " << p << " corner " << s << " is not its quad's; ";
    }
  }
  for (std::size_t p = 0; !layout && p < np; ++p) {
    const auto& c = r.patches[p].corners;
    if (std::set<int>(c.begin(), c.end()) != point_set)
      err << "patch " << p << " corners are not the 4 points; ";
    // Genus 0: P0; genus 1: patch 2a+b starts at P_{a+2b}.
    const int first = in_topo.genus == 0 ? points[0] : points[p / 2 + 2 * (p % 2)];
    if (c[0] != first) err << "patch " << p << " corner 0 is not the documented one; ";
  }
  if (!layout && in_topo.genus == 0) {
    const std::array<int, 4> c0 = {points[0], points[1], points[2], points[3]};
    const std::array<int, 4> c1 = {points[0], points[3], points[2], points[1]};
    if (r.patches[0].corners != c0 || r.patches[1].corners != c1) err << "genus-0 corner convention; ";
  }

  // Sides and the cut.
  const auto key = directed_edge_key;
  std::set<std::uint64_t> mesh_halfedges;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) mesh_halfedges.insert(key(t[k], t[(k + 1) % 3]));
  }
  std::set<int> cut_vertices;
  std::set<std::uint64_t> cut_halfedges;  // both directions
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
        if (!mesh_halfedges.count(key(v[i], v[i + 1])))
          err << "patch " << p << " side " << s << " not an edge path; ";
        side_halfedges.insert(key(v[i], v[i + 1]));
        cut_halfedges.insert(key(v[i], v[i + 1]));
        cut_halfedges.insert(key(v[i + 1], v[i]));
      }
      loop.insert(loop.end(), v.begin(), v.end() - 1);
      cut_vertices.insert(v.begin(), v.end());
    }
    if (std::set<int>(loop.begin(), loop.end()).size() != loop.size())
      err << "patch " << p << " loop not simple; ";
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
  // Fit for the square embedding of §3.3 (Floater's condition): no interior edge joins two cut vertices.
  for (int f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a < b && cut_vertices.count(a) && cut_vertices.count(b) && !cut_halfedges.count(key(a, b))) {
        err << "edge (" << a << "," << b << ") joins two cut vertices across a patch; ";
        f = nf;
        break;
      }
    }
  }
  return err.str();
}

}  // namespace geomip::test
