// The convert pipeline shared by `geomip convert` and `geomip rd`: prepared (repaired) models → consistent
// parameterization → geometry images (+ normal maps, + hole masks of repaired meshes) → a .gip pack in memory.
#pragma once

#include "codec/normal_mesh.h"
#include "codec/pack.h"
#include "gimage/surface_distance.h"
#include "mesh/mesh.h"
#include "mesh/view_frame.h"
#include "tools/model_inputs.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace geomip::tools {

/// Normal-mesh steps of a one-model pack by default: the codec's framed steps (GeometryCodecOptions::
/// frame_steps), where tangential components cost less; more steps lose (docs/codec-v3.md, "Normal-mesh
/// resampling").
constexpr int kAutoNormalMeshSteps = 3;

/// The grid level `geomip convert` and `geomip rd` use without --level: 8 (257² samples per patch) for two
/// squares and a torus's four, and for a K-patch layout the coarsest level whose K grids hold at least as
/// many samples as two squares at level 8 (K = 8: 7, 16: 7, 32: 6, 64: 6, 128: 5; at least 3, the default
/// framed steps), so that a layout changes where the samples are rather than multiplying them (a 64-quad
/// layout at level 8 holds 32 times as many) and never lowers the resolution a pack can reach (the four
/// animals' 64-quad layout at level 5, half the samples, ends 2–6 dB lower at 32 KB per model:
/// docs/measurements.md, "The level of a K-patch layout").
int default_grid_level(std::size_t patches);

