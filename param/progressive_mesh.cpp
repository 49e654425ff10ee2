#include "param/progressive_mesh.h"

// OpenMesh's VectorT is deliberately left uninitialised by its default constructor, and its property vectors
// push default-constructed values when vertices are added: GCC's -Wmaybe-uninitialized reports that inside
// OpenMesh's templates. Nothing here reads such a value (every position is set right after add_vertex).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "mesh/predicates.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/BaseDecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModBaseT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <queue>
#include <string>
#include <unordered_map>

namespace geomip {
namespace {

struct PmTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using PmMesh = OpenMesh::TriMesh_ArrayKernelT<PmTraits>;

[[noreturn]] void fail(const char* function, const std::string& what) {
  throw InvalidInput(std::string(function) + ": " + what);
}

/// next_on_boundary[v] = w for every directed boundary edge v→w (patch on the left), -1 elsewhere.
/// \pre the triangles form a manifold disk (checked by the caller).
std::vector<int> boundary_successors(const TriMesh& patch) {
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(patch.triangles.size() * 3);
  for (const auto& t : patch.triangles) {
    for (int i = 0; i < 3; ++i) directed.emplace(directed_edge_key(t[i], t[(i + 1) % 3]), 1);
  }
  std::vector<int> next(patch.positions.size(), -1);
  for (const auto& t : patch.triangles) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if (directed.count(directed_edge_key(b, a)) == 0) next[a] = b;
    }
  }
  return next;
}

void require_disk(const char* function, const TriMesh& patch) {
  const TopologyReport topo = analyze_topology(patch);
  if (!topo.manifold || topo.components != 1 || topo.boundary_loops != 1 || !topo.genus || *topo.genus != 0) {
    fail(function, "the patch is not a manifold disk (" + std::to_string(topo.components) + " components, " +
                       std::to_string(topo.boundary_loops) + " boundary loops, " +
                       (topo.manifold ? "manifold" : "non-manifold") + ")");
  }
  if (topo.unreferenced_vertices != 0) {
    fail(function, std::to_string(topo.unreferenced_vertices) + " unreferenced vertices");
  }
  if (topo.degenerate_faces != 0)
    fail(function, std::to_string(topo.degenerate_faces) + " degenerate triangles");
}

/// Checks that `sides` is exactly the boundary loop of `patch` cut at four distinct corners, and that no
/// interior edge joins two vertices of one side. Returns the per-vertex side bit mask (bit k: on side k;
/// corners have two bits).
std::vector<std::uint8_t> side_masks(const char* function, const TriMesh& patch, const PatchSides& sides) {
  const int n = static_cast<int>(patch.positions.size());
  const std::vector<int> next = boundary_successors(patch);
  std::vector<std::uint8_t> mask(n, 0);
  std::vector<char> visited(n, 0);
  std::size_t covered = 0;
  for (int k = 0; k < 4; ++k) {
    const auto& side = sides[k];
    if (side.size() < 2) fail(function, "side " + std::to_string(k) + " has fewer than 2 vertices");
    if (side.back() != sides[(k + 1) % 4].front()) {
      fail(function, "side " + std::to_string(k) + " does not end where side " + std::to_string((k + 1) % 4) +
                         " starts");
    }
    for (std::size_t i = 0; i < side.size(); ++i) {
      const int v = side[i];
      if (v < 0 || v >= n) fail(function, "side vertex id out of range");
      if (i + 1 < side.size()) {
        if (next[v] != side[i + 1]) {
          fail(function, "side " + std::to_string(k) + " does not follow the boundary loop at vertex " +
                             std::to_string(v) + " (sides must run with the patch on their left)");
        }
        if (visited[v]) fail(function, "vertex " + std::to_string(v) + " is on the boundary twice");
        visited[v] = 1;
        ++covered;
      }
      mask[v] |= static_cast<std::uint8_t>(1u << k);
    }
  }
  std::size_t loop = 0;
  for (int v = 0; v < n; ++v) loop += next[v] >= 0 ? 1 : 0;
  if (covered != loop) fail(function, "the sides do not cover the boundary loop once");
  for (const auto& t : patch.triangles) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if ((mask[a] & mask[b]) != 0 && next[a] != b && next[b] != a) {
        fail(function, "interior edge (" + std::to_string(a) + ", " + std::to_string(b) +
                           ") joins two vertices of one side: it would be flat in the parameter square");
      }
    }
  }
  return mask;
}

