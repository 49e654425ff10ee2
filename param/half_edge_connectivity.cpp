#include "param/half_edge_connectivity.h"

#include "mesh/errors.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace geomip {
namespace {

const char* const kFn = "partition_mesh: ";

// The half-edge b→a opposite h = a→b, found among b's outgoing half-edges in `c`.
// \throw InvalidInput unless there is exactly one, and h is the only a→b.
int opposite_of(const Connectivity& c, int h, int a, int b) {
  int found = -1, same_direction = 0;
  for (int k = c.out_begin[b]; k < c.out_begin[b + 1]; ++k) {
    if (c.out_to[k] == a) {
      if (found >= 0) same_direction = 1;
      found = c.out[k];
    }
  }
  for (int k = c.out_begin[a]; k < c.out_begin[a + 1]; ++k) {
    if (c.out[k] != h && c.out_to[k] == b) same_direction = 1;
  }
  if (found < 0 || same_direction) {
    throw InvalidInput(std::string(kFn) + "edge (" + std::to_string(a) + "," + std::to_string(b) +
                       ") is not shared by exactly two oppositely oriented triangles: the triangles must be "
                       "consistently oriented");
  }
  return found;
}

}  // namespace

Connectivity build_connectivity(const TriMesh& m) {
  const int nv = static_cast<int>(m.positions.size());
  const int nh = static_cast<int>(3 * m.triangles.size());
  Connectivity c;
  c.out_begin.assign(nv + 1, 0);
  for (int h = 0; h < nh; ++h) ++c.out_begin[he_from(m, h) + 1];
  for (int v = 0; v < nv; ++v) c.out_begin[v + 1] += c.out_begin[v];
  c.out.resize(nh);
  c.out_to.resize(nh);
  std::vector<int> fill(c.out_begin.begin(), c.out_begin.end() - 1);
  for (int h = 0; h < nh; ++h) {
    const int i = fill[he_from(m, h)]++;
    c.out[i] = h;
    c.out_to[i] = he_to(m, h);
  }
  c.opposite.assign(nh, -1);
  // Vertex by vertex: the half-edges a→b out of a, each looked up among b's (contiguous lists).
  for (int a = 0; a < nv; ++a) {
    for (int i = c.out_begin[a]; i < c.out_begin[a + 1]; ++i) {
      const int h = c.out[i], b = c.out_to[i];
      const int found = opposite_of(c, h, a, b);
      c.opposite[h] = found;
    }
  }
  return c;
}

void update_connectivity(const TriMesh& m, Connectivity& conn, const std::vector<int>& affected,
                         const std::vector<int>& old_corners, int old_faces) {
  const int nv = static_cast<int>(m.positions.size());
  const int old_nv = static_cast<int>(conn.out_begin.size()) - 1;
  const int nh = static_cast<int>(3 * m.triangles.size());
  std::vector<char> face_changed(m.triangles.size(), 0);
  for (int f : affected) face_changed[f] = 1;
  for (std::size_t f = static_cast<std::size_t>(old_faces); f < m.triangles.size(); ++f) face_changed[f] = 1;
  // Vertices whose outgoing half-edges change: the old and new corners of the changed triangles.
  std::vector<char> vertex_changed(nv, 0);
  for (int v = old_nv; v < nv; ++v) vertex_changed[v] = 1;
  for (int v : old_corners) vertex_changed[v] = 1;
  // The changed triangles: the replaced ones, then the appended ones.
  std::vector<int> changed_faces = affected;
  for (int f = old_faces; f < static_cast<int>(m.triangles.size()); ++f) changed_faces.push_back(f);
  for (int f : changed_faces)
    for (int v : m.triangles[f]) vertex_changed[v] = 1;
  // The new lists of the changed vertices: their old unchanged half-edges and every changed half-edge out of
  // them, ascending.
  std::unordered_map<int, std::vector<int>> lists;
  for (int v = 0; v < nv; ++v) {
    if (!vertex_changed[v]) continue;
    auto& list = lists[v];
    if (v < old_nv) {
      for (int i = conn.out_begin[v]; i < conn.out_begin[v + 1]; ++i)
        if (!face_changed[conn.out[i] / 3]) list.push_back(conn.out[i]);
    }
  }
  std::vector<int> changed_half_edges;
  for (int f : changed_faces) {
    for (int k = 0; k < 3; ++k) {
      const int h = 3 * f + k;
      changed_half_edges.push_back(h);
      lists[he_from(m, h)].push_back(h);
    }
  }
  Connectivity c;
  c.out_begin.assign(nv + 1, 0);
  for (int v = 0; v < nv; ++v) {
    if (vertex_changed[v]) {
      auto& list = lists[v];
      std::sort(list.begin(), list.end());
      c.out_begin[v + 1] = c.out_begin[v] + static_cast<int>(list.size());
    } else {
      c.out_begin[v + 1] = c.out_begin[v] + (conn.out_begin[v + 1] - conn.out_begin[v]);
    }
  }
  c.out.resize(nh);
  c.out_to.resize(nh);
  for (int v = 0; v < nv; ++v) {
    int i = c.out_begin[v];
    if (vertex_changed[v]) {
      for (int h : lists[v]) {
        c.out[i] = h;
        c.out_to[i++] = he_to(m, h);
      }
    } else {
      std::copy(conn.out.begin() + conn.out_begin[v], conn.out.begin() + conn.out_begin[v + 1],
                c.out.begin() + i);
      std::copy(conn.out_to.begin() + conn.out_begin[v], conn.out_to.begin() + conn.out_begin[v + 1],
                c.out_to.begin() + i);
    }
  }
  c.opposite = std::move(conn.opposite);
  c.opposite.resize(nh, -1);
  for (int h : changed_half_edges) {
    const int found = opposite_of(c, h, he_from(m, h), he_to(m, h));
    c.opposite[h] = found;
    c.opposite[found] = h;
  }
  conn = std::move(c);
}

