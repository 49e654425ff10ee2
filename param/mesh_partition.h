// Consistent partition of a closed manifold triangle mesh into quadrilateral disk patches, by shortest paths
// between user-given partition points (Lin, Lee et al., "Consistent mesh parameterizations", §3.2).
//
// Genus 0: four partition points P0..P3 are joined by Dijkstra shortest paths P0→P1→P2→P3→P0 (edge graph,
// Euclidean edge lengths) into one simple closed loop, which cuts the sphere into 2 quadrilateral patches.
// Genus 1: four partition points are the corners of a periodic 2×2 grid of 4 quadrilateral patches whose
// 8 edges are each guided through one auxiliary point. Higher genus is rejected by partition_mesh().
// Any genus, any number of patches: partition_mesh_layout() traces the edges of a quad layout (QuadLayout).
//
// The patches are what the next stages (base mesh by half-edge collapses, mean value embedding on the unit
// square, §3.3) consume: plain index arrays, no half-edge structure (see ../shared/STYLE.md).
#pragma once

#include "mesh/mesh.h"

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace geomip {

/// One side of a quadrilateral patch: the mesh vertices along a traced path, from the patch corner where the
/// side starts to the corner where it ends, both included (at least 2 vertices), in the patch's CCW order.
struct PatchSide {
  std::vector<int> vertices;
};

/// A disk-like patch with 4 corners. Side s runs from corners[s] to corners[(s+1)%4]; walking corners[0],
/// side 0, corners[1], side 1, ... goes once around the patch boundary counter-clockwise as seen from outside
/// the surface, i.e. with the patch on the left, consistent with the triangles' orientation. Mapping corner s
/// to (0,0), (1,0), (1,1), (0,1) therefore puts the patch on the unit square without a flip.
struct Patch {
  std::vector<int> faces;      ///< triangle ids into PartitionResult::mesh, ascending
  std::array<int, 4> corners;  ///< vertex ids (partition points)
  std::array<PatchSide, 4> sides;
};

/// How two patch sides are glued: side `side` of patch `patch` and side `other_side` of patch `other_patch`
/// are the same mesh path. `reversed`: the vertex sequences are each other's reverse (always true on a
/// consistently oriented surface, where two neighbouring patches walk their shared side in opposite
/// directions; kept explicit so consumers need not know that).
struct SideLink {
  int patch;
  int side;
  int other_patch;
  int other_side;
  bool reversed;
};

/// What `partition_mesh()` produces.
struct PartitionResult {
  /// The input mesh, with `split_vertices` vertices appended (edge midpoints, see PartitionOptions). Input
  /// vertices keep their ids and positions; an input triangle that was split keeps its id for its first
  /// piece, the other pieces are appended. Unsplit triangles keep their id and corner order.
  TriMesh mesh;
  std::vector<Patch> patches;  ///< 2 (genus 0) or 4 (genus 1) from partition_mesh(); one per quad from
                               ///< partition_mesh_layout()
  /// Patch id of each triangle of `mesh` (each triangle is in exactly one patch).
  std::vector<int> face_patch;
  /// One entry per (patch, side), patch-major: adjacency[4·p + s] describes side s of patch p.
  std::vector<SideLink> adjacency;
  std::size_t split_vertices = 0;  ///< vertices appended to `mesh` by edge splits
};

struct PartitionOptions {
  /// Repair degenerate configurations by splitting edges at their midpoints (on by default):
  /// - a "chord", i.e. an edge that is not on the cut but joins two cut vertices. A triangle with all three
  ///   vertices on the cut always has one; for the square embedding of §3.3.2 it would put three boundary
  ///   vertices of one triangle on the square's boundary (a flat triangle when on one straight side). With no
  ///   chord left, Floater's (2003) condition holds and a convex-combination map onto the square is
  ///   one-to-one. Splitting a chord adds one vertex inside its patch and 1 or 2 triangles on each side of
  ///   it;
  /// - a path that cannot be traced because earlier paths, with chords, enclose its start or end: the chords
  ///   of the cut so far are split and the path is traced again.
  /// When false, the mesh is never changed, and such a configuration throws InvalidInput.
  bool split_degenerate = true;
};

/// Partitions `closed_manifold` into quadrilateral disk patches connecting the partition points (§3.2).
///
/// \param closed_manifold  one connected component, closed (no boundary edges), manifold edges and vertices,
///   triangles consistently oriented (CCW seen from outside; the orientation of the result follows it).
///   Unreferenced vertices are allowed and ignored.
/// \param partition_points  exactly 4 distinct vertex ids, the patch corners P0..P3.
/// \param auxiliary_points  genus 0: empty, or 4 vertex ids where path k (P_k → P_{k+1 mod 4}) must pass;
///   genus 1: exactly 8 vertex ids, auxiliary point k guides edge k (see below). Distinct from each other and
///   from the partition points.
///
/// Paths are traced in order, each by Dijkstra's algorithm on the edge graph with Euclidean edge lengths
/// (corner → auxiliary point → corner when an auxiliary point is given). A path never passes through a
/// partition or auxiliary point other than its own, nor through a vertex of an earlier path except at its two
/// corners: paths are simple and meet only at corners, so they never cross.
///
/// Genus 0 — the loop P0→P1→P2→P3→P0 (paths 0..3) cuts the surface into two patches:
/// - patch 0 lies to the LEFT of the loop walked P0→P1→P2→P3 on the outside, i.e. the loop is its CCW
///   boundary: corners = {P0,P1,P2,P3}, side k = path k;
/// - patch 1 lies to the right: corners = {P0,P3,P2,P1}, side k = path 3−k reversed.
///   So P0 is corner 0 and P2 corner 2 of both patches, P1 and P3 trade corners 1 and 3: with corner s at
///   (0,0),(1,0),(1,1),(0,1), patch 1's square is patch 0's mirrored across its diagonal P0–P2, and a seam
///   point at (u,v) in patch 0 is at (v,u) in patch 1. Side s of patch 0 is glued to side 3−s of patch 1.
///   Meshes given corresponding partition points thus get corresponding patches, corners and sides.
///
/// Genus 1 — the torus is cut into a periodic 2×2 grid. Seen in the universal cover, corners sit on the
/// integer lattice, P0 at (even,even), P1 at (odd,even), P2 at (even,odd), P3 at (odd,odd); edges join
/// lattice neighbours. The 8 edges k = 0..7, each stored from → to as follows and guided by
/// auxiliary_points[k]:
///
///       P0 ──e0──► P1 ──e1──► P0          e0: P0→P1   e1: P1→P0 (the other way round the torus)
///       ▲           ▲          ▲          e2: P2→P3   e3: P3→P2
///       e5          e7         e5         e4: P0→P2   e5: P2→P0 (the other way round)
///       P2 ──e2──► P3 ──e3──► P2          e6: P1→P3   e7: P3→P1
///       ▲           ▲          ▲
///       e4          e6         e4         e0+e1 and e2+e3 are two disjoint parallel loops around the torus,
///       P0 ──e0──► P1 ──e1──► P0          e4+e5 and e6+e7 two disjoint loops the other way round.
///
/// Each patch has the 4 distinct corners P0, P1, P3, P2 in cyclic order and one edge of each pair as a side.
/// Patch index = 2·a + b, where the patch's P0–P1 side is e0 (a=0) or e1 (a=1) and its P0–P2 side is e4 (b=0)
/// or e5 (b=1): in the picture, patch 2a+b is the square with lower-left corner (a,b). Its corners[0] is that
/// lower-left corner, P_{a+2b}, and the rest follow CCW. So when the points are placed with the picture's
/// orientation seen from outside (patch 0's CCW boundary is P0→P1→P3→P2, bounded by e0,e6,e2,e4), side 0 of
/// every patch is its bottom (a horizontal edge e0..e3), and laying patch 2a+b's unit square at cell (a,b) of
/// a 2×2 grid glues every side to its neighbour by a translation, periodically: the torus becomes one
/// periodic square. When they are placed mirrored (patch 0's boundary is P0→P2→P3→P1), the same holds with
/// patch 2a+b at cell (b,a) and side 0 vertical. Corresponding points on two meshes give corresponding
/// patches, corners and sides.
///
/// Validation (always): every triangle is in exactly one patch; each patch is a topological disk (one
/// boundary loop, V−E+F = 1) whose boundary is exactly its 4 sides meeting at its 4 corners; every side is
/// glued to exactly one side of another patch. After chord splitting no edge joins two cut vertices across a
/// patch. Cost: O(F log F) in the number of triangles, a third of it in analyze_topology() (timings:
/// scripts/bench).
///
/// \throw InvalidInput with "partition_mesh:" and the reason when: a point index is out of range, repeated or
///   not referenced by a triangle; the number of points does not fit the genus; the mesh is not one closed,
///   manifold, consistently oriented component; the genus is 2 or more; a path cannot be traced; the genus-1
///   auxiliary points do not describe a 2×2 grid (e.g. a patch with 2 or 6 sides, or 3 or 5 patches); or a
///   degenerate configuration is found with split_degenerate = false.
/// \throw SolverFailure if a genus-0 result fails validation (a bug, never the input's fault).
PartitionResult partition_mesh(const TriMesh& closed_manifold, const std::vector<int>& partition_points,
                               const std::vector<int>& auxiliary_points,
                               const PartitionOptions& options = {});

/// Genus 0 with any number of guides per path: side_guides[k] (k = 0..3) lists, in order, the vertices path k
/// (P_k → P_{k+1 mod 4}) passes through; partition_mesh(m, p, aux) is this with side_guides[k] = {aux[k]}.
/// Each leg between consecutive guides is a shortest path avoiding the earlier legs, every other guide and
/// every earlier path, so the loop stays simple; a loop that runs down a protrusion to a guide at its tip
/// and back up its other side splits the protrusion lengthwise between the two patches (see
/// choose_partition_points()). Everything else as partition_mesh() for genus 0.
/// \throw InvalidInput as partition_mesh(), and when side_guides does not have 4 lists or the mesh is not
///   genus 0.
PartitionResult partition_mesh_guided(const TriMesh& closed_manifold, const std::vector<int>& partition_points,
                                      const std::vector<std::vector<int>>& side_guides,
                                      const PartitionOptions& options = {});

/// A quad base domain (Praun, Sweldens, Schröder 2001, "Consistent mesh parameterizations"): corners on the
/// mesh and quads between them. Quad q has corners corners[quads[q][0..3]], counter-clockwise seen from
/// outside the surface (the orientation of the mesh's triangles); its side s runs from quads[q][s] to
/// quads[q][(s+1)%4]. The quads must form a closed, oriented, manifold surface of the mesh's genus: every
/// directed layout edge (a, b) appears in exactly one quad and (b, a) in exactly one other, the quads around
/// each corner form one cycle, and #corners − #edges + #quads = 2 − 2·genus. Two corners share at most one
/// layout edge (no double edges), and every corner is used. A corner in only two quads must not be in two
/// odd-numbered ones (uniform_remesh_connectivity()'s diagonal rule would give both corner cells the same
/// diagonal, an edge of four triangles).
struct QuadLayout {
  std::vector<int> corners;               ///< mesh vertex ids, distinct
  std::vector<std::array<int, 4>> quads;  ///< indices into `corners`
};

/// Checks `layout` as a closed quad surface (see QuadLayout) whose corners are vertices of a mesh with
/// `num_vertices` vertices and genus `genus`; returns "" or the first problem found, one line.
std::string check_quad_layout(const QuadLayout& layout, std::size_t num_vertices, int genus);

/// Partitions `closed_manifold` into one quadrilateral disk patch per quad of `layout`, of any genus.
///
/// Layout edges are traced as Dijkstra shortest paths (edge graph, Euclidean lengths): first a spanning
/// tree of the corners (Kruskal, shortest corner distance first), then the other edges, shortest first. A
/// path never passes through a corner other than its own two, nor through a vertex of an earlier path. At
/// both of its corners it must leave the corner between the already traced paths that are its neighbours in
/// the layout's cyclic order around that corner (Praun et al. 2001, §3.3), so that paths land between the
/// right neighbours and each region between them is bounded by its quad's four paths.
///
/// Result: patch q is quad q, with corners[s] = layout.corners[layout.quads[q][s]] and side s the path of its
/// side s; adjacency, face_patch and split vertices as for partition_mesh(). The validation is the same as
/// partition_mesh()'s, and each region is matched to its quad by its corner cycle and side paths.
///
/// \throw InvalidInput with "partition_mesh:" and the reason when the mesh is not one closed, manifold,
///   consistently oriented component, a corner is out of range or repeated, the layout is not a closed quad
///   surface of the mesh's genus (check_quad_layout()), a path cannot be traced, or the traced paths do not
///   cut the mesh into the layout's quads (corner cycles that disagree with the mesh).
PartitionResult partition_mesh_layout(const TriMesh& closed_manifold, const QuadLayout& layout,
                                      const PartitionOptions& options = {});

/// What partition_mesh_layout() derives from the mesh alone — its checks, its genus, its half-edge
/// connectivity — computed once for many layouts of one mesh (choose_quad_layout() partitions the same mesh
/// for every pairing and corner move it tries: a fifth of its time went to these). Refers to the mesh, which
/// must outlive it unchanged.
class PartitionMeshCache {
 public:
  /// \throw InvalidInput as partition_mesh_layout() when the mesh is not one closed, manifold, consistently
  ///   oriented component.
  explicit PartitionMeshCache(const TriMesh& closed_manifold);
  ~PartitionMeshCache();
  PartitionMeshCache(const PartitionMeshCache&) = delete;
  PartitionMeshCache& operator=(const PartitionMeshCache&) = delete;
  const TriMesh& mesh() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  friend PartitionResult partition_mesh_layout(const PartitionMeshCache&, const QuadLayout&,
                                               const PartitionOptions&);
};

/// partition_mesh_layout() of cache.mesh(): the same result, without checking and connecting the mesh again.
PartitionResult partition_mesh_layout(const PartitionMeshCache& cache, const QuadLayout& layout,
                                      const PartitionOptions& options = {});

/// Quality figures of a partition, in the mesh's units.
struct PatchStats {
  double area = 0.0;             ///< sum of triangle areas
  double boundary_length = 0.0;  ///< sum of the 4 sides' polyline lengths
  /// |Σ a_f n_f| / Σ a_f over the patch's triangles (a_f area, n_f unit normal): the patch's projected area
  /// on its best plane over its area. 1 for a flat patch, near 1 for a height field over a plane, small when
  /// the patch wraps around (a cap, a tube): a cheap proxy for how much a map to the square must distort.
  double flatness = 0.0;
};
struct PartitionStats {
  std::vector<PatchStats> patches;
  double area_balance = 0.0;  ///< smallest patch area / largest patch area, in (0, 1]
  double cut_length = 0.0;    ///< total length of the cut (each shared side counted once)
};

/// Measures `partition` (areas, side lengths, flatness). Never throws on a result of partition_mesh().
PartitionStats partition_stats(const PartitionResult& partition);

}  // namespace geomip