/// The paper's locks (section 3.3.1) as a binary OpenMesh decimation module. OpenMesh's v0 is the removed
/// vertex (the paper's v2), v1 the kept one.
template <class MeshT>
class ModPatchLocksT : public OpenMesh::Decimater::ModBaseT<MeshT> {
 public:
  DECIMATING_MODULE(ModPatchLocksT, MeshT, PatchLocks);

  explicit ModPatchLocksT(MeshT& mesh) : Base(mesh, true) {}

  void configure(const std::vector<std::uint8_t>* side_mask, const std::vector<char>* locked) {
    side_mask_ = side_mask;
    locked_ = locked;
  }

  float collapse_priority(const CollapseInfo& ci) override {
    const MeshT& m = Base::mesh();
    const int v0 = ci.v0.idx(), v1 = ci.v1.idx();
    if ((*locked_)[v0]) return Base::ILLEGAL_COLLAPSE;  // corners and features stay
    const std::uint8_t m0 = (*side_mask_)[v0], m1 = (*side_mask_)[v1];
    int other = -1;  // v0's boundary neighbour other than v1 (boundary v0 only)
    if (m0 != 0) {
      // Boundary straightness, and the vertex stays on its own side.
      if (!m.is_boundary(m.edge_handle(ci.v0v1)) || (m0 & m1) == 0) return Base::ILLEGAL_COLLAPSE;
      for (auto h : m.voh_range(ci.v0)) {
        if (m.is_boundary(m.edge_handle(h)) && m.to_vertex_handle(h) != ci.v1)
          other = m.to_vertex_handle(h).idx();
      }
    }
    if (m1 == 0) return Base::LEGAL_COLLAPSE;
    // Every neighbour w of v0 becomes a neighbour of v1. The new edge (v1, w) must not be an interior edge
    // between two vertices of one side (it would be flat in the square).
    for (auto h : m.voh_range(ci.v0)) {
      const auto w = m.to_vertex_handle(h);
      if (w == ci.v1 || w == ci.vl || w == ci.vr || w.idx() == other) continue;
      if ((m1 & (*side_mask_)[w.idx()]) != 0) return Base::ILLEGAL_COLLAPSE;
    }
    return Base::LEGAL_COLLAPSE;
  }

 private:
  const std::vector<std::uint8_t>* side_mask_ = nullptr;
  const std::vector<char>* locked_ = nullptr;
};

/// OpenMesh's decimation framework (BaseDecimaterT: the modules and their priorities) driven by our own loop,
/// which is DecimaterT::decimate_to() with three changes: it records every collapse for the vertex splits; it
/// breaks priority ties by vertex id so that the result does not depend on heap internals; and its
/// topological test is BaseDecimaterT::is_collapse_legal() with TriConnectivity::is_collapse_ok() done on a
/// reusable mark array (OpenMesh 9's allocates on every call, which made it ~60% of the run time). DecimaterT
/// itself would also pull in libOpenMeshTools for its observer.
class RecordingDecimater : public OpenMesh::Decimater::BaseDecimaterT<PmMesh> {
 public:
  using Base = OpenMesh::Decimater::BaseDecimaterT<PmMesh>;
  explicit RecordingDecimater(PmMesh& mesh) : Base(mesh), mesh_(mesh) {}

  /// Collapses until `target` vertices remain or no legal collapse is left; appends to `log`.
  void decimate_to(std::size_t target, const std::vector<std::uint8_t>& side_mask,
                   std::vector<HalfEdgeCollapse>& log) {
    std::size_t alive = mesh_.n_vertices();
    stamp_.assign(mesh_.n_vertices(), 0);
    mark_.assign(mesh_.n_vertices(), 0);
    target_.assign(mesh_.n_vertices(), PmMesh::HalfedgeHandle());
    for (auto v : mesh_.vertices()) push_best(v);
    std::vector<PmMesh::VertexHandle> support;
    while (alive > target && !heap_.empty()) {
      const Entry top = heap_.top();
      heap_.pop();
      const auto v = PmMesh::VertexHandle(top.vertex);
      if (top.stamp != stamp_[top.vertex] || mesh_.status(v).deleted()) continue;
      CollapseInfo ci(mesh_, target_[top.vertex]);
      if (!legal(ci)) continue;  // as DecimaterT: wait until a neighbour changes

      support.clear();
      for (auto w : mesh_.vv_range(ci.v0)) support.push_back(w);
      log.push_back(record(ci, side_mask));
      this->preprocess_collapse(ci);
      mesh_.collapse(ci.v0v1);
      --alive;
      if (mesh_.has_face_normals()) {
        for (auto f : mesh_.vf_range(ci.v1)) mesh_.set_normal(f, mesh_.calc_face_normal(f));
      }
      this->postprocess_collapse(ci);
      for (auto w : support) push_best(w);
    }
  }

