// Foldover-free feature alignment of a patch embedding: "triangulation over time" (paper §3.3.3 and §3.4,
// after Fujimura & Makarov 1998, "Foldover-free image warping").
//
// Each patch of each model has an embedding `uv` of its base mesh in the unit square (corners on the square's
// corners, boundary vertices on its sides, interior vertices strictly inside, no flipped triangle). Some
// interior vertices are features; corresponding features of all models must end at the same uv, the average
// of their positions (§3.4.1, `average_feature_targets`). `warp_features` moves them there (§3.4.2) with a
// piecewise-linear homeomorphism of the square, and keeps the base mesh itself free of flipped triangles.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace geomip {

struct FeatureWarpOptions {
  /// Stop the binary search for an event (a warp triangle incident to the moving feature reaching zero signed
  /// area) when the bracket on the path parameter t ∈ [0,1] is this narrow.
  double event_tolerance = 1e-13;
  /// A feature's straight path may not pass closer than this (uv units) to another warp vertex (a corner or
  /// another feature): such a path is re-routed through one waypoint, or deferred until the blocking feature
  /// has moved. Targets must be farther apart than this, and farther than this from the square's sides.
  double collision_distance = 1e-7;
  /// When > 0, a path should pass another feature no closer than this times the sum of both features' star
  /// radii (the longest base edge at each); such a path is re-routed through a waypoint beside the other
  /// feature, or waits while that feature has yet to move. Off by default: on the 20×20-grid trials of the
  /// tests, 1.5 left more features unreached than straight paths did.
  double clearance = 0;
  /// When a base-mesh triangle would invert during a step, the feature stops this fraction of the way to the
  /// inversion (the triangle keeps 1 - fraction of its area) and the free (non-feature, non-boundary) vertices
  /// around that triangle are repaired. In (0,1).
  double repair_stop_fraction = 0.5;
  /// A repair relaxes the free vertices of the triangle, then of its 1-ring, 2-ring, ... up to this many rings,
  /// until the triangle has doubled its area. Each vertex goes to the centroid of the kernel of its star; if
  /// the triangle did not grow, to the point of the kernel that maximizes its smallest star triangle
  /// (Freitag & Plassmann 2000); if it still did not grow, centroids again over 4× as many rings.
  int repair_rings = 3;
  /// Gauss–Seidel sweeps per ring.
  int repair_sweeps = 3;
  /// Keep the base mesh free of inverted triangles (stop before an inversion and repair, see above). false
  /// gives the plain warp of the paper, which maps vertices only and may invert straight-edged base triangles
  /// (counted in `FeatureWarpResult::flipped_triangles`, no exception); for comparison and tests.
  bool keep_base_mesh_valid = true;
  /// A step moves the feature at most this fraction of its distance to the nearest other warp vertex
  /// (0: no bound, steps end only at events and repairs).
  double max_step_fraction = 0.1;
  /// After every step, flip warp edges until the warp mesh is Delaunay again (kinetic Delaunay). false: flip
  /// only at degeneracy events, as in the paper.
  bool keep_delaunay = true;
  /// Upper bound on warp edge flips (events) over the whole call.
  std::size_t max_events = 100000;
  /// Upper bound on steps (moves between events/repairs) of one feature; a feature that needs more is stopped
  /// where it is (still foldover-free) and reported in `FeatureWarpResult::unreached`.
  std::size_t max_steps_per_feature = 20000;
  /// A feature that stalls (the repair cannot keep the base triangles ahead of it positive) steps aside this
  /// many times at most before it is reported unreached: back by half a `sidestep_length` and to the left or
  /// right of its way (alternately, by 1, 1, 2, 2, ... `sidestep_length`), then on toward its target.
  int sidesteps = 4;
  double sidestep_length = 0.03;
  /// When a pass leaves features unreached, up to this many more passes start again from the input uv and
  /// move first the features the previous pass left unreached (in the order they moved there), then the
  /// others in the previous pass's order: a feature moved early crosses a fresh base mesh, and the features
  /// that stall are the ones whose way leads through the stars that earlier moves dragged and squeezed. Only
  /// the last pass steps aside (`sidesteps`); the earlier ones give a stalled feature up at once. A pass stops
  /// as soon as it has left as many features unreached as the best one so far; the pass with the fewest
  /// unreached features is kept. 0: one pass in the given order, with steps aside. Negative: InvalidInput.
  int reorder_passes = 3;
  /// After the passes, the features they left short (and no proof rules out) walk on from the best pass's
  /// embedding with a barrier relaxation: projected Newton steps on the symmetric Dirichlet energy of the map
  /// from the input embedding (infinite at a flat triangle, so the fans the warp squeezed open up again and
  /// nothing flips) over the free vertices within 24 rings, the feature drawn to its target by a quadratic
  /// term of growing weight and placed exactly on it once its star is positive there. If some are still
  /// short, every feature is placed on its target and the free vertices are untangled (Garanzha et al. 2021,
  /// "Foldover-free maps in 50 lines of code": a regularized energy that is finite on folded triangles, so it
  /// passes through folded states that no walk through fold-free ones can cross), from the embedding so far,
  /// then from the input embedding, then from the Tutte embedding of the pinned vertices; the first start that
  /// the exact predicate finds fold-free is kept. If that fails, every feature walks with the relaxation from
  /// the input embedding, in up to 6 orders; the order that leaves the fewest short is kept when that is fewer
  /// than before, and untangled once more from there. The embedding is then no longer the warp's PL map of the
  /// input, only fold-free with the same boundary. false: the passes' result as it is.
  bool relax_unreached = true;
  /// Upper bound on the relaxation's Newton iterations (each one sparse solve over at most the 24 rings
  /// around a feature, or over the whole patch when untangling) over the whole call; when they are spent the
  /// features still short stay short. Bounds the fallback's time on large patches (the stress test's far
  /// warps use up to 10,600; docs/measurements.md).
  std::size_t relax_iterations = 20000;
  /// Called with the warp mesh (points: 4 corners (0,0),(1,0),(1,1),(0,1) then the features in `features`
  /// order; counter-clockwise triangles) after it is built, after every move, after every event flip and after
  /// the Delaunay flips that follow a move, in every pass (`reorder_passes`; a later pass lists the features in
  /// its own order). May be empty. For tests and visualization.
  std::function<void(const std::vector<Eigen::Vector2d>& points, const std::vector<std::array<int, 3>>& triangles)>
      observer;
};

