// Consistent parameterization of one or several meshes over a common quad-patch base domain: the whole of
// §3 of ../shared/seed/consistent-mesh-parameterizations.txt, wired from its steps:
//   partition (mesh_partition.h) → per patch progressive mesh (progressive_mesh.h) → mean-value embedding of
//   the base mesh (mean_value_embedding.h) → stretch optimization (stretch_optimization.h) → feature
//   alignment across models (feature_warp.h) → coarse-to-fine vertex insertion with local stretch
//   optimization (coarse_to_fine.h) → a few global stretch sweeps → optionally an L∞ pass.
#pragma once

#include "mesh/mesh.h"
#include "param/mean_value_embedding.h"
#include "param/mesh_partition.h"
#include "param/progressive_mesh.h"
#include "param/sampling_weights.h"
#include "param/stretch.h"
#include "param/stretch_optimization.h"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace geomip {

/// One model to parameterize.
struct ParameterizationInput {
  TriMesh mesh;  ///< closed, manifold, consistently oriented, one component
  /// Without `layout_quads`: 4 vertex ids, in loop order; corresponding across models. With it: the quad
  /// layout's corners (any number; QuadLayout::corners), corresponding across models.
  std::vector<int> partition_points;
  std::vector<int> auxiliary_points;  ///< genus 0: none or 4 path guides; genus 1: 8 (see partition_mesh())
  /// Genus 0 instead of auxiliary_points: any number of guides per path, one list per path
  /// (partition_mesh_guided(); what choose_partition_points() gives for a loop through the tips).
  std::vector<std::vector<int>> side_guides;
  /// A quad layout over `partition_points` (QuadLayout::quads; partition_mesh_layout()): one patch per quad,
  /// any genus; the same quads in every model; auxiliary_points must then be empty. Empty = partition_mesh().
  std::vector<std::array<int, 4>> layout_quads;
  std::vector<int> features;  ///< feature vertex ids; same count and order in every model
  std::string name;           ///< for messages
};

/// Defaults of ParameterizationOptions::base_optimization: threshold 10⁻⁴ and up to 200 sweeps (instead of
/// StretchOptimizationOptions' 10⁻³ / 50). The base mesh (~100 vertices) is cheap to converge, and its layout
/// decides how much of the square the protrusions (bunny ears) get; chosen with
/// default_local_optimization() by measured remesh PSNR (README, "Tuning the parameterization"). The
/// threshold also stops the level and final sweeps, whose counts are level_sweeps / final_sweeps.
inline StretchOptimizationOptions default_base_optimization() {
  StretchOptimizationOptions o;
  o.threshold = 1e-4;
  o.max_sweeps = 200;
  return o;
}

/// Defaults of ParameterizationOptions::local_optimization: the blended energy, half L2 and half L∞
/// (w = 0.5), instead of plain L2. Penalizing each ring's largest stretch spreads samples onto the
/// undersampled ears. It pays only together with default_base_optimization() (README, "Tuning the
/// parameterization", has the figures).
inline VertexOptimizationOptions default_local_optimization() {
  VertexOptimizationOptions o;
  o.norm = StretchNorm::kBlend;
  o.linf_weight = 0.5;
  return o;
}