 private:
  struct Entry {
    float priority;
    int vertex;
    std::uint32_t stamp;
    bool operator<(const Entry& o) const {  // std::priority_queue is a max-heap: invert for the smallest
      return priority != o.priority ? priority > o.priority : vertex > o.vertex;
    }
  };

  /// DecimaterT::heap_vertex(): the cheapest legal outgoing collapse of v, or none.
  void push_best(PmMesh::VertexHandle v) {
    const int i = v.idx();
    ++stamp_[i];
    float best = std::numeric_limits<float>::max();
    PmMesh::HalfedgeHandle best_h;
    for (auto h : mesh_.voh_range(v)) {
      CollapseInfo ci(mesh_, h);
      if (!legal(ci)) continue;
      const float priority = this->collapse_priority(ci);
      if (priority >= 0.0f && priority < best) {
        best = priority;
        best_h = h;
      }
    }
    if (!best_h.is_valid()) return;
    target_[i] = best_h;
    heap_.push({best, i, stamp_[i]});
  }

  /// TriConnectivity::is_collapse_ok(): the link condition and the boundary cases.
  bool collapse_ok(const CollapseInfo& ci) {
    const auto h = ci.v0v1, o = ci.v1v0;
    if (mesh_.status(mesh_.edge_handle(h)).deleted()) return false;
    if (mesh_.status(ci.v0).deleted() || mesh_.status(ci.v1).deleted()) return false;
    PmMesh::VertexHandle vl, vr;
    if (!mesh_.is_boundary(h)) {
      const auto h1 = mesh_.next_halfedge_handle(h), h2 = mesh_.next_halfedge_handle(h1);
      vl = mesh_.to_vertex_handle(h1);
      if (mesh_.is_boundary(mesh_.opposite_halfedge_handle(h1)) &&
          mesh_.is_boundary(mesh_.opposite_halfedge_handle(h2))) {
        return false;
      }
    }
    if (!mesh_.is_boundary(o)) {
      const auto h1 = mesh_.next_halfedge_handle(o), h2 = mesh_.next_halfedge_handle(h1);
      vr = mesh_.to_vertex_handle(h1);
      if (mesh_.is_boundary(mesh_.opposite_halfedge_handle(h1)) &&
          mesh_.is_boundary(mesh_.opposite_halfedge_handle(h2))) {
        return false;
      }
    }
    if (vl == vr) return false;
    if (++mark_stamp_ == 0) {
      std::fill(mark_.begin(), mark_.end(), 0);
      mark_stamp_ = 1;
    }
    for (auto w : mesh_.vv_range(ci.v1)) mark_[w.idx()] = mark_stamp_;
    for (auto w : mesh_.vv_range(ci.v0)) {
      if (mark_[w.idx()] == mark_stamp_ && w != vl && w != vr) return false;  // a third common neighbour
    }
    return !(mesh_.is_boundary(ci.v0) && mesh_.is_boundary(ci.v1) && !mesh_.is_boundary(h) &&
             !mesh_.is_boundary(o));
  }

  /// BaseDecimaterT::is_collapse_legal() with the fast collapse_ok() (no locked/feature status is used here:
  /// the locks are ModPatchLocksT's).
  bool legal(const CollapseInfo& ci) {
    if (!collapse_ok(ci)) return false;
    if (ci.vl.is_valid() && ci.vr.is_valid() && mesh_.find_halfedge(ci.vl, ci.vr).is_valid() &&
        mesh_.valence(ci.vl) == 3 && mesh_.valence(ci.vr) == 3) {
      return false;
    }
    if (mesh_.is_boundary(ci.v0)) {
      if (!mesh_.is_boundary(ci.v1)) return false;
      if (ci.vl.is_valid() && ci.vr.is_valid()) return false;
    }
    // at least two triangles at v0
    return mesh_.cw_rotated_halfedge_handle(mesh_.cw_rotated_halfedge_handle(ci.v0v1)) != ci.v0v1;
  }