struct FeatureWarpResult {
  /// Warp edge flips performed: at degeneracy events (§3.4.2) and, with `keep_delaunay`, to restore the
  /// Delaunay property after a step.
  std::size_t events = 0;
  /// Base-mesh vertex relocations done to keep base triangles from inverting (a vertex relocated by two
  /// repairs counts twice). Relocated vertices are re-bound to the warp mesh where they land.
  std::size_t repaired_vertices = 0;
  /// Moves between events and repairs, over all features.
  std::size_t steps = 0;
  /// Features routed through a waypoint because their straight path passed a warp vertex.
  std::size_t detours = 0;
  /// max_k |uv[features[k]] - targets[k]| after the warp; 0 when every feature arrived.
  double max_feature_error = 0;
  /// Smallest signed area of a warp triangle seen after any move or flip (> 0: the warp never folded).
  double min_warp_triangle_area = 0;
  /// Indices k (into `features`), ascending, of features that could not reach their target without folding
  /// the base mesh (e.g. a target that inverts a base triangle whose vertices are all features or on the
  /// boundary, or a warp that stalled); they stay at a foldover-free intermediate position.
  std::vector<int> unreached;
  /// One line per entry of `unreached`, in the same order: why that feature stopped short. Either a proof that
  /// no fold-free embedding has it at its target (a base triangle whose three vertices are all features or
  /// boundary vertices would be flipped or flat with every feature at its target; the features of it that have
  /// to move are reported and not moved), or where and why the warp gave up on it.
  std::vector<std::string> unreached_reasons;
  /// Passes run (see `FeatureWarpOptions::reorder_passes`): 1 when the first pass reached every target or
  /// every target it left unreached is provably unreachable (no order can help). The
  /// result is the best pass's; `events`, `repaired_vertices`, `steps`, `detours` and
  /// `min_warp_triangle_area` are over all passes.
  int passes = 0;
  /// Features the passes left short that the barrier relaxation or the untangling after it
  /// (`FeatureWarpOptions::relax_unreached`) brought to their targets.
  std::size_t relaxed = 0;
  /// Features that came in only by untangling (the walks left them short; see
  /// `FeatureWarpOptions::relax_unreached`), counted in `relaxed` too when the passes had left them short.
  std::size_t untangled = 0;
  /// Newton iterations the relaxation spent (at most `FeatureWarpOptions::relax_iterations`).
  std::size_t relax_iterations = 0;
  /// Base triangles with signed area <= 0 after the warp, checked with exact predicates: always 0 unless
  /// `keep_base_mesh_valid` is false.
  std::size_t flipped_triangles = 0;
};

