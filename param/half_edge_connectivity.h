// The half-edge connectivity that the partition (mesh_partition.cpp) traces its paths on: each half-edge's
// opposite and each vertex's outgoing half-edges, plain index arrays over a TriMesh (no half-edge mesh
// class; see ../shared/STYLE.md). Internal to geomip::param; here so that its tests can check it.
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <utility>
#include <vector>

namespace geomip {

/// Half-edge h = 3·f + k of triangle f runs from triangles[f][k] to triangles[f][(k+1)%3].
inline int he_from(const TriMesh& m, int h) {
  return m.triangles[h / 3][h % 3];
}
inline int he_to(const TriMesh& m, int h) {
  return m.triangles[h / 3][(h + 1) % 3];
}

/// Connectivity of a closed, consistently oriented triangle mesh: each half-edge's opposite, and each
/// vertex's outgoing half-edges (CSR, ascending half-edge ids). On such a mesh the outgoing half-edges of v
/// reach every neighbour of v once.
struct Connectivity {
  std::vector<int> opposite;
  std::vector<int> out_begin;  ///< #V + 1
  std::vector<int> out;
  std::vector<int> out_to;  ///< he_to of out[i], beside it: the scans read contiguous memory

  int find(const TriMesh&, int a, int b) const {  ///< half-edge a→b or -1
    for (int i = out_begin[a]; i < out_begin[a + 1]; ++i) {
      if (out_to[i] == b) return out[i];
    }
    return -1;
  }
};

/// \throw InvalidInput ("partition_mesh: ...") when an edge is not shared by exactly two oppositely oriented
///   triangles.
Connectivity build_connectivity(const TriMesh& m);

/// Makes `conn`, the connectivity of `m` before the triangles `affected` (ascending ids below `old_faces`,
/// whose corners were `old_corners`, in any order) were replaced and triangles from `old_faces` on appended
/// (new vertices appended too), the connectivity of `m` as it is now: the same arrays as
/// build_connectivity(m), built from the old ones where nothing changed (only the changed half-edges'
/// opposites are searched). \throw InvalidInput as build_connectivity() when a changed half-edge has no
/// opposite or two.
void update_connectivity(const TriMesh& m, Connectivity& conn, const std::vector<int>& affected,
                         const std::vector<int>& old_corners, int old_faces);

/// Splits every listed edge (each an edge of `m`, whose connectivity is `conn`) at its midpoint; returns the
/// number of vertices appended (in list order). Triangles keep their id for their first piece (other pieces
/// appended, in triangle order) and their orientation; untouched triangles stay as they are. `conn` becomes
/// the split mesh's connectivity (update_connectivity()). Cost: the split edges' triangles, plus copying the
/// connectivity's arrays. \throw std::logic_error when a listed pair is not an edge of `m`.
std::size_t split_edges(TriMesh& m, Connectivity& conn, const std::vector<std::pair<int, int>>& edges);

}  // namespace geomip
