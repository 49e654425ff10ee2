// The models of `geomip param|gimage|remesh MESH... [--points CORR.json]`: meshes read, repaired when open or
// non-manifold (with a note on stderr), partition points resolved from CORR.json or chosen automatically —
// ready for parameterize_consistently(). One function so the three commands parameterize identically.
#pragma once

#include "mesh/mesh_repair.h"
#include "param/consistent_parameterization.h"
#include "param/partition_points.h"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace geomip::tools {

struct PreparedModels {
  std::vector<ParameterizationInput> inputs;  ///< name = the mesh file's stem
  std::vector<std::string> paths;             ///< the mesh files, as given or as named in CORR.json
  /// Per model: the mesh as read when it had to be repaired (holes filled, ...), else empty. Commands that
  /// must give back what the user had (the hole mask of a pack) compare against it.
  std::vector<TriMesh> originals;
};

/// The automatic two-square loop of a genus-0 mesh (no CORR.json): the plane section (kPlain), the same
/// outline rerouted down every protrusion to its tip and back (kTips: `--tip-loop`), or a loop through the
/// shape's ends (kEnds: `--end-loop`): tips found with a looser tube test (nose and tail besides the legs)
/// and joined through 4 outline guides instead of 16, with sliding seams (ends_loop_options()).
enum class LoopKind { kPlain, kTips, kEnds };

/// PartitionPointsOptions for a loop kind (tip_loop off for kPlain).
PartitionPointsOptions loop_options(LoopKind kind);

/// Sliding-seam rounds (ParameterizationOptions::seam_slide_rounds) a loop kind gets when `--slide-seams`
/// is not given: 10 for kEnds (measured on the horse: docs/measurements.md, "A loop through the ends"), 0
/// otherwise.
int default_seam_slide_rounds(LoopKind kind);

/// The options every model-consuming command shares: MESH..., --points, -o, --json, --quiet.
struct ModelArgs {
  std::vector<std::string> meshes;
  std::string points;
  std::string output;
  bool json = false;
  bool quiet = false;
  /// Curvature sampling exponent γ (SamplingWeightOptions::exponent); 0 = uniform geometric stretch.
  double sampling_exponent = SamplingWeightOptions{}.exponent;
  /// λ of the anisotropic curvature metric (ParameterizationOptions::curvature_metric); 0 = Euclidean.
  /// 0.03 on every command (ConvertOptions::curvature_metric's default too): the codec's prefixes and the
  /// uniform remeshes both gain (docs/measurements.md, "An anisotropic curvature metric for the stretch").
  double curvature_metric = 0.03;
  /// --linf-sweeps N: ParameterizationOptions::linf_sweeps (0 = no L∞ pass).
  int linf_sweeps = 0;
  /// --patches K: patches of the automatic layout. 2 = the two-square partition (choose_partition_points();
  /// genus 1: the 2×2 periodic grid; genus ≥ 2, which has neither: the first K-quad layout, K = 2g+2, 4g, 6g,
  /// 8g, 12g, … that partitions the mesh); another K = a K-quad layout (choose_quad_layout()). Only without
  /// CORR.json.
  int patches = 2;
  /// --patches was on the command line: the user chose the layout (`convert` and `rd` move a stretched shape
  /// to 16 patches only without it: kStretchedTwoSquares).
  bool patches_given = false;
  /// --equal-area-layout: the K-quad layout's coarse mesh by equal area (QuadLayoutOptions::error_weight 0)
  /// instead of equal error.
  bool equal_area_layout = false;
  /// --layout-error-weights: QuadLayoutOptions::error_weight_factors of an automatic K-quad layout.
  std::vector<double> layout_error_weights = {1.0};
  /// --layout-error-weights was on the command line (`convert` and `rd` then try only those weights when
  /// they move a stretched shape; else one weight and kLayoutErrorWeightSets' others).
  bool layout_error_weights_given = false;
  /// --tip-loop: PartitionPointsOptions::tip_loop for automatic two-square points (genus 0, no CORR.json).
  bool tip_loop = false;
  /// --end-loop: LoopKind::kEnds (not with --tip-loop).
  bool end_loop = false;
  /// --slide-seams N: ParameterizationOptions::seam_slide_rounds; -1 = default_seam_slide_rounds() of the loop.
  int slide_seams = -1;
};

/// The loop kind `--tip-loop` / `--end-loop` ask for. \throw InvalidInput when both are given.
LoopKind loop_kind(bool tip_loop, bool end_loop);
inline LoopKind loop_kind(const ModelArgs& args) { return loop_kind(args.tip_loop, args.end_loop); }

/// \throw InvalidInput (naming the flag) when `loop` is not kPlain and `patches` ≠ 2: the loops are of the
/// two-square partition.
void check_loop_patches(LoopKind loop, int patches);

/// Sets the parameterization's curvature sampling from `--sampling-exponent`, its L∞ pass from
/// `--linf-sweeps` and its sliding seams from `--slide-seams` (or the loop kind's default).
void apply_sampling(const ModelArgs& args, ParameterizationOptions& options);

/// Registers ModelArgs' options on `cmd` (same names and help in every command).
void add_model_options(CLI::App* cmd, ModelArgs& args);

/// repair_mesh(), its refusals (every face degenerate, no triangles, ...) said of `path`.
RepairResult repair_named(const std::string& path, const TriMesh& input, const RepairOptions& options = {});

/// CLI::Range for a floating-point option that also refuses NaN and infinities (every comparison with NaN is
/// false, so CLI::Range lets it through and the option silently acted as its default).
CLI::Validator finite_range(double lo, double hi);

/// `meshes`: one mesh (automatic partition points) or none when `points_file` names them. `command` prefixes
/// the repair note ("geomip param"); `quiet` silences it. `patches`: see ModelArgs::patches.
/// \throw InvalidInput when both or neither are given, several meshes come without CORR.json, a file is
///   unreadable, a point is out of range, `patches` < 2, `patches` ≠ 2 comes with CORR.json, or no K-quad
///   layout fits the mesh (choose_quad_layout()), or `loop` is not kPlain with CORR.json or `patches` ≠ 2.
/// `loop`: the automatically chosen two-square loop (LoopKind). `equal_area_layout`, `error_weights`: see
/// ModelArgs::equal_area_layout, ModelArgs::layout_error_weights (\throw InvalidInput when empty, longer than
/// kMaxLayoutErrorWeights or not all finite and > 0).
PreparedModels prepare_models(const std::vector<std::string>& meshes, const std::string& points_file,
                              const std::string& command, bool quiet, int patches = 2,
                              LoopKind loop = LoopKind::kPlain, bool equal_area_layout = false,
                              const std::vector<double>& error_weights = {1.0});

/// At most this many --layout-error-weights (each simplifies the mesh once more).
inline constexpr std::size_t kMaxLayoutErrorWeights = 8;

/// Registers `--patches K`, `--equal-area-layout` and `--layout-error-weights` on `cmd` (same names and help
/// in every command); `given` is set when --patches is on the command line, `weights_given` when
/// --layout-error-weights is.
void add_patches_option(CLI::App* cmd, int& patches, bool& given, bool& equal_area_layout,
                        std::vector<double>& error_weights, bool& weights_given);

}  // namespace geomip::tools