/// Warps the embedding `uv` so that uv[features[k]] = targets[k] exactly, for every k (§3.4.2).
///
/// A warp mesh is the 2D Delaunay triangulation of the square's 4 corners and the features' current uv;
/// every other interior vertex is bound to its enclosing warp triangle by barycentric coordinates. Features
/// move one at a time along straight lines toward their targets; before an event (an incident warp triangle
/// about to degenerate) the edge opposite the vertex that becomes the middle of the collinear triple is
/// flipped and the points of the two triangles are re-bound. Non-feature vertices follow their barycentric
/// coordinates, so the warp is a piecewise-linear homeomorphism of the square: corners and boundary vertices
/// do not move (bit-identical) and points outside the warp triangles incident to a moving feature do not move.
/// Steps are short and followed by Delaunay flips (`keep_delaunay`), so the kinks of the PL map move with
/// the feature. Because a PL map of the vertices alone can still invert a straight-edged base triangle (every
/// point moves linearly during a step, so each base triangle's area is linear in time and its inversion time
/// is known exactly), every step stops before a base triangle would invert and relaxes the free vertices
/// around it inside the kernels of their stars (`repaired_vertices`); every relocation is checked with exact
/// predicates. The base mesh therefore has no flipped triangle afterwards. Points outside the warp triangles
/// incident to a moving feature move only when repaired (they are then within a few rings of a moving one).
/// A pass that leaves targets unreached is followed by passes in other orders from the input uv
/// (`FeatureWarpOptions::reorder_passes`); `uv` and the result are those of the pass with the fewest unreached
/// features, and the features it left short then walk on with a barrier relaxation, or are placed on their
/// targets and the rest untangled (`FeatureWarpOptions::relax_unreached`; boundary vertices stay
/// bit-identical, the result is checked fold-free with exact predicates). A target may
/// still be left unreached (reported in `unreached`, never folded); how often that happens for near and far
/// targets is in docs/measurements.md.
///
/// \param triangles  #F base-mesh triangles, 0-based indices into `uv`, counter-clockwise (positive area).
/// \param uv         #V positions in [0,1]²: corners at the square's corners, boundary vertices with a
///                   coordinate exactly 0 or 1, other vertices strictly inside; no triangle of area <= 0.
///                   Modified in place.
/// \param features   indices into `uv` of interior vertices, pairwise distinct.
/// \param targets    one target per feature, strictly inside the square (farther than
///                   `collision_distance` from the sides) and pairwise farther apart than that.
/// \throw InvalidInput when a precondition does not hold (nothing is modified then).
/// \throw SolverFailure when, with `keep_base_mesh_valid`, the result would contain a flipped triangle (a bug).
/// A target that cannot be reached without a fold is not an error: see `FeatureWarpResult::unreached`.
FeatureWarpResult warp_features(const std::vector<std::array<int, 3>>& triangles, std::vector<Eigen::Vector2d>& uv,
                                const std::vector<int>& features, const std::vector<Eigen::Vector2d>& targets,
                                const FeatureWarpOptions& options = {});

/// The targets of feature alignment (§3.4.1): f_k = (1/m) Σ_i f_k^i, the average over the m models of the
/// uv of corresponding feature k. `feature_uv_per_model[i][k]` is feature k's uv on model i.
/// \throw InvalidInput when there is no model or the models have different feature counts.
std::vector<Eigen::Vector2d> average_feature_targets(
    const std::vector<std::vector<Eigen::Vector2d>>& feature_uv_per_model);

/// The initial warp mesh of §3.4.2: the Delaunay triangulation (counter-clockwise triangles) of the points
/// (0,0),(1,0),(1,1),(0,1), feature_uv[0], feature_uv[1], ... (indices in that order). Exposed for tests
/// and visualization. \throw InvalidInput when a feature is not strictly inside the square or two coincide.
std::vector<std::array<int, 3>> feature_warp_triangulation(const std::vector<Eigen::Vector2d>& feature_uv);

}  // namespace geomip