struct ConvertOptions {
  int level = 8;              ///< geometry image level N: (2^N+1)² samples per patch
  int normal_level = -1;      ///< normal map level (-1: N+1, at most 10)
  bool normals = true;        ///< false: geometry-only pack
  int quantization_bits = 14; ///< position quantization over the largest bounding-box extent
  /// The coarse bands' extra bits (codec::GeometryCodecOptions::headroom_bits; 4 by default, 0 without cell
  /// frames).
  int headroom_bits = codec::GeometryCodecOptions{}.headroom_bits;
  /// Normal-map quantization bits over the largest extent of the normals' components
  /// (codec::PackWriteOptions:: normal_codec; 10 by default). Each bit fewer costs about 0.8× the normal
  /// bytes of a whole pack and raises its shading error (docs/codec-v3.md, "Shading error" and "Normal maps
  /// of a shape moved to 16 patches"); a streamed prefix is hardly affected (the bottom planes come last).
  int normal_bits = codec::PackWriteOptions{}.normal_codec.quantization_bits;
  /// The normal maps' headroom (codec::PackWriteOptions::normal_codec; 4 by default, as the geometry's):
  /// every streamed prefix of the normal maps closer, the whole stream a little smaller and a little less
  /// exact than 0's (10 bits lossless).
  int normal_headroom_bits = codec::PackWriteOptions{}.normal_codec.headroom_bits;
  int normal_layers = codec::PackWriteOptions{}.normal_layers;  ///< 1 or 2 (codec::PackWriteOptions)
  /// Codec tools of the geometry stream (codec::GeometryCodecOptions: local frames of the finest
  /// frame_steps wavelet steps, their tangential components 2^tangential_shift coarser, orientation
  /// weights, the wavelet's lifting update). The defaults are the codec's; the switches exist for ablations
  /// (docs/codec-v3.md).
  int frame_steps = codec::GeometryCodecOptions{}.frame_steps;
  int tangential_shift = codec::GeometryCodecOptions{}.tangential_shift;
  bool orientation_weights = codec::GeometryCodecOptions{}.orientation_weights;
  bool lifting_update = codec::GeometryCodecOptions{}.lifting_update;
  bool cell_frames = codec::GeometryCodecOptions{}.cell_frames;
  /// The geometry's wavelet filter (kCubicLong by default; kCubic for ablations); the normal-mesh
  /// resampling predicts with the same one.
  codec::WaveletFilter filter = codec::GeometryCodecOptions{}.filter;
  /// Level of the hole-mask grid (repaired meshes); -1 = the geometry's level.
  int hole_mask_level = -1;
  /// Repaired meshes: the fill samples at a hole's border move onto the original surface
  /// (snap_hole_borders(), after the normal-mesh resampling and the fit), so the decoded border ends on the
  /// hole's rim instead of hanging over the fill (with a coarser hole mask: the fill samples of the quads it
  /// keeps, on the geometry's grid). On by default (bunny, means of three jittered copies: +1.61 dB at 32 KB,
  /// +0.75 at 16 KB, the same below 8.8 KB; docs/codec-v3.md, "Hole borders on the original surface"); false
  /// for ablations.
  bool snap_hole_borders = true;
  /// Curvature sampling exponent of the parameterization (SamplingWeightOptions::exponent; 0 = off, the
  /// default here because it costs the codec at low rates; the remeshing commands default to 1/3; README,
  /// "Curvature sampling").
  double sampling_exponent = 0;
  /// λ of the parameterization's anisotropic curvature metric (ParameterizationOptions::curvature_metric;
  /// 0 = Euclidean stretch). 0.03 by default here: +0.20…+0.53 dB on the mean prefix PSNR of the bunny, the
  /// horse, venus and the armadillo (docs/measurements.md, "An anisotropic curvature metric"); the
  /// remeshing commands use the same default (ModelArgs::curvature_metric).
  double curvature_metric = 0.03;
  /// Sweeps of the parameterization's L∞ pass (ParameterizationOptions::linf_sweeps; 0 = off).
  std::size_t linf_sweeps = 0;
  /// Sliding-seam rounds of the parameterization (ParameterizationOptions::seam_slide_rounds; 0 = off).
  int seam_slide_rounds = 0;
  /// Normal-mesh resampling of the finest `normal_mesh_steps` wavelet steps' samples before coding
  /// (codec/normal_mesh.h; 0 = off). One model only: it moves samples off the parameterization, which the
  /// morphs of a consistent set rely on (InvalidInput when asked for with several models). -1 (default) =
  /// kAutoNormalMeshSteps for one model, off for several.
  int normal_mesh_steps = -1;
  /// Largest move of a normal-mesh sample, in local sample spacings (NormalMeshOptions::max_shift).
  double normal_mesh_max_shift = 0.5;
  /// Normal-mesh steps from this one up refuse moves that fold their grid
  /// (NormalMeshOptions::fold_guard_from_step; 0 = none).
  int normal_mesh_fold_guard = codec::NormalMeshOptions{}.fold_guard_from_step;
  /// Least-squares fitted samples (gimage/fit.h), after the normal-mesh resampling: the level-N remesh fits
  /// the surface (the mesh before repair, the hole mask's quads left out) instead of interpolating it. Any
  /// number of models (offsets along the normals keep the correspondences). `geomip convert` and `geomip rd`
  /// turn it on by default where fit_by_default() says so.
  bool fit = false;
  /// The viewer's frame stored as each model's normalization (codec::PackModelInfo::normalization): the up
  /// axis (kAuto: from the first model's shape) and front of the first model (upright_rotation()), one
  /// rotation for every model of the pack alike (a consistent set keeps one pose), then each model's rotated
  /// box to the centred unit box (view_normalization()); a rotation that is the identity is not stored (the
  /// viewer's default frame). nullopt: identity (no frame; the viewer fits the decoded box, y up) — 129
  /// manifest bytes per model fewer, as `geomip rd` measures.
  std::optional<UpAxis> up;
  /// The front with `up` (upright_rotation()'s `front`): a signed unit axis of the first model's units, or
  /// zero (default) for the shape's rule.
  Eigen::Vector3d front = Eigen::Vector3d::Zero();
  ProgressCallback progress;  ///< stages "parameterize …", "resample", "encode" (and "measure layouts")
  /// Threads of convert_relayout_when_stretched()'s layout choice (its candidates built side by side);
  /// 0: one per hardware thread. The packs do not depend on it.
  int threads = 0;
  /// Keep the pack's inputs (geometry images, normal maps, hole masks before coding) in
  /// ConvertResult::inputs (codec_bench --normals measures the coded normal maps against them).
  bool keep_inputs = false;
  /// > 0: when one model lands on two squares whose L2 stretch is at least this, stop after the
  /// parameterization (ConvertResult::stopped_stretched, no pack): convert_relayout_when_stretched() moves
  /// such a shape to more patches and needs nothing else from this pipeline.
  double stop_when_stretched = 0;
};

