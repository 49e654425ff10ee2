#include "mesh/mesh_topology.h"

#include "mesh/errors.h"

#include <algorithm>
#include <numeric>
#include <string>

namespace geomip {
namespace {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::size_t find(std::size_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::size_t> parent_;
};

struct EdgeRef {
  int a, b;   // a < b
  int face;
  bool operator<(const EdgeRef& o) const { return a != o.a ? a < o.a : b != o.b ? b < o.b : face < o.face; }
};

bool repeats_index(const std::array<int, 3>& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

}  // namespace

TopologyReport analyze_topology(const TriMesh& mesh) {
  TopologyReport r;
  const std::size_t nv = mesh.positions.size();
  const std::size_t nf = mesh.triangles.size();
  r.faces = nf;

  std::vector<char> referenced(nv, 0);
  std::vector<char> valid_face(nf, 0);
  std::vector<EdgeRef> edges;
  edges.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    for (int v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        throw InvalidInput("analyze_topology: face " + std::to_string(f) + " has vertex index " +
                           std::to_string(v) + " out of range [0," + std::to_string(nv) + ")");
      }
      referenced[v] = 1;
    }
    if (repeats_index(t)) {
      ++r.degenerate_faces;
      continue;
    }
    const Eigen::Vector3d n =
        (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    if (n.squaredNorm() == 0.0) ++r.degenerate_faces;
    valid_face[f] = 1;
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), static_cast<int>(f)});
    }
  }
  r.vertices = static_cast<std::size_t>(std::count(referenced.begin(), referenced.end(), 1));
  r.unreferenced_vertices = nv - r.vertices;
  r.bbox_diagonal = referenced_bounding_box(mesh).diagonal();
  std::sort(edges.begin(), edges.end());

  // Corners (3 per face) joined across the edges at their vertex: the roots are the fans of each vertex.
  auto corner_of = [&](int face, int vertex) {
    const auto& t = mesh.triangles[face];
    const int k = t[0] == vertex ? 0 : (t[1] == vertex ? 1 : 2);
    return 3 * static_cast<std::size_t>(face) + k;
  };
  UnionFind corners(3 * nf);
  UnionFind faces(nf);
  struct BoundaryEdge {
    int face, a, b;
  };
  std::vector<BoundaryEdge> boundary;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    const std::size_t count = j - i;
    ++r.edges;
    if (count == 1) boundary.push_back({edges[i].face, edges[i].a, edges[i].b});
    if (count > 2) ++r.non_manifold_edges;
    for (std::size_t k = i + 1; k < j; ++k) {
      faces.unite(edges[i].face, edges[k].face);
      corners.unite(corner_of(edges[i].face, edges[i].a), corner_of(edges[k].face, edges[k].a));
      corners.unite(corner_of(edges[i].face, edges[i].b), corner_of(edges[k].face, edges[k].b));
    }
    i = j;
  }
  r.boundary_edges = boundary.size();

  // Fans per vertex and the number of vertices of the split surface.
  std::vector<int> fans(nv, 0);
  std::size_t split_vertices = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    if (!valid_face[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const std::size_t c = 3 * f + k;
      if (corners.find(c) == c) {
        ++fans[mesh.triangles[f][k]];
        ++split_vertices;
      }
    }
  }
  r.non_manifold_vertices = static_cast<std::size_t>(std::count_if(fans.begin(), fans.end(), [](int n) { return n > 1; }));
  r.manifold = r.non_manifold_edges == 0 && r.non_manifold_vertices == 0;

  std::size_t valid_faces = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    if (valid_face[f]) {
      ++valid_faces;
      if (faces.find(f) == f) ++r.components;
    }
  }

  // Boundary loops: components of the boundary edges over fan nodes (corner roots).
  UnionFind loops(3 * nf);
  std::vector<char> on_boundary(3 * nf, 0);
  for (const auto& e : boundary) {
    const std::size_t ca = corners.find(corner_of(e.face, e.a));
    const std::size_t cb = corners.find(corner_of(e.face, e.b));
    loops.unite(ca, cb);
    on_boundary[ca] = on_boundary[cb] = 1;
  }
  for (std::size_t c = 0; c < 3 * nf; ++c) {
    if (on_boundary[c] && loops.find(c) == c) ++r.boundary_loops;
  }

  if (r.non_manifold_edges == 0) {
    const long long chi = static_cast<long long>(split_vertices) - static_cast<long long>(r.edges) +
                          static_cast<long long>(valid_faces);
    const long long twice_genus = 2 * static_cast<long long>(r.components) - chi -
                                  static_cast<long long>(r.boundary_loops);
    if (twice_genus >= 0 && twice_genus % 2 == 0) r.genus = static_cast<int>(twice_genus / 2);
  }
  return r;
}

}  // namespace geomip
