#include "param/mesh_partition.h"

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "mesh/predicates.h"
#include "param/half_edge_connectivity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace geomip {
namespace {

const char* const kFn = "partition_mesh: ";

// Dijkstra on the edge graph with Euclidean lengths, reusing its arrays between queries.
class PathTracer {
 public:
  // `first_ok` / `last_ok` (when not null): the only vertices the path may take right after `source` /
  // right before `target`.
  std::vector<int> shortest_path(const TriMesh& m, const Connectivity& c, int source, int target,
                                 const std::vector<char>& blocked, const std::vector<int>* first_ok = nullptr,
                                 const std::vector<int>* last_ok = nullptr) {
    auto listed = [](const std::vector<int>* list, int v) {
      return !list || std::find(list->begin(), list->end(), v) != list->end();
    };
    const std::size_t nv = m.positions.size();
    if (dist_.size() != nv) {
      dist_.assign(nv, std::numeric_limits<double>::infinity());
      prev_.assign(nv, -1);
    }
    for (int v : touched_) {
      dist_[v] = std::numeric_limits<double>::infinity();
      prev_[v] = -1;
    }
    touched_.clear();
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    dist_[source] = 0.0;
    touched_.push_back(source);
    heap.push({0.0, source});
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (d > dist_[v]) continue;
      if (v == target) break;
      for (int i = c.out_begin[v]; i < c.out_begin[v + 1]; ++i) {
        const int u = c.out_to[i];
        if (blocked[u] && u != target) continue;
        if ((v == source && !listed(first_ok, u)) || (u == target && !listed(last_ok, v))) continue;
        const double du = d + (m.positions[u] - m.positions[v]).norm();
        if (du < dist_[u]) {
          if (prev_[u] < 0 && u != source) touched_.push_back(u);
          dist_[u] = du;
          prev_[u] = v;
          heap.push({du, u});
        }
      }
    }
    std::vector<int> path;
    if (!std::isfinite(dist_[target])) return path;
    for (int v = target; v != source; v = prev_[v]) path.push_back(v);
    path.push_back(source);
    std::reverse(path.begin(), path.end());
    return path;
  }

 private:
  std::vector<double> dist_;
  std::vector<int> prev_;
  std::vector<int> touched_;
};

// One path to trace: from corner `from` to corner `to`, through the guides `via` in order (none when empty).
struct PathSpec {
  int from, to;
  std::vector<int> via;
  std::vector<int> first_ok{}, last_ok{};  // allowed first / last steps; empty = any
  bool restricted = false;                 // first_ok and last_ok apply
};

std::string vertex_name(int v) {
  return "vertex " + std::to_string(v);
}

std::string through(const std::vector<int>& via) {
  if (via.empty()) return "";
  std::string s = via.size() == 1 ? " through vertex " : " through vertices ";
  for (std::size_t i = 0; i < via.size(); ++i) s += (i ? ", " : "") + std::to_string(via[i]);
  return s;
}

// The working state of one partition: the mesh being cut (split as needed), its connectivity, and the cut.
class Partitioner {
 public:
  Partitioner(const TriMesh& mesh, const PartitionOptions& options) : options_(options) {
    result_.mesh = mesh;
    conn_ = build_connectivity(result_.mesh);
  }
  // With the mesh's connectivity already built (PartitionMeshCache).
  Partitioner(const TriMesh& mesh, const Connectivity& conn, const PartitionOptions& options)
      : options_(options), conn_(conn) {
    result_.mesh = mesh;
  }

  // Traces `specs` in order; every path avoids all special points but its own and the interior vertices of
  // earlier paths. `special` lists every partition and auxiliary point.
  // `prepare` (optional) is called before each attempt at path k and may restrict its first and last steps
  // (it sees the paths traced so far and the current mesh).
  void trace(std::vector<PathSpec> specs, const std::vector<int>& special,
             const std::function<void(std::size_t, PathSpec&)>& prepare = {}) {
    blocked_.assign(result_.mesh.positions.size(), 0);
    for (int v : special) blocked_[v] = 1;
    for (std::size_t k = 0; k < specs.size(); ++k) {
      if (prepare) prepare(k, specs[k]);
      std::vector<int> path = trace_one(specs[k]);
      if (path.empty() && options_.split_degenerate) {
        // Earlier paths and chords between them may enclose the corners: opening the chords frees a way.
        split_chords();
        if (prepare) prepare(k, specs[k]);
        path = trace_one(specs[k]);
      }
      if (path.empty()) {
        throw InvalidInput(std::string(kFn) + "cannot trace path " + std::to_string(k) + " from " +
                           vertex_name(specs[k].from) + " to " + vertex_name(specs[k].to) +
                           through(specs[k].via) +
                           " without touching earlier paths; move the points further apart" +
                           (options_.split_degenerate ? "" : " or enable split_degenerate"));
      }
      for (std::size_t i = 1; i + 1 < path.size(); ++i) blocked_[path[i]] = 1;
      paths_.push_back(std::move(path));
    }
    mark_cut();
    const std::size_t chord_count = chords().size();
    if (chord_count > 0) {
      if (!options_.split_degenerate) {
        throw InvalidInput(std::string(kFn) + "degenerate configuration: " + std::to_string(chord_count) +
                           " edge(s) join two cut vertices without being on the cut (a triangle with all "
                           "three vertices on the cut); enable split_degenerate");
      }
      split_chords();
    }
  }