struct ConvertResult {
  std::vector<std::uint8_t> pack;
  std::vector<codec::PackModelInput> inputs;  ///< with ConvertOptions::keep_inputs, else empty
  std::vector<std::size_t> masked_quads;  ///< per model: grid quads left out as filled holes
  std::size_t snapped_samples = 0;        ///< distinct fill samples moved onto hole borders (all models)
  /// Normal-mesh resampling: the steps applied (0 = off) and figures over all patches.
  int normal_mesh_steps = 0;
  std::size_t normal_mesh_candidates = 0, normal_mesh_moved = 0, normal_mesh_would_fold = 0;
  double normal_mesh_mean_shift = 0;  ///< mean move of the moved samples, in local sample spacings
  double param_seconds = 0, resample_seconds = 0, encode_seconds = 0;
  /// One model on two squares (genus 0, the default layout): the larger L2 stretch of its two patches
  /// (param/stretch.h; 1 = no stretch). 0 for any other layout or several models.
  double two_squares_l2_stretch = 0;
  /// ConvertOptions::stop_when_stretched applied: the parameterization only, `pack` empty.
  bool stopped_stretched = false;
};

/// Whether `geomip convert` and `geomip rd` fit the samples (ConvertOptions::fit) when neither --fit nor
/// --no-fit is given: for one mesh (`model_count` 1), of any size and on any layout (a stretched shape's
/// candidate layouts are fitted before they are measured); not for consistent sets (not measured). Measured
/// (docs/codec-v3.md, "The fit by default"): since the hole borders are snapped onto the original surface,
/// the fit raises the 16 and 32 KB prefixes (means of three jittered copies: bunny +0.15 / +0.45 dB, venus
/// +0.50 / +1.06, horse +0.33 / +0.45) and moves the smaller ones by −0.02…+0.10 dB. Its cost, one
/// Gauss–Newton pass (docs/codec-v3.md, "A faster fit"): the bunny's `convert --no-normals` 2.7 → 6.1 s and
/// 88 → 486 MB, a million faces (`scripts/bench-scale`'s mesh) 43.7 → 49.4 s and 1.40 → 1.47 GB (idle 2
/// cores), so no size limit: until 2026-12-07 meshes above 500,000 faces were not fitted, when the fit took
/// four passes and an LDLT per pass.
bool fit_by_default(std::size_t model_count);

/// From this L2 stretch of a model's two squares up, `geomip convert` and `geomip rd` move the mesh to
/// more patches (kStretchedShapeLayouts) when --patches is not given (convert_relayout_when_stretched()). The
/// two squares' L2 stretch (as `convert` parameterizes) and which layout coded better (mean PSNR of the
/// 1.5–32 KB geometry prefixes; docs/measurements.md, "A note when two squares stretch the shape" and
/// "Stretched shapes move to 16 patches"): venus 1.07, max-planck 1.07, pig 1.17, camelhead 1.19, spot 1.23,
/// bunny 1.31 (two squares better by 0.8–2.6 dB); fandisk 1.22 (16 patches +0.5 dB); cow 1.74 (16 patches
/// about the same: −1.1…+1.6 dB by size); horse 1.78 (16 patches +1.0 dB), armadillo 1.97 (16 patches
/// +1.1 dB, 64 patches +2.8 dB; measured before the curvature metric).
inline constexpr double kStretchedTwoSquares = 1.5;

/// The layouts a stretched shape may move to: automatic layouts (choose_quad_layout()) of 16 and 64
/// patches, each at the level that keeps about the two squares' samples (relayout_level()). Which codes a
/// shape better depends on the shape, not on a stretch figure: on the mean PSNR of the 1.5–32 KB geometry
/// prefixes the horse and the cow code better on 16 patches (horse +0.87 dB over 64), the armadillo on 64
/// (+1.98 dB over 16, higher at every size), and the parameterizations' stretch does not tell them apart
/// (docs/measurements.md, "How many patches for a moved shape" and "16 or 64 patches, measured by convert").
/// So convert_relayout_when_stretched() converts the shape on each and keeps the one whose prefixes measure
/// closer to the mesh.
inline constexpr int kStretchedShapeLayouts[] = {16, 64};