  HalfEdgeCollapse record(const CollapseInfo& ci, const std::vector<std::uint8_t>& side_mask) const {
    HalfEdgeCollapse c;
    c.removed = ci.v0.idx();
    c.kept = ci.v1.idx();
    c.left = ci.vl.is_valid() ? ci.vl.idx() : -1;
    c.right = ci.vr.is_valid() ? ci.vr.idx() : -1;
    c.left_triangle = ci.fl.is_valid() ? ci.fl.idx() : -1;
    c.right_triangle = ci.fr.is_valid() ? ci.fr.idx() : -1;
    for (auto f : mesh_.vf_range(ci.v0)) {
      if (f != ci.fl && f != ci.fr) c.moved_triangles.push_back(f.idx());
    }
    if (side_mask[c.removed] != 0) {
      for (auto h : mesh_.voh_range(ci.v0)) {
        if (mesh_.is_boundary(mesh_.edge_handle(h)) && mesh_.to_vertex_handle(h) != ci.v1) {
          c.boundary_neighbor = mesh_.to_vertex_handle(h).idx();
        }
      }
    }
    return c;
  }

  PmMesh& mesh_;
  std::priority_queue<Entry> heap_;
  std::vector<std::uint32_t> stamp_;
  std::vector<PmMesh::HalfedgeHandle> target_;
  std::vector<std::uint32_t> mark_;
  std::uint32_t mark_stamp_ = 0;
};

}  // namespace

PatchSides patch_sides(const TriMesh& patch, const std::array<int, 4>& corners) {
  constexpr const char* kFn = "patch_sides";
  require_disk(kFn, patch);
  const int n = static_cast<int>(patch.positions.size());
  for (int k = 0; k < 4; ++k) {
    if (corners[k] < 0 || corners[k] >= n) fail(kFn, "corner id out of range");
    for (int j = 0; j < k; ++j) {
      if (corners[j] == corners[k]) fail(kFn, "corner " + std::to_string(corners[k]) + " is repeated");
    }
  }
  const std::vector<int> next = boundary_successors(patch);
  for (int k = 0; k < 4; ++k) {
    if (next[corners[k]] < 0) fail(kFn, "corner " + std::to_string(corners[k]) + " is not on the boundary");
  }
  PatchSides sides;
  for (int k = 0; k < 4; ++k) {
    const int end = corners[(k + 1) % 4];
    std::vector<int>& side = sides[k];
    side.push_back(corners[k]);
    for (int v = next[corners[k]];; v = next[v]) {
      side.push_back(v);
      if (v == end) break;
      for (int j = 0; j < 4; ++j) {
        if (v == corners[j]) fail(kFn, "the corners are not in boundary-loop order (patch on the left)");
      }
      if (side.size() > static_cast<std::size_t>(n)) fail(kFn, "the boundary loop does not close");
    }
  }
  return sides;
}