  // Flood-fills the triangles into the regions between cut edges; returns their number.
  int label_regions() {
    const int nf = static_cast<int>(result_.mesh.triangles.size());
    result_.face_patch.assign(nf, -1);
    int regions = 0;
    std::vector<int> stack;
    for (int f = 0; f < nf; ++f) {
      if (result_.face_patch[f] >= 0) continue;
      result_.face_patch[f] = regions;
      stack.push_back(f);
      while (!stack.empty()) {
        const int g = stack.back();
        stack.pop_back();
        for (int k = 0; k < 3; ++k) {
          const int h = 3 * g + k;
          if (cut_[h]) continue;
          const int o = conn_.opposite[h] / 3;
          if (result_.face_patch[o] < 0) {
            result_.face_patch[o] = regions;
            stack.push_back(o);
          }
        }
      }
      ++regions;
    }
    return regions;
  }

  // The CCW boundary cycle (vertices, first = `start`, not repeated at the end) of region `region`, after
  // checking the region is a disk whose boundary is one simple loop through `start`. On failure returns an
  // empty cycle and sets `why`.
  std::vector<int> disk_boundary(int region, int start, std::string& why) const {
    const TriMesh& m = result_.mesh;
    const int nh = static_cast<int>(cut_.size());
    std::unordered_map<int, int> next;  // boundary vertex → its outgoing boundary half-edge in the region
    std::vector<int> vertices;
    std::size_t faces = 0, boundary = 0;
    for (int h = 0; h < nh; ++h) {
      if (result_.face_patch[h / 3] != region) continue;
      if (h % 3 == 0) {
        ++faces;
        for (int k = 0; k < 3; ++k) vertices.push_back(m.triangles[h / 3][k]);
      }
      if (!cut_[h]) continue;
      ++boundary;
      if (result_.face_patch[conn_.opposite[h] / 3] == region) {
        why = "the cut edge (" + std::to_string(he_from(m, h)) + "," + std::to_string(he_to(m, h)) +
              ") has the same patch on both sides";
        return {};
      }
      if (!next.emplace(he_from(m, h), h).second) {
        why = "its boundary touches itself at " + vertex_name(he_from(m, h));
        return {};
      }
    }
    std::sort(vertices.begin(), vertices.end());
    const std::size_t nverts = std::unique(vertices.begin(), vertices.end()) - vertices.begin();
    const long long euler = static_cast<long long>(nverts) -
                            static_cast<long long>((3 * faces + boundary) / 2) +
                            static_cast<long long>(faces);
    if (euler != 1) {
      why = "it is not a disk (V-E+F = " + std::to_string(euler) + ")";
      return {};
    }
    std::vector<int> cycle;
    if (!next.count(start)) {
      why = "its boundary does not pass through " + vertex_name(start);
      return {};
    }
    int v = start;
    do {
      cycle.push_back(v);
      v = he_to(m, next.at(v));
    } while (v != start && cycle.size() <= next.size());
    if (cycle.size() != next.size()) {
      why = "its boundary has more than one loop";
      return {};
    }
    return cycle;
  }

  // Cuts `cycle` (CCW, starting at corners[0]) into the 4 sides between `corners`, which must appear once
  // each in that order; other partition points must not appear at all.
  static bool make_sides(const std::vector<int>& cycle, const std::array<int, 4>& corners, Patch& patch) {
    patch.corners = corners;
    std::size_t pos = 0;
    for (int s = 0; s < 4; ++s) {
      const int end = corners[(s + 1) % 4];
      auto& side = patch.sides[s].vertices;
      side.clear();
      side.push_back(cycle[pos]);
      do {
        pos = (pos + 1) % cycle.size();
        side.push_back(cycle[pos]);
      } while (cycle[pos] != end && pos != 0);
      if (cycle[pos] != end || (s < 3 && pos == 0)) return false;
      for (std::size_t i = 1; i + 1 < side.size(); ++i) {
        if (std::find(corners.begin(), corners.end(), side[i]) != corners.end()) return false;
      }
    }
    return pos == 0;
  }

  // The neighbours of `v` in counter-clockwise order seen from outside.
  std::vector<int> ring(int v) const {
    std::vector<int> ring;
    const int h0 = conn_.out[conn_.out_begin[v]];
    int h = h0;
    do {
      ring.push_back(he_to(result_.mesh, h));
      h = conn_.opposite[3 * (h / 3) + (h % 3 + 2) % 3];
    } while (h != h0 && ring.size() <= static_cast<std::size_t>(conn_.out_begin[v + 1] - conn_.out_begin[v]));
    return ring;
  }

  PartitionResult& result() { return result_; }
  const std::vector<std::vector<int>>& paths() const { return paths_; }
  const Connectivity& connectivity() const { return conn_; }

