// Coarse-to-fine parameterization of a patch by replaying its progressive mesh's vertex splits
// (../shared/seed/consistent-mesh-parameterizations.txt, section 3.3.4; Sander et al. 2002 / Hormann et al.).
#pragma once

#include "mesh/mesh.h"
#include "param/progressive_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

namespace geomip {

/// Called after each vertex insertion, first on the new vertex and then on each of its neighbours that is
/// neither a corner nor a feature vertex. `ring_triangles` are the ids of the triangles around `vertex` at
/// the current level (read their corners with `CoarseToFine::triangle()`). The callback may move `vertex`,
/// and only `vertex`, through `CoarseToFine::uv()`; a boundary vertex must stay on its side. CoarseToFine
/// checks after every call that no triangle around `vertex` is flipped or degenerate and throws SolverFailure
/// if one is.
using VertexOptimizer = std::function<void(int vertex, const std::vector<int>& ring_triangles)>;

struct CoarseToFineOptions {
  /// After every split, also count flipped triangles over the whole current level (O(F) per split, so
  /// O(F²) in all): for tests and debugging. The local check around the changed vertices is always on.
  bool check_all_triangles = false;
  /// Optional metric tensors per patch vertex (not owned; must outlive the object): the sides' chord
  /// lengths are measured in them, as square_boundary_uv() with the same tensors places the base mesh's
  /// side vertices. Null = Euclidean.
  const std::vector<Eigen::Matrix3d>* side_metrics = nullptr;
};

struct CoarseToFineResult {
  std::vector<Eigen::Vector2d> uv;            ///< (u, v) ∈ [0,1]² for every patch vertex
  std::vector<std::array<int, 3>> triangles;  ///< the full patch's triangles (the input's, in its order)
  /// Boundary vertices that are not at their chord-length position (that of `square_boundary_uv()` on the
  /// full patch) because every attempt to put them there would have flipped a triangle.
  std::size_t boundary_off_chord = 0;
  double min_area2 = 0.0;  ///< smallest doubled parameter area over the triangles
};

/// The coarse-to-fine state: the current level of a patch's progressive mesh and its parameterization. A
/// class because the stretch optimizer works on this state between insertions (through `uv()` and
/// `triangle()`).
///
/// Each vertex split re-inserts the removed vertex v2 of one collapse (in reverse collapse order):
/// - an interior vertex goes to the area centroid of the kernel of its neighbourhood polygon, i.e. of the
///   intersection of the half-planes to the left of the polygon's edges, computed by clipping the unit square
///   against each of them. The kernel is not empty when the level before is an embedding (v1 lies on its
///   closure), so no triangle flips;
/// - a boundary vertex goes on its side, between its two boundary neighbours, to its chord-length position
///   (3D arc length along the side of the full patch, as `square_boundary_uv()` places it) when that flips no
///   triangle; otherwise to the point nearest to it that keeps a quarter of the admissible part of the side
///   (where no triangle flips) on either side, and it moves on to its chord-length position as soon as a
///   later split in its ring (or the last split) allows it. Either way the side stays monotone.
/// Corners and feature vertices are never removed, so they keep their base-mesh parameters throughout.
/// Every step is local: O(valence²) per split plus the callbacks. The object keeps references to `patch` and
/// `pm`: they must outlive it.
class CoarseToFine {
 public:
  /// \param patch  the full patch the progressive mesh was built from (its 3D positions are used for the
  ///               chord lengths along the sides)
  /// \param pm     its progressive mesh (`progressive_mesh(patch, ...)`)
  /// \param base_uv  (u, v) per patch vertex; read for `pm.base_vertices` only. The base mesh must be an
  ///               embedding in the unit square with corner k at (0,0), (1,0), (1,1), (0,1) for k = 0..3 and
  ///               the base boundary vertices on their sides, e.g. `mean_value_embedding()` of the base
  ///               triangles with `square_boundary_uv()` of `pm.sides`.
  /// \throw InvalidInput if sizes disagree, `pm` does not fit `patch`, or the base mesh has a flipped
  /// triangle
  ///        or a corner off its place.
  CoarseToFine(const TriMesh& patch, const ProgressiveMesh& pm, const std::vector<Eigen::Vector2d>& base_uv,
               const CoarseToFineOptions& options = {});

