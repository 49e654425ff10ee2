// Automatic quad layouts for one model (issue 15, item 3): a coarse triangle mesh made of the mesh's own
// vertices, its triangles paired into quads. The result feeds partition_mesh_layout() (one patch per quad,
// each patch one (2^n+1)² geometry image). Like choose_partition_points(), for one model on its own: layouts
// of different models chosen this way do not correspond.
#pragma once

#include "mesh/mesh.h"
#include "param/mesh_partition.h"

#include <cstddef>
#include <vector>

namespace geomip {

/// What the choice of a layout minimizes (both computed from partition_stats()).
enum class LayoutObjective {
  kAreaSpread,    ///< Σ (A_q / Ā)² / K: equal patch areas
  kSamplingCost,  ///< K · Σ A_q² / (flatness_q · A²): equal areas and patches close to height fields
};

struct QuadLayoutOptions {
  /// K, the number of quads (patches), ≥ 2. The coarse mesh has 2K triangles and K + 2 − 2·genus vertices.
  int patches = 8;
  /// At most this many steps that move the corners to even out the patch areas (0: none); each step costs
  /// one partition_mesh_layout().
  int balance_steps = 40;
  LayoutObjective objective = LayoutObjective::kSamplingCost;
  /// Protrusion tips: maxima of the geodesic distance from the middle of the surface whose persistence is at
  /// least this fraction of the largest distance are offered as corners (layouts with them pinned compete
  /// with layouts without, by the objective); 0 (default): no tips. Off by default because on the horse
  /// the pinned-tip layout wins on the objective but loses remesh PSNR (docs/measurements.md).
  double tip_persistence = 0.0;
  /// For measurements: only the candidates with the tips pinned (when tips are found).
  bool only_pinned_tips = false;
  /// Patch shape (issue 15, L∞ stretch per patch): the objective gets `shape_weight` times Σ over the
  /// patches of Σ_corners (max(0, corner angle − max_corner_angle_deg) / 90°)² + Σ_sides max(0, side length /
  /// sqrt(patch area) − max_side_ratio)² + (max(0, min_flatness − flatness) / 0.25)², where a corner angle is
  /// the 3D angle sum of the patch's triangles at that corner (the square has 90° there) and a side length
  /// the 3D length of its path. A side of length L bounds the patch's L∞ stretch from below by L / sqrt(A)
  /// whatever the map (the side lies on a unit edge of the square); a corner far above 90° squeezes the
  /// surface around it into the square's wedge; a patch of low flatness (PatchStats::flatness) wraps around
  /// a limb and cannot be mapped to the square without stretch. 0 (default): the objective alone, the
  /// layouts as without this term. Off by default: on the horse, bunny, armadillo and cow it moved the
  /// worst patch's L∞ stretch both ways and lowered the remesh PSNR on most of them (docs/measurements.md,
  /// "L∞ stretch per patch: layouts").
  double shape_weight = 0.0;
  double max_corner_angle_deg = 150.0;
  double max_side_ratio = 2.5;
  double min_flatness = 0.5;
  /// At most this many partitions tried by the shape moves after the balancing (each moves one corner of
  /// the worst-shaped patches; a move is kept only when the objective drops). 0: none.
  int shape_steps = 120;
  /// How the simplification (step 1 below) picks its collapses. > 0: by equal error, the collapse of the
  /// lowest error_weight · E / (A · D²) + (a / A)² first, E the quadric error of the merged vertex
  /// (Garland–Heckbert 1997: the area-weighted squared distances from it to the planes of the mesh triangles
  /// it stands for), a the area it stands for, A the mesh's area and D its bounding-box diagonal; so the
  /// coarse vertices, hence the patches, crowd where the surface bends (legs, ears, fingers) and every patch,
  /// which gets the same grid, holds a similar share of the detail. 0: by equal area (the layouts before
  /// 2026-12-04, thirteenth session). Measured on pack prefixes (docs/measurements.md, "Equal-error quad
  /// layouts"): see there for the figures behind the default.
  double error_weight = 1000.0;
  /// Equal error: the mesh is simplified once with each of these multiples of error_weight (those ≤ 0
  /// skipped), and every pairing of every coarse mesh competes by the objective. One weight (the default)
  /// is fragile: the horse with every coordinate moved by up to 1e-7 of itself got a layout of sampling cost
  /// 2.12 instead of 1.70 and prefixes 3.3–6.5 dB lower. Five ({1, 0.5, 2, 0.25, 4}) raised the means of
  /// three such copies' prefixes by 1.6–2.6 dB (horse) and 0.3–0.6 dB (armadillo) but lowered the cow's by
  /// 0.8–3.3 dB (one copy's layout of lowest sampling cost coded 9 dB worse at 32 KB): the objective does not
  /// predict the codec well enough to choose among more candidates (docs/measurements.md, "How much a prefix
  /// moves when the input moves by 1e-7"). So `convert` and `rd` build a stretched shape's layouts with one
  /// weight and with five and keep the one whose prefixes measure better (tools/convert_pipeline.h,
  /// kStretchedLayoutErrorWeights; `--layout-error-weights` sets these factors).
  std::vector<double> error_weight_factors = {1.0};
  /// Equal error from this many patches up; fewer are simplified by equal area whatever error_weight says.
  /// With so few coarse vertices the equal-error ones go to the tips (hooves, ears, nose) and the patches
  /// run along the limbs: the horse's 8-patch equal-error layout measured 4.7 dB below its equal-area one.
  int min_error_patches = 16;
};

/// What choose_quad_layout() measured on the layout it returns.
struct QuadLayoutChoice {
  QuadLayout layout;
  double area_balance = 0.0;   ///< smallest / largest patch area of its partition (PartitionStats)
  /// Σ (A_q / Ā)² / K over its patch areas A_q (Ā their mean): 1 when all are equal. With the same grid on
  /// every patch a patch's squared resampling error grows like A_q², so this is what the choice lowers.
  double area_spread = 0.0;
  /// K · Σ A_q² / (flatness_q · A²) (A the total area; PatchStats::flatness): relative to K equal flat
  /// squares (1), an estimate of the layout's squared resampling error at a fixed sample count.
  double sampling_cost = 0.0;
  int balance_steps = 0;       ///< corner moves kept by the balancing
  int shape_steps = 0;         ///< corner moves kept by the shape moves
  /// The largest corner angle (degrees) and side length / sqrt(area) over the patches of its partition, and
  /// its shape penalty (QuadLayoutOptions::shape_weight's sum, with the options' bounds; 0: all within).
  double max_corner_angle_deg = 0.0;
  double max_side_ratio = 0.0;
  double shape_penalty = 0.0;
  std::vector<int> tips;       ///< protrusion tips found (vertex ids; pinned in some candidates)
  bool tips_pinned = false;    ///< the layout returned is one with the tips pinned
  std::size_t candidates = 0;  ///< pairings tried that partition the mesh
};

/// Chooses a K-quad layout for `closed_manifold` (same preconditions as partition_mesh_layout()):
/// 1. simplify the mesh by half-edge collapses to K + 2 − 2g vertices (g the genus): by equal error (see
///    QuadLayoutOptions::error_weight) or, with error_weight 0, the pair of vertices that stands for the
///    least surface area first (each vertex starts with a third of its star's area and inherits the area of
///    the vertices merged into it): greedy clustering into equal areas, so the coarse triangles, hence the
///    patches, get similar areas (every patch gets the same grid); by equal area also when no pairing of the
///    equal-error coarse mesh partitions the mesh. A collapse keeps the
///    surviving vertex where it is (so the coarse vertices are mesh vertices), respects the link condition
///    (the coarse mesh stays a closed manifold of the same genus) and, while it can, never turns a
///    triangle's normal by 90° or more;
/// 2. pair the 2K coarse triangles into K quads: a perfect matching of the dual graph, which is cubic and
///    bridgeless on a closed triangle mesh, so one exists (Petersen 1891). A greedy matching by one of three
///    scores (flattest pairs, pairs closest to the mean quad area, pairs across the longest edge) is
///    completed by augmenting paths with blossom contraction (Edmonds 1965);
/// 3. every pairing that partition_mesh_layout() accepts is measured and the one with the lowest objective
///    (QuadLayoutOptions::objective; PartitionStats) is kept;
/// 4. its corners are moved to lower the objective (at most `balance_steps` partitions tried): each corner
///    steps towards the area centroids of its larger neighbouring patches and away from its smaller ones,
///    landing on a mesh vertex that is not another corner; a move is kept only when the layout still
///    partitions the mesh and the objective drops, so it never makes the layout worse.
/// 5. with `shape_weight` > 0 the objective includes the shape penalty (see QuadLayoutOptions) in steps 3
///    and 4, and then the corners with the largest share of it are moved (at most `shape_steps` partitions
///    tried): each towards or away from one of its patches' area centroids or along one of its sides,
///    kept only when the objective drops.
/// Deterministic: no randomness, no threads; the same mesh and options give the same layout.
/// With `tip_persistence` > 0 the steps run twice, without and with the protrusion tips pinned as coarse
/// vertices (never collapsed, never moved), and the layout with the lower objective is returned.
/// Cost: O(F log F) for the simplification plus one partition per pairing, per balancing step and per shape
/// move tried.
///
/// \throw InvalidInput with "choose_quad_layout:" when the mesh is not one closed, manifold, oriented
///   component, K < 2, K + 2 − 2g < 4 (K too small for the genus), K + 2 − 2g exceeds the mesh's vertices
///   (K larger than the mesh can hold), the simplification gets stuck above K + 2 − 2g vertices, or no
///   pairing partitions the mesh.
QuadLayoutChoice choose_quad_layout(const TriMesh& closed_manifold, const QuadLayoutOptions& options = {});

}  // namespace geomip