 private:
  // Traces from → via[0] → via[1] → … → to, each leg a shortest path that avoids the earlier legs, the guides
  // still ahead and the end corner (until the last leg). Empty when a leg cannot be traced.
  std::vector<int> trace_one(const PathSpec& s) {
    if (s.via.empty()) {
      blocked_[s.from] = blocked_[s.to] = 0;
      std::vector<int> path =
          tracer_.shortest_path(result_.mesh, conn_, s.from, s.to, blocked_, s.restricted ? &s.first_ok : nullptr,
                                s.restricted ? &s.last_ok : nullptr);
      blocked_[s.from] = blocked_[s.to] = 1;
      return path;
    }
    std::vector<int> stops = {s.from};
    stops.insert(stops.end(), s.via.begin(), s.via.end());
    stops.push_back(s.to);
    for (int v : stops) blocked_[v] = 1;
    std::vector<int> path = {s.from};
    std::vector<int> legs;  // interior vertices of the legs traced so far, blocked while the path is traced
    bool ok = true;
    for (std::size_t i = 0; i + 1 < stops.size() && ok; ++i) {
      blocked_[stops[i]] = blocked_[stops[i + 1]] = 0;
      const std::vector<int> leg = tracer_.shortest_path(result_.mesh, conn_, stops[i], stops[i + 1], blocked_);
      blocked_[stops[i]] = 1;
      if (leg.empty()) {
        ok = false;
        break;
      }
      for (std::size_t j = 1; j < leg.size(); ++j) {
        path.push_back(leg[j]);
        if (j + 1 < leg.size() && !blocked_[leg[j]]) {
          blocked_[leg[j]] = 1;
          legs.push_back(leg[j]);
        }
      }
    }
    for (int v : legs) blocked_[v] = 0;
    for (int v : stops) blocked_[v] = 1;
    if (!ok) path.clear();
    return path;
  }

  // Marks the half-edges of all traced paths (both directions) as cut.
  void mark_cut() {
    cut_.assign(3 * result_.mesh.triangles.size(), 0);
    on_cut_.assign(result_.mesh.positions.size(), 0);
    for (const auto& path : paths_) {
      for (std::size_t i = 0; i < path.size(); ++i) on_cut_[path[i]] = 1;
      for (std::size_t i = 0; i + 1 < path.size(); ++i) {
        const int h = conn_.find(result_.mesh, path[i], path[i + 1]);
        cut_[h] = cut_[conn_.opposite[h]] = 1;
      }
    }
  }

  // Edges that join two cut vertices without being cut edges.
  std::vector<std::pair<int, int>> chords() const {
    std::vector<std::pair<int, int>> list;
    const TriMesh& m = result_.mesh;
    for (int h = 0; h < static_cast<int>(cut_.size()); ++h) {
      const int a = he_from(m, h), b = he_to(m, h);
      if (a < b && !cut_[h] && on_cut_[a] && on_cut_[b]) list.emplace_back(a, b);
    }
    return list;
  }

  void split_chords() {
    mark_cut();
    const auto list = chords();
    if (list.empty()) return;
    result_.split_vertices += split_edges(result_.mesh, conn_, list);
    blocked_.resize(result_.mesh.positions.size(), 0);
    mark_cut();
  }

  PartitionOptions options_;
  PartitionResult result_;
  Connectivity conn_;
  PathTracer tracer_;
  std::vector<char> blocked_;
  std::vector<char> cut_;     // per half-edge
  std::vector<char> on_cut_;  // per vertex
  std::vector<std::vector<int>> paths_;
};

// Fills each patch's face list (ascending) from face_patch.
void collect_faces(PartitionResult& r) {
  for (Patch& patch : r.patches) patch.faces.clear();
  for (int f = 0; f < static_cast<int>(r.face_patch.size()); ++f)
    r.patches[r.face_patch[f]].faces.push_back(f);
}

// Fills `adjacency` by matching every side with the side that walks the same vertices the other way.
// Returns false (and sets `why`) when a side has no partner.
bool link_sides(PartitionResult& r, std::string& why) {
  std::unordered_map<std::uint64_t, std::pair<int, int>> by_start;  // (first, second vertex) → (patch, side)
  const auto key = directed_edge_key;
  for (int p = 0; p < static_cast<int>(r.patches.size()); ++p) {
    for (int s = 0; s < 4; ++s) {
      const auto& v = r.patches[p].sides[s].vertices;
      by_start[key(v[0], v[1])] = {p, s};
    }
  }
  r.adjacency.clear();
  for (int p = 0; p < static_cast<int>(r.patches.size()); ++p) {
    for (int s = 0; s < 4; ++s) {
      const auto& v = r.patches[p].sides[s].vertices;
      const auto it = by_start.find(key(v.back(), v[v.size() - 2]));
      bool ok = it != by_start.end() && it->second.first != p;
      if (ok) {
        const auto& w = r.patches[it->second.first].sides[it->second.second].vertices;
        ok = std::equal(v.begin(), v.end(), w.rbegin(), w.rend());
      }
      if (!ok) {
        why = "side " + std::to_string(s) + " of patch " + std::to_string(p) +
              " is not shared with another patch";
        return false;
      }
      r.adjacency.push_back({p, s, it->second.first, it->second.second, true});
    }
  }
  return true;
}