std::size_t split_edges(TriMesh& m, Connectivity& conn, const std::vector<std::pair<int, int>>& edges) {
  std::vector<int> he_mid(3 * m.triangles.size(), -1);  // per half-edge: the midpoint of its edge, or -1
  const int old_faces = static_cast<int>(m.triangles.size());
  std::vector<int> affected;
  std::size_t added = 0;
  for (const auto& [a, b] : edges) {
    const int h = conn.find(m, a, b);
    if (h < 0) throw std::logic_error("split_edges: not an edge of the mesh");
    if (he_mid[h] >= 0) continue;
    he_mid[h] = he_mid[conn.opposite[h]] = static_cast<int>(m.positions.size());
    m.positions.push_back(0.5 * (m.positions[a] + m.positions[b]));
    affected.push_back(h / 3);
    affected.push_back(conn.opposite[h] / 3);
    ++added;
  }
  std::sort(affected.begin(), affected.end());
  affected.erase(std::unique(affected.begin(), affected.end()), affected.end());
  std::vector<int> old_corners;
  for (const int fi : affected) {
    const auto f = static_cast<std::size_t>(fi);
    const auto t = m.triangles[f];
    old_corners.insert(old_corners.end(), t.begin(), t.end());
    std::array<int, 3> mids;  // mids[k]: midpoint of edge t[k]→t[k+1], or -1
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      mids[k] = he_mid[3 * f + static_cast<std::size_t>(k)];
      count += mids[k] >= 0;
    }
    std::vector<std::array<int, 3>> pieces;
    if (count == 3) {
      pieces = {{t[0], mids[0], mids[2]},
                {mids[0], t[1], mids[1]},
                {mids[2], mids[1], t[2]},
                {mids[0], mids[1], mids[2]}};
    } else {
      // Rotate so that: one split edge is edge 0 (a→b); two split edges leave edge 2 (c→a) whole.
      int r = 0;
      while (count == 1 ? mids[r] < 0 : mids[(r + 2) % 3] >= 0) ++r;
      const int a = t[r], b = t[(r + 1) % 3], c = t[(r + 2) % 3];
      const int m0 = mids[r], m1 = mids[(r + 1) % 3];
      if (count == 1) {
        pieces = {{a, m0, c}, {m0, b, c}};
      } else {
        pieces = {{a, m0, m1}, {m0, b, m1}, {a, m1, c}};
      }
    }
    m.triangles[f] = pieces[0];
    m.triangles.insert(m.triangles.end(), pieces.begin() + 1, pieces.end());
  }
  if (added > 0) update_connectivity(m, conn, affected, old_corners, old_faces);
  return added;
}

}  // namespace geomip