  std::size_t num_splits() const { return pm_.collapses.size(); }
  std::size_t splits_done() const { return done_; }
  bool finished() const { return done_ == pm_.collapses.size(); }

  /// Performs the next vertex split, then calls `optimize` (if not empty) as described at `VertexOptimizer`.
  /// Returns the re-inserted vertex, or -1 when the full patch is reached.
  /// \throw SolverFailure if a triangle flips (a bug here, or an optimizer that broke its contract).
  int split_next(const VertexOptimizer& optimize = {});
  /// Splits until `num_splits()` splits are done.
  void refine_all(const VertexOptimizer& optimize = {});

  /// Parameters of all patch vertices; entries of vertices absent at the current level are meaningless.
  /// The mutable overload is for the optimizer callback.
  const std::vector<Eigen::Vector2d>& uv() const { return uv_; }
  std::vector<Eigen::Vector2d>& uv() { return uv_; }
  /// Current corners of triangle `id` (counter-clockwise), {-1,-1,-1} if it is absent at this level.
  const std::array<int, 3>& triangle(int id) const { return triangles_[id]; }
  /// Ids of the triangles around vertex `v` at this level (empty if `v` is absent).
  const std::vector<int>& vertex_triangles(int v) const { return star_[v]; }
  /// All triangles of the patch indexed by id, as at this level ({-1,-1,-1} for absent ones).
  const std::vector<std::array<int, 3>>& current_triangles() const { return triangles_; }

  /// The parameterization of the full patch.
  /// \throw InvalidInput if called before `finished()`.
  CoarseToFineResult result() const;

 private:
  void insert_interior(int v, int kept);
  /// Moves free vertex v to the area centroid of the kernel of its star (walking towards `anchor` if rounding
  /// puts the centroid outside); false, and v unmoved, when the kernel is empty.
  bool move_to_kernel_centroid(int v, const Eigen::Vector2d& anchor);
  /// After the last split: brings boundary vertices still off their chord-length position there, relaxing
  /// the interior vertices around them to make room (seams of adjacent patches must agree).
  void settle_off_chord();
  /// Puts boundary vertex v at its chord-length position, relaxing the free vertices of its 2-ring up to
  /// `rounds` times to make room; false when it is still off (v is then at the admissible point nearest).
  bool settle_on_chord(int v, int rounds);
  static constexpr int kSettleRounds = 200;
  static constexpr int kInsertSettleRounds = 8;
  void insert_boundary(const HalfEdgeCollapse& c);
  bool place_on_side(int v);
  void retry_off_chord(int v);
  void check_star(int v, const char* when) const;
  double side_arclength(int side, int v) const;

  const TriMesh& patch_;
  const ProgressiveMesh& pm_;
  CoarseToFineOptions options_;
  std::vector<Eigen::Vector2d> uv_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<std::vector<int>> star_;
  std::vector<char> fixed_;        // corners and features: never passed to the optimizer
  std::vector<int> side_of_;       // side of a non-corner boundary vertex, -1 elsewhere
  std::vector<double> arclength_;  // 3D arc length from its side's first corner (non-corner boundary)
  std::array<double, 4> side_length_{};
  std::size_t done_ = 0;
  std::vector<char> off_chord_;  // boundary vertices not (yet) at their chord-length position
  std::size_t num_off_chord_ = 0;
};

/// Convenience: the whole coarse-to-fine pass without an optimizer (pure kernel-centroid insertion).
/// Same arguments and exceptions as `CoarseToFine`.
CoarseToFineResult coarse_to_fine(const TriMesh& patch, const ProgressiveMesh& pm,
                                  const std::vector<Eigen::Vector2d>& base_uv,
                                  const CoarseToFineOptions& options = {});

}  // namespace geomip