void check_points(const TriMesh& mesh, const std::vector<int>& points, const std::vector<int>& aux) {
  const int nv = static_cast<int>(mesh.positions.size());
  std::vector<char> referenced(nv, 0);
  for (const auto& t : mesh.triangles) {
    for (int v : t) {
      if (v < 0 || v >= nv)
        throw InvalidInput(std::string(kFn) + "a triangle has a vertex index out of range");
      referenced[v] = 1;
    }
  }
  std::vector<int> all = points;
  all.insert(all.end(), aux.begin(), aux.end());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const std::string what = i < points.size() ? "partition point " + std::to_string(i)
                                               : "auxiliary point " + std::to_string(i - points.size());
    if (all[i] < 0 || all[i] >= nv) {
      throw InvalidInput(std::string(kFn) + what + " = " + std::to_string(all[i]) + " is out of range [0," +
                         std::to_string(nv) + ")");
    }
    if (!referenced[all[i]]) {
      throw InvalidInput(std::string(kFn) + what + " = " + std::to_string(all[i]) +
                         " is not a vertex of any triangle");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (all[j] == all[i]) {
        throw InvalidInput(std::string(kFn) + what + " repeats " + vertex_name(all[i]) +
                           ": partition and auxiliary points must be distinct");
      }
    }
  }
}

PartitionResult partition_genus0(const TriMesh& mesh, const std::vector<int>& p,
                                 const std::vector<std::vector<int>>& guides, const PartitionOptions& options) {
  Partitioner part(mesh, options);
  std::vector<PathSpec> specs;
  std::vector<int> special = p;
  for (int k = 0; k < 4; ++k) {
    specs.push_back({p[k], p[(k + 1) % 4], guides[k]});
    special.insert(special.end(), guides[k].begin(), guides[k].end());
  }
  part.trace(specs, special);

  PartitionResult& r = part.result();
  auto fail = [&](const std::string& why) {
    throw SolverFailure(std::string(kFn) + "genus-0 partition failed validation: " + why);
  };
  const int regions = part.label_regions();
  if (regions != 2) fail("the loop cuts the surface into " + std::to_string(regions) + " parts, not 2");
  // Patch 0 is on the left of P0→P1, i.e. owns the half-edge P0→(next loop vertex).
  const auto& path0 = part.paths()[0];
  const int h0 = part.connectivity().find(r.mesh, path0[0], path0[1]);
  const int left = r.face_patch[h0 / 3];
  if (left == 1) {
    for (int& f : r.face_patch) f = 1 - f;
  }
  const std::array<std::array<int, 4>, 2> corners = {{{p[0], p[1], p[2], p[3]}, {p[0], p[3], p[2], p[1]}}};
  r.patches.assign(2, Patch());
  for (int k = 0; k < 2; ++k) {
    std::string why;
    const auto cycle = part.disk_boundary(k, p[0], why);
    if (cycle.empty()) fail("patch " + std::to_string(k) + ": " + why);
    if (!Partitioner::make_sides(cycle, corners[k], r.patches[k])) {
      fail("patch " + std::to_string(k) + " does not have the 4 corners in loop order");
    }
  }
  std::string why;
  if (!link_sides(r, why)) fail(why);
  collect_faces(r);
  return std::move(r);
}

PartitionResult partition_genus1(const TriMesh& mesh, const std::vector<int>& p, const std::vector<int>& a,
                                 const PartitionOptions& options) {
  Partitioner part(mesh, options);
  // Edge k: from → to, guided by a[k] (see the header's picture).
  const std::array<std::array<int, 2>, 8> ends = {
      {{0, 1}, {1, 0}, {2, 3}, {3, 2}, {0, 2}, {2, 0}, {1, 3}, {3, 1}}};
  std::vector<PathSpec> specs;
  for (int k = 0; k < 8; ++k) specs.push_back({p[ends[k][0]], p[ends[k][1]], {a[k]}});
  std::vector<int> special = p;
  special.insert(special.end(), a.begin(), a.end());
  part.trace(specs, special);

  PartitionResult& r = part.result();
  auto fail = [&](const std::string& why) {
    throw InvalidInput(std::string(kFn) +
                       "the genus-1 points do not cut the torus into a 2x2 grid of quads (" + why +
                       "); check the order of the auxiliary points (see mesh_partition.h)");
  };
  const int regions = part.label_regions();
  if (regions != 4) fail(std::to_string(regions) + " patches instead of 4");

  // Which traced edge starts with (corner, next vertex), in either direction.
  std::unordered_map<std::uint64_t, int> edge_by_start;
  const auto key = directed_edge_key;
  for (int k = 0; k < 8; ++k) {
    const auto& path = part.paths()[k];
    edge_by_start[key(path[0], path[1])] = k;
    edge_by_start[key(path.back(), path[path.size() - 2])] = k;
  }
  std::vector<Patch> patches(4);
  std::vector<char> taken(4, 0);
  std::vector<int> renumber(4, -1);
  for (int region = 0; region < 4; ++region) {
    std::string why;
    const auto cycle = part.disk_boundary(region, p[0], why);
    if (cycle.empty()) fail("patch " + std::to_string(region) + ": " + why);
    std::array<int, 4> corners = {p[0], -1, p[3], -1};
    std::vector<int> found;
    for (int v : cycle) {
      if (std::find(p.begin(), p.end(), v) != p.end()) found.push_back(v);
    }
    if (found.size() != 4 || found[2] != p[3] || (found[1] != p[1] && found[1] != p[2])) {
      fail("a patch has " + std::to_string(found.size()) + " corners, or not P0,P1,P3,P2 in cyclic order");
    }
    corners[1] = found[1];
    corners[3] = found[3];
    Patch patch;
    if (!Partitioner::make_sides(cycle, corners, patch)) fail("a patch's corners are out of order");
    int a01 = -1, a02 = -1;
    for (int s = 0; s < 4; ++s) {
      const auto& v = patch.sides[s].vertices;
      const auto it = edge_by_start.find(key(v[0], v[1]));
      if (it == edge_by_start.end()) fail("a patch side is not one traced edge");
      const int k = it->second;
      if (k < 2) a01 = k;
      if (k == 4 || k == 5) a02 = k - 4;
    }
    if (a01 < 0 || a02 < 0) fail("a patch does not have one P0-P1 and one P0-P2 side");
    const int index = 2 * a01 + a02;
    if (taken[index]) fail("two patches lie between the same P0-P1 and P0-P2 edges");
    // Corner 0 is P_{a+2b}: the patch's lower-left corner in the cover picture.
    const int first =
        static_cast<int>(std::find(corners.begin(), corners.end(), p[a01 + 2 * a02]) - corners.begin());
    std::rotate(patch.corners.begin(), patch.corners.begin() + first, patch.corners.end());
    std::rotate(patch.sides.begin(), patch.sides.begin() + first, patch.sides.end());
    taken[index] = 1;
    renumber[region] = index;
    patches[index] = std::move(patch);
  }
  for (int& f : r.face_patch) f = renumber[f];
  r.patches = std::move(patches);
  std::string why;
  if (!link_sides(r, why)) fail(why);
  collect_faces(r);
  return std::move(r);
}