ProgressiveMesh progressive_mesh(const TriMesh& patch, const PatchSides& sides,
                                 const std::vector<int>& features, const ProgressiveMeshOptions& options) {
  constexpr const char* kFn = "progressive_mesh";
  require_disk(kFn, patch);
  const int n = static_cast<int>(patch.positions.size());
  const std::vector<std::uint8_t> mask = side_masks(kFn, patch, sides);

  std::vector<char> locked(n, 0);
  for (int k = 0; k < 4; ++k) locked[sides[k].front()] = 1;
  for (int f : features) {
    if (f < 0 || f >= n) fail(kFn, "feature id " + std::to_string(f) + " out of range");
    locked[f] = 1;
  }
  const std::size_t num_locked = static_cast<std::size_t>(std::count(locked.begin(), locked.end(), 1));

  PmMesh mesh;
  mesh.reserve(patch.positions.size(), patch.positions.size() + patch.triangles.size(),
               patch.triangles.size());
  for (const auto& p : patch.positions) mesh.add_vertex(PmMesh::Point(p.x(), p.y(), p.z()));
  for (const auto& t : patch.triangles) {
    const auto f =
        mesh.add_face(PmMesh::VertexHandle(t[0]), PmMesh::VertexHandle(t[1]), PmMesh::VertexHandle(t[2]));
    if (!f.is_valid()) fail(kFn, "OpenMesh rejected a triangle (complex edge or vertex)");
  }
  // Held across the decimater's lifetime so that the deleted flags survive its destructor.
  mesh.request_vertex_status();
  mesh.request_edge_status();
  mesh.request_face_status();

  ProgressiveMesh pm;
  pm.num_vertices = patch.positions.size();
  pm.num_triangles = patch.triangles.size();
  pm.sides = sides;
  pm.features = features;

  const std::size_t target =
      options.target_vertices != 0 ? options.target_vertices : std::max<std::size_t>(num_locked + 16, 100);
  if (target < pm.num_vertices) {
    RecordingDecimater decimater(mesh);
    OpenMesh::Decimater::ModQuadricT<PmMesh>::Handle quadric;
    ModPatchLocksT<PmMesh>::Handle locks;
    decimater.add(quadric);
    decimater.add(locks);
    decimater.module(quadric).unset_max_err();
    decimater.module(locks).configure(&mask, &locked);
    OpenMesh::Decimater::ModNormalFlippingT<PmMesh>::Handle normals;
    if (options.max_normal_deviation_degrees < 180.0) {
      mesh.request_face_normals();
      mesh.update_face_normals();
      decimater.add(normals);
      decimater.module(normals).set_max_normal_deviation(options.max_normal_deviation_degrees);
    }
    if (!decimater.initialize())
      throw SolverFailure(std::string(kFn) + ": OpenMesh decimater did not initialize");
    pm.collapses.reserve(pm.num_vertices - target);
    decimater.decimate_to(target, mask, pm.collapses);
  }

  for (auto v : mesh.vertices()) {
    if (!mesh.status(v).deleted()) pm.base_vertices.push_back(v.idx());
  }
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    std::array<int, 3> t{};
    int i = 0;
    for (auto v : mesh.fv_range(f)) t[i++] = v.idx();
    pm.base_triangles.push_back(t);
    pm.base_triangle_ids.push_back(f.idx());
  }
  return pm;
}

void apply_vertex_split(const HalfEdgeCollapse& c, std::vector<std::array<int, 3>>& triangles) {
  constexpr const char* kFn = "apply_vertex_split";
  const int nt = static_cast<int>(triangles.size());
  for (int id : c.moved_triangles) {
    if (id < 0 || id >= nt) fail(kFn, "triangle id out of range");
    auto& t = triangles[id];
    auto it = std::find(t.begin(), t.end(), c.kept);
    if (it == t.end())
      fail(kFn, "moved triangle " + std::to_string(id) + " does not contain the kept vertex");
    *it = c.removed;
  }
  auto revive = [&](int id, std::array<int, 3> t) {
    if (id < 0) return;
    if (id >= nt) fail(kFn, "triangle id out of range");
    if (triangles[id][0] >= 0) fail(kFn, "wing triangle " + std::to_string(id) + " already exists");
    triangles[id] = t;
  };
  revive(c.left_triangle, {c.removed, c.kept, c.left});
  revive(c.right_triangle, {c.kept, c.removed, c.right});
}

std::vector<std::array<int, 3>> triangles_after_splits(const ProgressiveMesh& pm, std::size_t num_splits) {
  if (num_splits > pm.collapses.size()) fail("triangles_after_splits", "more splits than collapses");
  std::vector<std::array<int, 3>> triangles(pm.num_triangles, {-1, -1, -1});
  for (std::size_t i = 0; i < pm.base_triangles.size(); ++i) {
    const int id = pm.base_triangle_ids[i];
    if (id < 0 || static_cast<std::size_t>(id) >= pm.num_triangles) {
      fail("triangles_after_splits", "base triangle id out of range");
    }
    triangles[id] = pm.base_triangles[i];
  }
  for (std::size_t s = 0; s < num_splits; ++s) {
    apply_vertex_split(pm.collapses[pm.collapses.size() - 1 - s], triangles);
  }
  return triangles;
}

}  // namespace geomip