/// The error weights (QuadLayoutOptions::error_weight_factors) each of those layouts is built with when
/// --layout-error-weights is not given: one weight, and five, whose simplifications all compete by the
/// layout's sampling cost. The sampling cost is a loose guide to the codec: measured on three copies each
/// of the horse, the armadillo and the cow (each coordinate moved by up to 1e-7 of itself), the five-weight
/// layouts coded the horse 1.6–2.6 dB and the armadillo 0.3–0.6 dB better on the mean, the cow 0.8–3.3 dB
/// worse (docs/measurements.md, "How much a prefix moves when the input moves by 1e-7"). So both are built
/// and measured, the five-weight one only where its layout differs from the one-weight layout.
inline const std::vector<std::vector<double>> kStretchedLayoutErrorWeights = {{1.0},
                                                                              {1.0, 0.5, 2.0, 0.25, 4.0}};

/// The layout choice builds its candidates side by side on at most this many faces' worth of threads
/// (kRelayoutFacesPerThread / faces threads, at least one): a conversion's peak memory grows with the faces
/// (1.75 GB for a million, docs/measurements.md), so a mesh of a million faces or more is converted one
/// layout after another, as before threads.
inline constexpr std::size_t kRelayoutFacesPerThread = 1'000'000;

/// `weights` as --layout-error-weights takes them ("1", "1,0.5,2,0.25,4").
std::string error_weights_text(const std::vector<double>& weights);

/// The prefix sizes that choice scores (issue #14's range, as `--search`'s kSearchSizes).
inline constexpr std::size_t kStretchedChoiceSizes[] = {1500, 2000, 4700, 8800, 16000, 32000};

/// The grid level of a `patches`-patch layout for two squares at `level`: about their samples, as --search
/// names its K-patch candidates (level + default_grid_level(patches) − default_grid_level(2): 16 patches one
/// level coarser, 64 two); 0 when that is below 1.
int relayout_level(int level, int patches);

/// PSNR of the geometry of `pack` decoded from each prefix in `sizes` against `reference` (the symmetric
/// RMS surface distance of `geomip eval`, measured with `distance`; the decoded grids as decoded, no
/// untangling, as `geomip rd` measures); NaN where a prefix decodes to no model. `sizes_in_parallel`: one
/// size per thread; else one size at a time on every thread (less memory: one decoded mesh and its search
/// trees at a time). The result depends on neither.
std::vector<double> prefix_psnr(const std::vector<std::uint8_t>& pack, const std::vector<std::size_t>& sizes,
                                const TriMesh& reference, const SurfaceDistanceOptions& distance = {},
                                bool sizes_in_parallel = true);

/// The choice convert_relayout_when_stretched() made, for reports: each layout considered, with the mean
/// PSNR of its geometry prefixes at `sizes` (NaN: not built — its level is below 1 or does not fit the
/// options, or no such layout fits the mesh — or the only one built, which is not measured (`sizes`
/// empty), or a prefix decoded to nothing).
struct RelayoutChoice {
  double two_squares_l2_stretch = 0;  ///< 0: the two squares did not stretch the shape (nothing tried)
  std::vector<std::size_t> sizes;
  struct Candidate {
    int patches = 0;
    std::vector<double> error_weights;  ///< its layout's QuadLayoutOptions::error_weight_factors
    int level = 0;
    double mean_psnr_db = NAN;
    std::vector<double> psnr_db;     ///< per size
    std::size_t geometry_bytes = 0;  ///< its geometry-only pack
    std::string not_built;           ///< why it was not built, or empty
  };
  std::vector<Candidate> candidates;
  int chosen_patches = 0;  ///< 0: the two squares were kept
  std::vector<double> chosen_error_weights;  ///< the error weights of the layout kept
  int chosen_level = 0;
  /// "16 patches", with " (error weights 1,0.5,2,0.25,4)" when the candidates' weights differ.
  std::string name(const Candidate& c) const;
  /// `c` is the layout kept.
  bool kept(const Candidate& c) const {
    return chosen_patches > 0 && c.patches == chosen_patches && c.error_weights == chosen_error_weights;
  }
  double seconds = 0;  ///< building and measuring the layouts (the two squares' parameterization not counted)
};