// Half-edges of a quad layout: h = 4q + s runs from quads[q][s] to quads[q][(s+1)%4] (corner indices).
struct LayoutHalfEdges {
  std::vector<int> opposite;  // per half-edge
  std::vector<int> edge;      // undirected edge id per half-edge
  int num_edges = 0;
  std::vector<std::vector<int>> out_ccw;  // per corner: outgoing half-edges, counter-clockwise
};

int layout_from(const QuadLayout& l, int h) {
  return l.quads[h / 4][h % 4];
}
int layout_to(const QuadLayout& l, int h) {
  return l.quads[h / 4][(h + 1) % 4];
}

// Builds the half-edge structure of `l`; returns "" or the first reason it is not a closed quad surface.
std::string layout_half_edges(const QuadLayout& l, LayoutHalfEdges& he) {
  const int nc = static_cast<int>(l.corners.size());
  const int nh = static_cast<int>(4 * l.quads.size());
  if (l.quads.empty()) return "the layout has no quads";
  for (std::size_t q = 0; q < l.quads.size(); ++q) {
    for (int s = 0; s < 4; ++s) {
      const int c = l.quads[q][s];
      if (c < 0 || c >= nc) {
        return "quad " + std::to_string(q) + " names corner " + std::to_string(c) + ", outside [0," +
               std::to_string(nc) + ")";
      }
      for (int t = 0; t < s; ++t) {
        if (l.quads[q][t] == c) return "quad " + std::to_string(q) + " repeats corner " + std::to_string(c);
      }
    }
  }
  std::unordered_map<std::uint64_t, int> by_key;
  for (int h = 0; h < nh; ++h) {
    if (!by_key.emplace(directed_edge_key(layout_from(l, h), layout_to(l, h)), h).second) {
      return "the layout edge from corner " + std::to_string(layout_from(l, h)) + " to corner " +
             std::to_string(layout_to(l, h)) +
             " is walked the same way by two quads (quads not consistently oriented, or overlapping)";
    }
  }
  he.opposite.assign(nh, -1);
  he.edge.assign(nh, -1);
  he.num_edges = 0;
  for (int h = 0; h < nh; ++h) {
    const auto it = by_key.find(directed_edge_key(layout_to(l, h), layout_from(l, h)));
    if (it == by_key.end()) {
      return "the layout edge between corners " + std::to_string(layout_from(l, h)) + " and " +
             std::to_string(layout_to(l, h)) + " has a quad on one side only (the quads are not closed)";
    }
    he.opposite[h] = it->second;
    if (he.edge[h] < 0) he.edge[h] = he.edge[it->second] = he.num_edges++;
  }
  he.out_ccw.assign(nc, {});
  std::vector<int> out_count(nc, 0);
  for (int h = 0; h < nh; ++h) ++out_count[layout_from(l, h)];
  std::vector<int> first(nc, -1);
  for (int h = 0; h < nh; ++h) {
    if (first[layout_from(l, h)] < 0) first[layout_from(l, h)] = h;
  }
  for (int c = 0; c < nc; ++c) {
    if (first[c] < 0) return "corner " + std::to_string(c) + " is in no quad";
    int h = first[c];
    do {
      he.out_ccw[c].push_back(h);
      h = he.opposite[4 * (h / 4) + (h % 4 + 3) % 4];  // next outgoing half-edge counter-clockwise
    } while (h != first[c] && static_cast<int>(he.out_ccw[c].size()) <= out_count[c]);
    if (static_cast<int>(he.out_ccw[c].size()) != out_count[c]) {
      return "the quads around corner " + std::to_string(c) + " do not form one fan (non-manifold layout)";
    }
  }
  return "";
}