struct ParameterizationOptions {
  ProgressiveMeshOptions progressive_mesh;
  /// Stretch optimization of each base mesh's MVC embedding (boundary locked, features free); its
  /// threshold also ends the level and final sweeps. See default_base_optimization().
  StretchOptimizationOptions base_optimization = default_base_optimization();
  /// Local optimization of each inserted vertex and its neighbours during coarse-to-fine. See
  /// default_local_optimization().
  VertexOptimizationOptions local_optimization = default_local_optimization();
  /// optimize_vertex() calls per vertex and per insertion (each does `local_optimization.num_directions`
  /// line searches).
  int local_rounds = 4;
  /// Global stretch sweeps over the current level each time coarse-to-fine has grown it by `level_growth`
  /// (Sander et al. 2002's hierarchical optimization); 0 = only the paper's local moves.
  std::size_t level_sweeps = 5;
  double level_growth = 2.0;
  /// Global sweeps over each full patch after coarse-to-fine (boundary and features locked); 0 = none.
  std::size_t final_sweeps = 10;
  /// L∞ pass: after the final sweeps (and the MVC fallback), up to this many StretchNorm::kLinf sweeps over
  /// each patch (boundary and features locked). Each sweep moves only the vertices whose ring holds a
  /// triangle with normalized L∞ stretch (stretch.h) >= max(`linf_floor`, `linf_relative_floor` · the
  /// patch's L∞ stretch before the sweep) (StretchOptimizationOptions::min_local_stretch), so the pass works
  /// on the worst regions and leaves the rest as it is; it stops after a sweep that moved nothing. Each move
  /// lowers the largest Γ of its ring, so the pass never raises a patch's L∞ stretch and never folds a
  /// triangle; it raises the L2 stretch of the patches it works on. Deterministic (seeds per patch and
  /// sweep), hence bit-identical for any thread count. 0 = off (the default: it costs remesh PSNR;
  /// docs/measurements.md, "L∞ stretch per patch").
  std::size_t linf_sweeps = 0;
  /// See `linf_sweeps`: normalized L∞ stretch below which a ring is never moved. Finite, >= 0.
  double linf_floor = 2.0;
  /// See `linf_sweeps`: fraction of the patch's current L∞ stretch below which a ring is not moved. In [0, 1].
  double linf_relative_floor = 0.85;
  /// Sliding seams: rounds of moving every seam vertex along its side to where the stretch of its triangles
  /// in both patches is least, each followed by `seam_slide_sweeps` global sweeps over every patch (boundary
  /// and features locked). Frees the sides from their chord-length parameterization; 0 = off.
  int seam_slide_rounds = 0;
  std::size_t seam_slide_sweeps = 10;
  int seam_slide_iterations = 12;  ///< golden-section steps per seam vertex and round
  /// Also compute the mean-value embedding of each full patch, the baseline the stretch figures are
  /// reported against (one sparse solve per patch).
  bool measure_mvc_baseline = true;
  /// Signal-specialized sampling: weight every stretch optimization's L2 term by curvature_sampling_weights()
  /// of the patch (more parameter area, hence more geometry-image samples, where the surface bends). Off =
  /// Sander 2001's uniform geometric stretch.
  bool curvature_sampling = true;
  SamplingWeightOptions sampling_weights;
  /// Anisotropic, curvature-adapted stretch: λ of curvature_metric_tensors(), computed once per model on the
  /// partitioned mesh (so both patches of a seam see the same tensors), measures every stretch
  /// optimization's triangles in M = I + λ·D·|S| (VertexOptimizationOptions::vertex_metrics): a direction
  /// in which the surface bends gets more parameter length, hence more samples, than one along which it
  /// is straight (around a leg rather than along it); the sides' chord lengths are measured in it too
  /// (square_boundary_uv(), CoarseToFineOptions::side_metrics). 0 = the Euclidean metric (Sander 2001). The
  /// figures a parameterization reports (PatchParameterization::stretch) stay Euclidean, and so does the L∞
  /// pass (`linf_sweeps`: it lowers the reported L∞); the MVC fallback of a feature-free patch and sliding
  /// seams compare by the metric's L2 energy. (The two squares' L2 stretch that moves a shape to 16 patches
  /// in `geomip convert` is the reported, Euclidean one.)
  double curvature_metric = 0;
  /// Seed of the random search directions (results are deterministic for a given seed).
  unsigned seed = 1;
  /// Threads over the patches of a model (progressive meshes and base embeddings, then coarse-to-fine, final
  /// sweeps and MVC baseline); 0 = one per hardware thread. Patches are independent, so the result is
  /// bit-identical for every thread count, and so is a failure: the exception thrown is the one a
  /// `threads = 1` run throws (the lowest failing patch's).
  unsigned threads = 0;
  /// Called from one thread at a time (possibly a worker thread, not the caller's). An exception it throws
  /// fails the patch it reports on; patches already running finish before it reaches the caller.
  ProgressCallback progress;
};

/// One patch's parameterization, in the unit square.
struct PatchParameterization {
  std::vector<int> vertices;                  ///< local id → vertex id in ModelParameterization::mesh
  std::vector<std::array<int, 3>> triangles;  ///< local ids, counter-clockwise in uv and on the surface
  std::vector<Eigen::Vector2d> uv;            ///< per local vertex, in [0,1]²
  std::array<int, 4> corners{};               ///< mesh vertex ids at (0,0), (1,0), (1,1), (0,1)
  std::array<std::vector<int>, 4> sides;      ///< mesh vertex ids, side k from corner k to corner k+1
  std::size_t base_vertices = 0;              ///< vertices of the progressive mesh's base mesh
  StretchValues mvc_stretch;                  ///< of the full patch's MVC embedding (if measured)
  StretchValues stretch;                      ///< of the final parameterization (after the seams are reconciled)
  std::size_t flipped = 0;                    ///< triangles with uv area <= 0 in the final result (0)
  std::size_t boundary_off_chord = 0;         ///< boundary vertices not at their chord-length position
  /// True when coarse-to-fine ended above the MVC embedding's stretch and the stretch-optimized MVC
  /// embedding was used instead (patches without features only).
  bool mvc_fallback = false;
};

/// Where a feature ended.
struct FeatureLocation {
  int vertex = -1;
  int patch = -1;
  Eigen::Vector2d uv{0, 0};
};

/// Seconds spent in each stage (summed over the patches of the model, so with several threads a stage's
/// figure can exceed its wall-clock time; the warp is shared by all models and counted in each).
struct StageSeconds {
  double partition = 0, progressive_mesh = 0, base_embedding = 0, feature_warp = 0, coarse_to_fine = 0,
         final_optimization = 0, mvc_baseline = 0;
};

struct ModelParameterization {
  TriMesh mesh;  ///< the input mesh with partition split vertices appended (originals keep ids)
  std::vector<PatchParameterization> patches;
  std::vector<SideLink> adjacency;  ///< from partition_mesh(): adjacency[4·p + s] is side s of patch p
  std::vector<FeatureLocation> features;
  std::size_t split_vertices = 0;
  std::size_t warp_events = 0;  ///< Delaunay flips of the feature warp, over this model's patches
  /// Seam vertices whose position along the side differs between the two patches (0 unless a boundary
  /// vertex could be placed at the same position in neither patch).
  std::size_t seam_mismatches = 0;
  StageSeconds seconds;
};

/// Parameterizes `models` consistently: corresponding patches over the same unit squares, corresponding
/// features at identical (u,v). One model is a plain (non-consistent) parameterization.
///
/// \throw InvalidInput when the models disagree (genus, feature counts, layout quads), a point is invalid
/// (see
///   partition_mesh()), a feature lies on the partition cut, corresponding features fall in different
///   patches, or a mesh is not closed and manifold.
/// \throw SolverFailure when a stage breaks its guarantees (a bug: never the input's fault).
std::vector<ModelParameterization> parameterize_consistently(const std::vector<ParameterizationInput>& models,
                                                             const ParameterizationOptions& options = {});

}  // namespace geomip