/// The distance measure of that choice: 100,000 area-uniform samples per surface and every vertex, as
/// `geomip eval --samples 100000` measures (eval's default takes 10 per face, up to 1.3 M samples on a
/// decoded level-7 grid). Its means sit 0.2–0.6 dB off the default's, but the difference between the two
/// layouts is within 0.1 dB of the default's on the horse, the cow and the armadillo (without vertex samples
/// up to 0.31 dB off: docs/measurements.md, "16 or 64 patches, measured by convert").
SurfaceDistanceOptions relayout_distance_options();

/// The mesh the viewer's frame (ConvertOptions::up, front) is guessed from: the first model as read when it
/// was repaired (a filled hole — the camel head's neck cut faired into a dome — would hide the cut that tells
/// a neck from a crown), else the first model. Requires !models.inputs.empty().
const TriMesh& view_frame_mesh(const PreparedModels& models);

/// Bytes of top bit-planes coded by one coder for all `patches` patches of a model before each patch gets its
/// own (codec::GeometryCodecOptions::joint_bytes): 1 KiB per patch, so two squares keep the codec's 2 KiB and
/// a K-patch layout's per-patch streams start about as far into the stream per patch. Each per-patch coder
/// learns its contexts from nothing and costs a segment size per plane; on the 32-patch equal-error layouts
/// the longer joint part measured +0.2…+0.3 dB from 4.7 to 16 KB (horse, armadillo; docs/measurements.md,
/// "Equal-error quad layouts"), at the price of decoding those bytes on one thread.
std::size_t geometry_joint_bytes(std::size_t patches);

/// The options convert_models() encodes its pack of `patches` patches per model with (codec tools,
/// quantization, normals, geometry_joint_bytes()).
codec::PackWriteOptions pack_write_options(const ConvertOptions& options, std::size_t patches);

/// The quantization switches of `convert` and `encode`: --bits in [8, 24], --normal-bits in [6, 16] and not
/// given together with --no-normals. \throw InvalidInput naming the switch.
void check_quantization_switches(int bits, int normal_bits, bool normal_bits_given, bool no_normals);

/// \throw InvalidInput / SolverFailure from the parameterization; std::invalid_argument never escapes (the
/// images come from resample_geometry()).
ConvertResult convert_models(const PreparedModels& models, const ConvertOptions& options);

/// The level a layout of `patches` patches would get; 0 with `why_not` saying why that layout is not tried;
/// −1 when the user chose the layout (no choice at all).
using RelayoutLevel = std::function<int(int patches, std::string& why_not)>;

/// convert_models(models, options), except that one mesh whose two squares have an L2 stretch of at least
/// kStretchedTwoSquares is, right after that parameterization, converted again on each layout of
/// kStretchedShapeLayouts whose `level_for` is ≥ 1, each with every set of `error_weight_sets` (in order;
/// a set whose layout is that of an earlier set of the same patch count is not converted again: its
/// candidate's not_built says so) (`prepare(patches, error_weights)` prepares it; `before_switch(stretch,
/// layouts)` is called once before the first, with the patch counts to be tried). When more than one layout
/// is built, the one whose geometry-only prefixes at kStretchedChoiceSizes (those below the larger pack; its
/// whole pack where smaller) have the higher mean PSNR against the mesh (relayout_distance_options()) is
/// returned; a single built layout is returned unmeasured. `models` and `options.level` then describe it,
/// and its pack is byte for byte that of convert_models() on its layout and level (the choice is
/// deterministic). When no layout can be built (InvalidInput, SolverFailure) or none is tried, the two
/// squares are converted after all. `choice` reports what was tried (chosen_patches 0: the two squares).
/// The callers give a `level_for` that returns −1 when the user chose the layout (--patches, --points, a
/// loop).
ConvertResult convert_relayout_when_stretched(
    PreparedModels& models, ConvertOptions& options, const RelayoutLevel& level_for,
    const std::vector<std::vector<double>>& error_weight_sets,
    const std::function<PreparedModels(int patches, const std::vector<double>& error_weights)>& prepare,
    const std::function<void(double stretch, const std::vector<int>& layouts)>& before_switch,
    RelayoutChoice& choice);

}  // namespace geomip::tools