PartitionResult partition_layout(const TriMesh& mesh, const QuadLayout& layout, const LayoutHalfEdges& he,
                                 const PartitionOptions& options, const Connectivity* conn = nullptr) {
  Partitioner part = conn ? Partitioner(mesh, *conn, options) : Partitioner(mesh, options);
  // One path per layout edge, stored from its lower-numbered half-edge's start, shortest corners first.
  const int ne = he.num_edges;
  std::vector<int> edge_half(ne, -1);
  for (int h = 0; h < static_cast<int>(he.edge.size()); ++h) {
    if (edge_half[he.edge[h]] < 0) edge_half[he.edge[h]] = h;
  }
  auto corner_vertex = [&](int c) { return layout.corners[c]; };
  std::vector<int> order(ne);
  for (int e = 0; e < ne; ++e) order[e] = e;
  auto length = [&](int e) {
    const int h = edge_half[e];
    return (mesh.positions[corner_vertex(layout_from(layout, h))] -
            mesh.positions[corner_vertex(layout_to(layout, h))])
        .norm();
  };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return length(a) < length(b); });
  // A spanning tree of the corners first (Kruskal, shortest first): tree paths cannot close a loop around a
  // corner that a later path must reach. Then the other edges, shortest first.
  {
    std::vector<int> root(layout.corners.size());
    for (std::size_t c = 0; c < root.size(); ++c) root[c] = static_cast<int>(c);
    auto find = [&](int c) {
      while (root[c] != c) c = root[c] = root[root[c]];
      return c;
    };
    std::vector<int> tree, rest;
    for (int e : order) {
      const int a = find(layout_from(layout, edge_half[e])), b = find(layout_to(layout, edge_half[e]));
      if (a != b) {
        root[a] = b;
        tree.push_back(e);
      } else {
        rest.push_back(e);
      }
    }
    order = tree;
    order.insert(order.end(), rest.begin(), rest.end());
  }
  std::vector<PathSpec> specs;
  for (int e : order) {
    const int h = edge_half[e];
    specs.push_back({corner_vertex(layout_from(layout, h)), corner_vertex(layout_to(layout, h)), {}});
  }
  std::vector<int> traced_as(ne, -1);  // edge → index into part.paths()
  // First mesh step of traced layout half-edge h from its start corner, or -1 when not traced yet.
  auto first_step = [&](int h) {
    const int k = traced_as[he.edge[h]];
    if (k < 0) return -1;
    const auto& path = part.paths()[k];
    return h == edge_half[he.edge[h]] ? path[1] : path[path.size() - 2];
  };
  // The mesh neighbours of h's start corner strictly between the traced neighbours of h in the layout's
  // cyclic order (all neighbours when none is traced).
  auto sector = [&](int h) {
    const int c = layout_from(layout, h);
    const std::vector<int>& fan = he.out_ccw[c];
    const int n = static_cast<int>(fan.size());
    const int at = static_cast<int>(std::find(fan.begin(), fan.end(), h) - fan.begin());
    int succ = -1, pred = -1;
    for (int i = 1; i < n && succ < 0; ++i) succ = first_step(fan[(at + i) % n]);
    for (int i = 1; i < n && pred < 0; ++i) pred = first_step(fan[(at - i + n) % n]);
    std::vector<int> ring = part.ring(corner_vertex(c));
    if (pred < 0) return ring;
    const int r = static_cast<int>(ring.size());
    const int start = static_cast<int>(std::find(ring.begin(), ring.end(), pred) - ring.begin());
    std::vector<int> allowed;
    for (int i = 1; i < r; ++i) {
      const int v = ring[(start + i) % r];
      if (v == succ) break;
      allowed.push_back(v);
    }
    return allowed;
  };
  // Called before each attempt at path k, when paths 0..k-1 exist.
  auto prepare = [&](std::size_t k, PathSpec& spec) {
    if (k > 0) traced_as[order[k - 1]] = static_cast<int>(k - 1);
    const int h = edge_half[order[k]];
    spec.restricted = true;
    spec.first_ok = sector(h);
    spec.last_ok = sector(he.opposite[h]);
  };
  std::vector<int> special = layout.corners;
  const char* const kHint =
      "; check that each quad's corners are counter-clockwise seen from outside and that the corners' cyclic "
      "order matches the mesh";
  try {
    part.trace(specs, special, prepare);
  } catch (const InvalidInput& e) {
    throw InvalidInput(e.what() + std::string(kHint));
  }
  for (int k = 0; k < ne; ++k) traced_as[order[k]] = k;

  PartitionResult& r = part.result();
  auto fail = [&](const std::string& why) {
    throw InvalidInput(std::string(kFn) + "the layout's paths do not cut the mesh into its " +
                       std::to_string(layout.quads.size()) + " quads (" + why + ")" + kHint);
  };
  const int nq = static_cast<int>(layout.quads.size());
  const int regions = part.label_regions();
  if (regions != nq) fail(std::to_string(regions) + " regions");
  // Quad q owns the region left of each of its sides, walked in its direction.
  std::vector<int> quad_of_region(nq, -1), region_of_quad(nq, -1);
  for (int q = 0; q < nq; ++q) {
    for (int s = 0; s < 4; ++s) {
      const int h = 4 * q + s;
      const int a = corner_vertex(layout_from(layout, h));
      const int step = first_step(h);
      const int mh = part.connectivity().find(r.mesh, a, step);
      const int region = r.face_patch[mh / 3];
      if (s == 0) region_of_quad[q] = region;
      if (region != region_of_quad[q])
        fail("the sides of quad " + std::to_string(q) + " bound different regions");
    }
    if (quad_of_region[region_of_quad[q]] >= 0) {
      fail("quads " + std::to_string(quad_of_region[region_of_quad[q]]) + " and " + std::to_string(q) +
           " bound the same region");
    }
    quad_of_region[region_of_quad[q]] = q;
  }
  r.patches.assign(nq, Patch());
  for (int q = 0; q < nq; ++q) {
    std::array<int, 4> corners;
    for (int s = 0; s < 4; ++s) corners[s] = corner_vertex(layout.quads[q][s]);
    std::string why;
    const auto cycle = part.disk_boundary(region_of_quad[q], corners[0], why);
    if (cycle.empty()) fail("quad " + std::to_string(q) + ": " + why);
    if (!Partitioner::make_sides(cycle, corners, r.patches[q])) {
      fail("quad " + std::to_string(q) + "'s region does not have its 4 corners in cyclic order");
    }
    for (int s = 0; s < 4; ++s) {
      const int h = 4 * q + s;
      std::vector<int> path = part.paths()[traced_as[he.edge[h]]];
      if (h != edge_half[he.edge[h]]) std::reverse(path.begin(), path.end());
      if (r.patches[q].sides[s].vertices != path) {
        fail("side " + std::to_string(s) + " of quad " + std::to_string(q) + " is not its traced path");
      }
    }
  }
  for (int& f : r.face_patch) f = quad_of_region[f];
  std::string why;
  if (!link_sides(r, why)) fail(why);
  collect_faces(r);
  return std::move(r);
}

// Checks the mesh preconditions shared by both entry points; returns the genus.
int checked_genus(const TriMesh& mesh) {
  const TopologyReport topo = analyze_topology(mesh);
  if (!topo.manifold) {
    throw InvalidInput(std::string(kFn) + "the mesh is not manifold (" +
                       std::to_string(topo.non_manifold_edges) + " non-manifold edges, " +
                       std::to_string(topo.non_manifold_vertices) +
                       " non-manifold vertices); run repair_mesh first");
  }
  if (topo.boundary_edges > 0) {
    throw InvalidInput(std::string(kFn) + "the mesh is not closed (" + std::to_string(topo.boundary_loops) +
                       " boundary loops); run repair_mesh first");
  }
  if (topo.components != 1) {
    throw InvalidInput(std::string(kFn) + "the mesh has " + std::to_string(topo.components) +
                       " connected components; partition each one separately");
  }
  if (topo.degenerate_faces > 0) {
    throw InvalidInput(std::string(kFn) + "the mesh has " + std::to_string(topo.degenerate_faces) +
                       " degenerate triangles; run repair_mesh first");
  }
  if (!topo.genus) throw InvalidInput(std::string(kFn) + "the mesh is not orientable");
  return *topo.genus;
}

}  // namespace

std::string check_quad_layout(const QuadLayout& layout, std::size_t num_vertices, int genus) {
  for (std::size_t i = 0; i < layout.corners.size(); ++i) {
    const int v = layout.corners[i];
    if (v < 0 || static_cast<std::size_t>(v) >= num_vertices) {
      return "layout corner " + std::to_string(i) + " = " + std::to_string(v) + " is out of range [0," +
             std::to_string(num_vertices) + ")";
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (layout.corners[j] == v) {
        return "layout corners " + std::to_string(j) + " and " + std::to_string(i) + " are both " +
               vertex_name(v);
      }
    }
  }
  LayoutHalfEdges he;
  std::string why = layout_half_edges(layout, he);
  if (!why.empty()) return why;
  // Uniform remeshing splits each grid quad along a diagonal by the parity of (i + j + patch): an
  // odd-numbered patch's corner cells have the diagonal that misses the corner. Two such cells meeting at a
  // corner of only two quads would share their diagonal (an edge of 4 triangles).
  for (std::size_t c = 0; c < he.out_ccw.size(); ++c) {
    const auto& fan = he.out_ccw[c];
    if (fan.size() == 2 && (fan[0] / 4) % 2 == 1 && (fan[1] / 4) % 2 == 1) {
      return "corner " + std::to_string(c) + " lies in only two quads (" + std::to_string(fan[0] / 4) + " and " +
             std::to_string(fan[1] / 4) +
             "), both odd-numbered: their remeshes would fold there; give one of them an even number";
    }
  }
  const long long euler = static_cast<long long>(layout.corners.size()) - he.num_edges +
                          static_cast<long long>(layout.quads.size());
  if (euler != 2 - 2LL * genus) {
    return "the layout has Euler characteristic " + std::to_string(euler) + " (" +
           std::to_string(layout.corners.size()) + " corners, " + std::to_string(he.num_edges) + " edges, " +
           std::to_string(layout.quads.size()) + " quads) but the mesh has genus " + std::to_string(genus) +
           " (Euler characteristic " + std::to_string(2 - 2 * genus) + ")";
  }
  return "";
}

PartitionResult partition_mesh_layout(const TriMesh& closed_manifold, const QuadLayout& layout,
                                      const PartitionOptions& options) {
  check_points(closed_manifold, layout.corners, {});
  const int genus = checked_genus(closed_manifold);
  const std::string why = check_quad_layout(layout, closed_manifold.positions.size(), genus);
  if (!why.empty()) throw InvalidInput(std::string(kFn) + why);
  LayoutHalfEdges he;
  layout_half_edges(layout, he);
  return partition_layout(closed_manifold, layout, he, options);
}

struct PartitionMeshCache::Impl {
  const TriMesh* mesh = nullptr;
  int genus = 0;
  Connectivity conn;
};

PartitionMeshCache::PartitionMeshCache(const TriMesh& closed_manifold) : impl_(std::make_unique<Impl>()) {
  impl_->mesh = &closed_manifold;
  impl_->genus = checked_genus(closed_manifold);
  impl_->conn = build_connectivity(closed_manifold);
}

PartitionMeshCache::~PartitionMeshCache() = default;

const TriMesh& PartitionMeshCache::mesh() const {
  return *impl_->mesh;
}

PartitionResult partition_mesh_layout(const PartitionMeshCache& cache, const QuadLayout& layout,
                                      const PartitionOptions& options) {
  const TriMesh& mesh = cache.mesh();
  check_points(mesh, layout.corners, {});
  const std::string why = check_quad_layout(layout, mesh.positions.size(), cache.impl_->genus);
  if (!why.empty()) throw InvalidInput(std::string(kFn) + why);
  LayoutHalfEdges he;
  layout_half_edges(layout, he);
  return partition_layout(mesh, layout, he, options, &cache.impl_->conn);
}

PartitionResult partition_mesh(const TriMesh& closed_manifold, const std::vector<int>& partition_points,
                               const std::vector<int>& auxiliary_points, const PartitionOptions& options) {
  const TriMesh& mesh = closed_manifold;
  if (partition_points.size() != 4) {
    throw InvalidInput(std::string(kFn) + "expected 4 partition points, got " +
                       std::to_string(partition_points.size()));
  }
  check_points(mesh, partition_points, auxiliary_points);
  const int genus = checked_genus(mesh);
  if (genus == 0) {
    if (!auxiliary_points.empty() && auxiliary_points.size() != 4) {
      throw InvalidInput(std::string(kFn) + "a genus-0 mesh takes 0 or 4 auxiliary points, got " +
                         std::to_string(auxiliary_points.size()));
    }
    std::vector<std::vector<int>> guides(4);
    for (std::size_t k = 0; k < auxiliary_points.size(); ++k) guides[k] = {auxiliary_points[k]};
    return partition_genus0(mesh, partition_points, guides, options);
  }
  if (genus == 1) {
    if (auxiliary_points.size() != 8) {
      throw InvalidInput(std::string(kFn) +
                         "a genus-1 mesh takes 8 auxiliary points (one per patch edge), got " +
                         std::to_string(auxiliary_points.size()));
    }
    return partition_genus1(mesh, partition_points, auxiliary_points, options);
  }
  throw InvalidInput(std::string(kFn) + "the mesh has genus " + std::to_string(genus) +
                     "; only genus 0 (4 partition points) and genus 1 (4 partition + 8 auxiliary points) "
                     "are supported");
}

PartitionResult partition_mesh_guided(const TriMesh& closed_manifold, const std::vector<int>& partition_points,
                                      const std::vector<std::vector<int>>& side_guides,
                                      const PartitionOptions& options) {
  const TriMesh& mesh = closed_manifold;
  if (partition_points.size() != 4) {
    throw InvalidInput(std::string(kFn) + "expected 4 partition points, got " +
                       std::to_string(partition_points.size()));
  }
  if (side_guides.size() != 4) {
    throw InvalidInput(std::string(kFn) + "expected one guide list per path (4), got " +
                       std::to_string(side_guides.size()));
  }
  std::vector<int> all;
  for (const auto& g : side_guides) all.insert(all.end(), g.begin(), g.end());
  check_points(mesh, partition_points, all);
  const int genus = checked_genus(mesh);
  if (genus != 0) {
    throw InvalidInput(std::string(kFn) + "guide lists per path are for genus 0; the mesh has genus " +
                       std::to_string(genus));
  }
  return partition_genus0(mesh, partition_points, side_guides, options);
}

PartitionStats partition_stats(const PartitionResult& r) {
  PartitionStats stats;
  const TriMesh& m = r.mesh;
  auto polyline = [&](const std::vector<int>& v) {
    double len = 0.0;
    for (std::size_t i = 0; i + 1 < v.size(); ++i) len += (m.positions[v[i + 1]] - m.positions[v[i]]).norm();
    return len;
  };
  double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
  for (const Patch& patch : r.patches) {
    PatchStats ps;
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    for (int f : patch.faces) {
      const auto& t = m.triangles[f];
      const Eigen::Vector3d n =
          0.5 * (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
      normal_sum += n;
      ps.area += n.norm();
    }
    ps.flatness = ps.area > 0.0 ? normal_sum.norm() / ps.area : 0.0;
    for (const PatchSide& side : patch.sides) ps.boundary_length += polyline(side.vertices);
    smallest = std::min(smallest, ps.area);
    largest = std::max(largest, ps.area);
    stats.cut_length += 0.5 * ps.boundary_length;
    stats.patches.push_back(ps);
  }
  stats.area_balance = largest > 0.0 ? smallest / largest : 0.0;
  return stats;
}

}  // namespace geomip
