// geomip convert MESH... [--points CORR.json] [--level N] [--no-normals] -o PACK: repair (when needed) →
// consistent parameterization → geometry images (+ normal maps, + hole masks of repaired meshes) → the
// progressive .gip pack (codec/pack.h), written atomically.
#include "codec/pack.h"
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/convert_pipeline.h"
#include "tools/convert_search.h"
#include "tools/model_inputs.h"
#include "tools/pack_models.h"
#include "tools/progress.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace geomip::tools {
namespace {

struct ConvertArgs {
  ModelArgs common;
  int level = 8;
  bool level_given = false;  ///< --level on the command line; else default_grid_level() of the layout
  int normal_level = -1;
  int quantization_bits = 14;
  int normal_bits = ConvertOptions{}.normal_bits;
  int hole_mask_level = -1;
  bool no_hole_border_snap = false;
  bool no_normals = false;
  int normal_mesh_steps = ConvertOptions{}.normal_mesh_steps;
  double normal_mesh_reach = ConvertOptions{}.normal_mesh_max_shift;
  int normal_mesh_guard = ConvertOptions{}.normal_mesh_fold_guard;
  int frame_steps = ConvertOptions{}.frame_steps;
  bool frame_steps_given = false;  ///< --frame-steps on the command line
  bool normal_bits_given = false;  ///< --normal-bits on the command line
  int tangential_shift = ConvertOptions{}.tangential_shift;
  bool no_orientation_weights = false;
  bool no_lifting_update = false;
  bool no_cell_frames = false;
  int headroom_bits = ConvertOptions{}.headroom_bits;
  int normal_headroom_bits = ConvertOptions{}.normal_headroom_bits;
  bool normal_headroom_given = false;  ///< --normal-headroom-bits on the command line
  int normal_layers = ConvertOptions{}.normal_layers;
  bool normal_layers_given = false;  ///< --normal-layers on the command line
  bool short_filter = false;
  int threads = 0;  ///< --threads: the layout choice's (0 = one per hardware thread)
  bool fit = false;
  bool fit_given = false;    ///< --fit or --no-fit on the command line (else fit_by_default())
  bool choose_loop = false;  ///< --choose-loop: the plain, tip or end loop, whichever prefixes are closest
  bool search =
      false;       ///< --search: the loops, the 8- to 64-patch layouts, the fit, ... (tools/convert_search.h)
  std::string up;  ///< x, y, z, auto, none; empty: auto, or none for a geometry-only pack
  std::string front;  ///< +x, -x, +y, -y, +z, -z; empty: from the shape
};

/// --up as ConvertOptions::up (nullopt = no frame stored).
std::optional<UpAxis> up_axis(const ConvertArgs& args) {
  const std::string up = args.up.empty() ? (args.no_normals ? "none" : "auto") : args.up;
  if (up == "x") return UpAxis::kX;
  if (up == "y") return UpAxis::kY;
  if (up == "z") return UpAxis::kZ;
  if (up == "auto") return UpAxis::kAuto;
  return std::nullopt;
}

/// --front as a signed unit axis of the model's units (zero = from the shape, upright_rotation()).
Eigen::Vector3d front_axis(const ConvertArgs& args) {
  if (args.front.size() != 2) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d::Unit(args.front[1] - 'x') * (args.front[0] == '-' ? -1.0 : 1.0);
}

/// Prefix sizes --choose-loop compares the packs at (those below the largest pack).
constexpr std::size_t kChooseLoopSizes[] = {2000, 4000, 8000, 16000};

std::string format_db(double db) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f dB", db);
  return text;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The options whose range depends on the grid level.
void check_level_options(const ConvertArgs& args, int level) {
  if (level < 1 || level > 10) throw InvalidInput("--level " + std::to_string(level) + " is outside [1, 10]");
  if (args.normal_level >= 0 && (args.normal_level < level || args.normal_level > 10))
    throw InvalidInput("--normal-level " + std::to_string(args.normal_level) + " is outside [" +
                       std::to_string(level) + ", 10]");
  if (args.normal_mesh_steps < -1 || args.normal_mesh_steps > level)
    throw InvalidInput("--normal-mesh " + std::to_string(args.normal_mesh_steps) + " is outside [0, " +
                       std::to_string(level) + "] (the level)");
  // The default (3) is capped at the level by the codec; a number the user gave must fit.
  if (args.frame_steps < 0 || (args.frame_steps_given && args.frame_steps > level))
    throw InvalidInput("--frame-steps " + std::to_string(args.frame_steps) + " is outside [0, " +
                       std::to_string(level) + "] (the level)");
}

int run_convert(const ConvertArgs& args) {
  check_pack_output_name(args.common.output);
  if (!args.common.points.empty()) note_input_file(args.common.points);
  for (const std::string& mesh : args.common.meshes) note_input_file(mesh);
  check_output_file(args.common.output);
  // The level: --level, else default_grid_level() of --patches (a CORR.json's layout is counted once it is
  // read).
  int level =
      args.level_given ? args.level : default_grid_level(static_cast<std::size_t>(args.common.patches));
  check_level_options(args, level);
  check_quantization_switches(args.quantization_bits, args.normal_bits, args.normal_bits_given,
                              args.no_normals);
  if (args.no_normals && args.normal_headroom_given)
    throw InvalidInput(
        "--normal-headroom-bits sets the normal maps' headroom, and --no-normals writes none: drop one");
  if (args.no_normals && args.normal_layers_given)
    throw InvalidInput(
        "--normal-layers sets how the normal maps are coded, and --no-normals writes none: drop one");
  if (args.no_normals && args.normal_level >= 0)
    throw InvalidInput("--normal-level sets the normal maps' level, and --no-normals writes none: drop one");
  if (args.tangential_shift < 0 || args.tangential_shift > 8)
    throw InvalidInput("--tangential-shift " + std::to_string(args.tangential_shift) + " is outside [0, 8]");
  if (args.normal_mesh_steps > 0 && (args.common.meshes.size() > 1 || !args.common.points.empty()))
    throw InvalidInput("--normal-mesh moves samples off the parameterization, which the morphs of a consistent "
                       "set rely on: use it with one mesh");
  const LoopKind loop_asked = loop_kind(args.common);
  if (args.choose_loop && (args.common.meshes.size() != 1 || !args.common.points.empty() ||
                           args.common.patches != 2 || loop_asked != LoopKind::kPlain))
    throw InvalidInput("--choose-loop compares the automatic two-square loops of one mesh: give one MESH, "
                       "without --points, --patches, --tip-loop or --end-loop");
  if (args.search && (args.choose_loop || args.common.meshes.size() != 1 || !args.common.points.empty() ||
                      args.common.patches != 2 || args.common.layout_error_weights_given ||
                      loop_asked != LoopKind::kPlain || args.fit_given))
    throw InvalidInput(
        "--search chooses the layout and the fit of one mesh itself: give one MESH, without "
        "--points, --patches, --layout-error-weights, --tip-loop, --end-loop, --fit, --no-fit or "
        "--choose-loop");
  const bool report = !args.common.quiet && !args.common.json;
  const auto t_start = std::chrono::steady_clock::now();
  auto slide_rounds = [&](LoopKind kind) {
    return args.common.slide_seams >= 0 ? args.common.slide_seams : default_seam_slide_rounds(kind);
  };
  const bool searching = args.choose_loop || args.search;
  // Without a search: the models now, so that bad input fails before the frame checks below.
  PreparedModels models;
  if (!searching)
    models =
        prepare_models(args.common.meshes, args.common.points, "geomip convert", !report, args.common.patches,
                       loop_asked, args.common.equal_area_layout, args.common.layout_error_weights);
  if (!args.level_given && !models.inputs.empty() && !models.inputs.front().layout_quads.empty()) {
    level = default_grid_level(models.inputs.front().layout_quads.size());
    check_level_options(args, level);
  }

  const std::optional<UpAxis> up = up_axis(args);
  const Eigen::Vector3d front = front_axis(args);
  if (!front.isZero()) {
    if (!up) throw InvalidInput("--front " + args.front + " needs a stored frame: --up x, y, z or auto");
    const PreparedModels frame_models =
        searching ? prepare_models(args.common.meshes, "", "geomip convert", true) : PreparedModels{};
    const PreparedModels& m = searching ? frame_models : models;
    if (!m.inputs.empty() && !upright_rotation(view_frame_mesh(m), *up, front).row(0).transpose().isApprox(front))
      throw InvalidInput("--front " + args.front + " is along the up axis; name one of the other two axes");
  }

  ProgressBar bar("convert", report);
  ConvertOptions options;
  options.level = level;
  options.normal_level = args.normal_level;
  options.normals = !args.no_normals;
  options.quantization_bits = args.quantization_bits;
  options.normal_bits = args.normal_bits;
  options.normal_headroom_bits = args.normal_headroom_bits;
  options.normal_layers = args.normal_layers;
  options.hole_mask_level = args.hole_mask_level;
  options.snap_hole_borders = !args.no_hole_border_snap;
  options.sampling_exponent = args.common.sampling_exponent;
  options.curvature_metric = args.common.curvature_metric;
  options.linf_sweeps = static_cast<std::size_t>(args.common.linf_sweeps);
  options.seam_slide_rounds = slide_rounds(loop_asked);
  options.normal_mesh_steps = args.normal_mesh_steps;
  options.normal_mesh_max_shift = args.normal_mesh_reach;
  options.normal_mesh_fold_guard = args.normal_mesh_guard;
  options.frame_steps = args.frame_steps;
  options.tangential_shift = args.tangential_shift;
  options.orientation_weights = !args.no_orientation_weights;
  options.lifting_update = !args.no_lifting_update;
  options.cell_frames = !args.no_cell_frames;
  options.headroom_bits = args.headroom_bits;
  if (args.short_filter) options.filter = codec::WaveletFilter::kCubic;
  // The fit: as asked, else fit_by_default() (--search tries it itself; --choose-loop's loops are of its one
  // mesh).
  if (args.fit_given)
    options.fit = args.fit;
  else if (args.choose_loop)
    options.fit = fit_by_default(1);
  else if (!args.search)
    options.fit = fit_by_default(models.inputs.size());
  options.up = up;
  options.front = front;
  options.progress = bar.callback();
  options.threads = args.threads;
  ConvertResult converted;
  std::optional<SearchResult> searched;
  const int named_level = level;  // the level the search names its candidates against
  bool relayouted = false;        // moved from two stretched squares to more patches
  RelayoutChoice relayout_choice;
  if (searching) {
    // --choose-loop: the loops only (with --fit every loop fitted: options.fit).
    SearchOptions search = args.search ? full_search_options() : SearchOptions{};
    if (!args.search) search.sizes.assign(std::begin(kChooseLoopSizes), std::end(kChooseLoopSizes));
    search.slide_seams = args.common.slide_seams;
    if (report && args.search)
      search.log = [&bar](const std::string& line) {
        bar.finish();
        std::fprintf(stderr, "%s\n", line.c_str());
      };
    searched = search_conversion(args.common.meshes.front(), options, search, !report);
    converted = std::move(searched->converted);
    models = std::move(searched->models);
    level = searched->chosen.level;
  } else {
    // One mesh on the plain two squares, layout and level left to us: a shape they stretch moves to 16 or
    // 64 patches, whichever codes it better (kStretchedTwoSquares, kStretchedShapeLayouts), each at a level
    // that keeps about the two squares' samples, unless the level-dependent options do not fit there.
    const bool may_move = !args.common.patches_given && args.common.points.empty() &&
                          args.common.meshes.size() == 1 && loop_asked == LoopKind::kPlain;
    const auto level_for = [&](int patches, std::string& why_not) {
      if (!may_move) return -1;
      const int l = relayout_level(level, patches);
      if (l < 1) {
        why_not = "its level would be below 1 (--level " + std::to_string(level) + ")";
        return 0;
      }
      try {
        check_level_options(args, l);
      } catch (const InvalidInput& e) {
        why_not = std::string("at level ") + std::to_string(l) + ": " + e.what();
        return 0;
      }
      return l;
    };
    converted = convert_relayout_when_stretched(
        models, options, level_for,
        args.common.layout_error_weights_given
            ? std::vector<std::vector<double>>{args.common.layout_error_weights}
            : kStretchedLayoutErrorWeights,
        [&](int patches, const std::vector<double>& weights) {
          return prepare_models(args.common.meshes, "", "geomip convert", true, patches, LoopKind::kPlain,
                                args.common.equal_area_layout, weights);
        },
        [&](double stretch, const std::vector<int>& layouts) {
          bar.finish();
          if (!report) return;
          std::string which;
          for (std::size_t i = 0; i < layouts.size(); ++i)
            which += (i == 0 ? "" : i + 1 == layouts.size() ? " and " : ", ") + std::to_string(layouts[i]);
          std::printf(
              "layout: the two squares stretch this shape (L2 stretch %.2f; 1 is none): converting it again "
              "on %s patches%s (--patches 2 keeps the two squares)\n",
              stretch, which.c_str(),
              layouts.size() > 1 ? " and keeping the layout whose prefixes measure closer to the mesh" : "");
        },
        relayout_choice);
    relayouted = relayout_choice.chosen_patches > 0;
    if (!relayout_choice.candidates.empty() && report) {
      bar.finish();
      for (const RelayoutChoice::Candidate& c : relayout_choice.candidates) {
        const std::string name = relayout_choice.name(c);
        if (!c.not_built.empty())
          std::printf("layout: %s: not built (%s)\n", name.c_str(), c.not_built.c_str());
        else if (std::isfinite(c.mean_psnr_db))
          std::printf("layout: %s at level %d: %.2f dB mean PSNR of the geometry prefixes (%zu B)%s\n",
                      name.c_str(), c.level, c.mean_psnr_db, c.geometry_bytes,
                      relayout_choice.kept(c) ? ", kept" : "");
        else if (relayout_choice.kept(c))
          std::printf("layout: %s at level %d, kept (the only layout built)\n", name.c_str(), c.level);
      }
      if (relayouted && !relayout_choice.sizes.empty())
        std::printf(
            "layout: chosen in %.1f s (--patches %d --layout-error-weights %s gives this layout without "
            "the choice)\n",
            relayout_choice.seconds, relayout_choice.chosen_patches,
            error_weights_text(relayout_choice.chosen_error_weights).c_str());
      if (!relayouted) std::printf("layout: keeping the two squares\n");
    }
    level = options.level;
  }
  // --choose-loop's report: the mean PSNR of each loop (NaN: not built, e.g. a mesh without tips).
  std::string loop = searched ? std::string(searched->chosen.patches == 2 ? "" : "none") : "";
  double plain_psnr = NAN, tip_psnr = NAN, end_psnr = NAN;
  if (searched) {
    for (const CandidateScore& s : searched->scores) {
      // Each loop's own score: not its codec variants (framed steps), the fit and L∞ pass as chosen.
      if (s.candidate.patches != 2 || s.candidate.fit != searched->chosen.fit ||
          s.candidate.linf_sweeps != searched->chosen.linf_sweeps || s.candidate.frame_steps >= 0)
        continue;
      (s.candidate.loop == LoopKind::kTips ? tip_psnr : s.candidate.loop == LoopKind::kEnds ? end_psnr : plain_psnr) =
          s.mean_psnr_db;
    }
    if (searched->chosen.patches == 2)
      loop = searched->chosen.loop == LoopKind::kTips ? "tips" : searched->chosen.loop == LoopKind::kEnds ? "ends" : "plain";
  }
  const bool fitted = searched ? searched->chosen.fit : options.fit;  // the pack's samples
  const std::vector<std::uint8_t>& pack = converted.pack;
  write_file_atomically(args.common.output, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(pack.data()), static_cast<std::streamsize>(pack.size()));
  });
  bar.finish();

  codec::PackInfo info;
  codec::read_pack_info(pack, info);
  const nlohmann::json search_report =
      searched ? search_json(*searched, named_level) : nlohmann::json(nullptr);
  if (args.common.json) {
    nlohmann::json j_models = nlohmann::json::array();
    for (std::size_t m = 0; m < models.inputs.size(); ++m)
      j_models.push_back({{"mesh", models.paths[m]},
                          {"name", models.inputs[m].name},
                          {"masked_quads", converted.masked_quads[m]}});
    std::cout << nlohmann::json{{"pack", args.common.output},
                                {"bytes", pack.size()},
                                {"manifest_bytes", info.manifest_end},
                                {"chunks", info.chunks.size()},
                                {"level", level},
                                {"patches", info.models.front().geometry.num_patches},
                                {"moved_to_patches", relayouted},
                                {"fit", fitted},
                                {"layout_choice", relayout_json(relayout_choice)},
                                {"normals", !args.no_normals},
                                {"models", j_models},
                                {"snapped_border_samples", converted.snapped_samples},
                                {"normal_mesh",
                                 {{"steps", converted.normal_mesh_steps},
                                  {"samples", converted.normal_mesh_candidates},
                                  {"moved", converted.normal_mesh_moved},
                                  {"refused_folds", converted.normal_mesh_would_fold},
                                  {"mean_shift", converted.normal_mesh_mean_shift}}},
                                {"loop", loop.empty() ? nlohmann::json(nullptr) : nlohmann::json(loop)},
                                {"loop_psnr_db",
                                 {{"plain", std::isfinite(plain_psnr) ? nlohmann::json(plain_psnr)
                                                                      : nlohmann::json(nullptr)},
                                  {"tips", std::isfinite(tip_psnr) ? nlohmann::json(tip_psnr)
                                                                   : nlohmann::json(nullptr)},
                                  {"ends", std::isfinite(end_psnr) ? nlohmann::json(end_psnr)
                                                                   : nlohmann::json(nullptr)}}},
                                {"search", search_report},
                                {"param_seconds", converted.param_seconds},
                                {"resample_seconds", converted.resample_seconds},
                                {"encode_seconds", converted.encode_seconds},
                                {"two_squares_l2_stretch",
                                 converted.two_squares_l2_stretch > 0
                                     ? nlohmann::json(converted.two_squares_l2_stretch)
                                     : nlohmann::json(nullptr)},
                                {"seconds", seconds_since(t_start)}}
                     .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  } else if (report) {
    std::printf("convert %zu model(s) → %s: %zu bytes (header and manifest %zu, %zu chunks), level %d%s%s\n",
                models.inputs.size(), args.common.output.c_str(), pack.size(), info.manifest_end,
                info.chunks.size(), level, args.no_normals ? ", geometry only" : ", with normal maps",
                fitted ? ", samples fitted (--no-fit: on the surface)" : "");
    std::printf("parameterization %.2f s, resampling %.2f s, encoding %.2f s\n", converted.param_seconds,
                converted.resample_seconds, converted.encode_seconds);
    // The note points at more patches; not when convert tried them and none fits this mesh.
    if (!searching && !relayouted && converted.two_squares_l2_stretch >= kStretchedTwoSquares &&
        relayout_choice.candidates.empty())
      std::printf(
          "note: the two squares stretch this shape (L2 stretch %.2f; 1 is none): a layout of more "
          "patches may code it better (on the mean PSNR of the 1.5-32 KB prefixes, `--patches 16`: horse "
          "+1.0 dB, armadillo +1.1, cow about the same; `--patches 64`: armadillo +2.8), and `--search` "
          "measures which (docs/measurements.md, \"A note when two squares stretch the shape\")\n",
          converted.two_squares_l2_stretch);
    if (args.choose_loop) {
      if (std::isfinite(tip_psnr) || std::isfinite(end_psnr)) {
        std::string scores = "plain " + format_db(plain_psnr);
        if (std::isfinite(tip_psnr)) scores += ", through the tips " + format_db(tip_psnr);
        if (std::isfinite(end_psnr)) scores += ", through the ends " + format_db(end_psnr);
        std::printf("loop: %s (mean PSNR of the 2-16 KB prefixes: %s)\n", loop.c_str(), scores.c_str());
      } else {
        std::printf("loop: plain (no protrusion tips found)\n");
      }
    }
    if (args.search) {
      std::string sizes;
      for (std::size_t n : searched->sizes) sizes += (sizes.empty() ? "" : ", ") + std::to_string(n);
      const std::string switches = searched->chosen.switches(named_level);
      std::printf("search: %s (%s; the highest mean PSNR of the prefixes of %s bytes)\n",
                  searched->chosen.name(named_level).c_str(),
                  switches.empty() ? "the defaults" : switches.c_str(), sizes.c_str());
    }
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_convert_command(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Mesh(es) → progressive .gip pack: repair when needed, consistent parameterization, geometry images "
      "(and normal maps) at level N, wavelet coding. Holes of a repaired mesh are kept as holes (a mask).");
  args->common.sampling_exponent = ConvertOptions{}.sampling_exponent;  // streaming: best at low rates
  args->common.curvature_metric = ConvertOptions{}.curvature_metric;
  add_model_options(cmd, args->common);
  cmd->get_option("--output")->description("Output pack file (.gip)");
  CLI::Option* level = cmd->add_option(
      "--level", args->level,
      "Grid level N in [1, 10] (default 8: 257² samples per patch, for two squares; for a K-patch layout "
      "the coarsest level whose K grids hold at least as many samples: K = 3 to 7: 8, 8 to 31: 7, 32 to 121: "
      "6; a stretched shape moved to 16 or 64 patches gets one or two levels below the two squares' N)");
  cmd->add_option("--normal-level", args->normal_level,
                  "Normal map level in [N, 10] (default N+1, at most 10)")
      ->check(CLI::Range(0, 10));
  cmd->add_option("--bits", args->quantization_bits,
                  "Position quantization bits over the largest bounding-box extent (default 14)");
  CLI::Option* normal_bits = cmd->add_option(
      "--normal-bits", args->normal_bits,
      "Normal-map quantization bits in [6, 16] (default 10; each bit fewer: about 0.8-0.9x the normal "
      "bytes of the whole pack and a coarser shading; streamed prefixes hardly change)");
  cmd->add_option("--hole-mask-level", args->hole_mask_level,
                  "Grid level in [0, 10] of the mask of filled holes (default: N; coarser costs fewer bytes; "
                  "one above the grid level N is taken as N)")
      ->check(CLI::Range(0, 10));
  cmd->add_flag(
      "--no-hole-border-snap", args->no_hole_border_snap,
      "Leave the fill samples at a hole's border where the fill put them instead of moving them onto "
      "the original surface (ablations; decoded borders then hang over the hole by up to a quad)");
  cmd->add_flag("--no-normals", args->no_normals, "Geometry-only pack (for rate–distortion comparisons)");
  cmd->add_option(
         "--normal-mesh", args->normal_mesh_steps,
         "Normal-mesh resampling: move the samples of the finest STEPS wavelet steps onto the surface "
         "along their predicted normals, so their details are normal offsets (fewer bits); one mesh "
         "only (default " +
             std::to_string(kAutoNormalMeshSteps) + " for one mesh, 0 = off)")
      ->check(CLI::Range(0, 10));
  cmd->add_option("--normal-mesh-reach", args->normal_mesh_reach,
                  "Largest move of a normal-mesh sample, in sample spacings of its level")
      ->check(finite_range(0.0, 4.0));
  cmd->add_option("--normal-mesh-guard", args->normal_mesh_guard,
                  "Normal-mesh steps from STEP up (the coarser ones) refuse a move that would fold their grid "
                  "around the sample (default 3; 0 = none, 1 = every step)")
      ->check(CLI::Range(0, 10));
  CLI::Option* fit = cmd->add_flag(
      "--fit,!--no-fit", args->fit,
      "Move every level-N sample along its normal so that the level-N remesh is a least-squares fit of the "
      "surface, not its interpolant (gimage/fit.h, after the normal-mesh resampling; hole-mask quads left "
      "out; up to about twice the conversion time); --no-fit: samples on the surface. Default: fitted for "
      "one mesh, not for consistent sets");
  // Codec tools, for ablations (docs/codec-v3.md); the defaults are the codec's best measured.
  CLI::Option* frame_steps =
      cmd->add_option("--frame-steps", args->frame_steps,
                      "Code the details of the finest STEPS wavelet steps in local (normal, tangent) frames "
                      "(default " +
                          std::to_string(ConvertOptions{}.frame_steps) + ", at most the level; 0 = off)");
  cmd->add_option("--tangential-shift", args->tangential_shift,
                  "Quantize framed tangential components 2^S times coarser than normal ones (default " +
                      std::to_string(ConvertOptions{}.tangential_shift) + ")");
  cmd->add_flag("--no-orientation-weights", args->no_orientation_weights,
                "Weigh row/column and diagonal detail bands alike (ablations)");
  cmd->add_flag("--no-lifting-update", args->no_lifting_update,
                "Code the geometry with the plain interpolating wavelet, without the update step (ablations; "
                "the pack's format is the same)");
  cmd->add_option(
         "--threads", args->threads,
         "Worker threads of the layout choice of a shape that two squares stretch (its layouts built "
         "side by side; default: all cores, fewer for meshes of over a million faces); the pack does "
         "not depend on it")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--headroom-bits", args->headroom_bits,
                  "Extra quantization bits of the coarse wavelet bands (default 4; the stream ends where the "
                  "finest details have --bits): a prefix's error sits in the coarse bands, so these lift the "
                  "16-32 KB prefixes by up to 2.3 dB at about the same pack size; 0 = pack format 9's stream "
                  "(ablations; also 0 with --no-cell-frames)")
      ->check(CLI::Range(0, 10));
  CLI::Option* normal_headroom =
      cmd->add_option(
             "--normal-headroom-bits", args->normal_headroom_bits,
             "Extra quantization bits of the normal maps' coarse bands, as --headroom-bits for the geometry "
             "(default 4: streamed prefixes of the normal maps up to 38 % closer in angle, the whole "
             "normal stream 0.90-0.99x the bytes at a mean error of about 0.05 degrees instead of 0.042; "
             "0 = 10 bits lossless, the normal maps of packs before 2026-12-07)")
          ->check(CLI::Range(0, 8));
  CLI::Option* normal_layers =
      cmd->add_option(
             "--normal-layers", args->normal_layers,
             "How the normal maps are coded: 2 (default; pack format 11) = the first passes of the xyz "
             "map, then the rest as a 2-channel residual in frames around them (bunny: the whole map "
             "at 0.58x the mean angle in 0.98x the bytes, 8-34 % lower mean angle at 50-600 KB "
             "prefixes); 1 = the xyz map alone, as packs before format 11")
          ->check(CLI::Range(1, 2));
  cmd->add_flag("--no-cell-frames", args->no_cell_frames,
                "Build the local frames as pack format 7 did (per sample, from the finest reconstruction) "
                "instead of from the coarse grid and a table of direction cells (ablations; decodes slower; "
                "the pack's format is the same)");
  cmd->add_flag(
      "--short-filter", args->short_filter,
      "Code the geometry with pack format 5's 4-point wavelet filter on every step and its 2-tap update, "
      "not the 6-point prediction of the coarser steps and the 4-tap update (ablations; the pack's "
      "format is the same)");
  cmd->add_flag("--choose-loop", args->choose_loop,
                "One mesh, two squares: build the pack with the plain loop, with --tip-loop and with --end-loop "
                "(each when the mesh has tips) and keep the one whose 2, 4, 8 and 16 KB prefixes are closest to "
                "the mesh (mean PSNR); up to three times the time");
  cmd->add_flag(
      "--search", args->search,
      "One mesh: build the pack with each two-square loop (plain, --tip-loop, --end-loop) and the "
      "automatic 8-, 16-, 32- and 64-patch layouts (at about the same samples), then the "
      "best of them with --fit, "
      "then with the L-infinity pass (--linf-sweeps 1000), then with 4 and 5 framed steps, and keep the "
      "one whose 1.5, 2, 4.7, 8.8, 16 and 32 KB geometry prefixes are closest to the mesh (mean PSNR; "
      "tools/convert_search.h); several pipelines: several minutes for the horse");
  cmd->add_option(
         "--up", args->up,
         "The models' up axis, stored with the front in each model's normalization (the viewer's frame; "
         "decoded meshes keep their units): x, y, z, auto (from the first model's shape: the side it "
         "rests on) or none (no frame: the viewer shows y up). One rotation for all models. Default: "
         "auto; none with --no-normals (R-D packs stay byte-identical)")
      ->check(CLI::IsMember({"x", "y", "z", "auto", "none"}));
  cmd->add_option("--front", args->front,
                  "The model axis the viewer shows as its front (the head of an animal, towards the default "
                  "camera): +x, -x, +y, -y, +z or -z, across the up axis. Default: from the first model's "
                  "shape (docs/streaming.md, \"Upright and front\")")
      ->check(CLI::IsMember({"+x", "-x", "+y", "-y", "+z", "-z"}));
  return [args, level, frame_steps, normal_bits, normal_headroom, normal_layers, fit] {
    args->level_given = level->count() > 0;
    args->normal_headroom_given = normal_headroom->count() > 0;
    args->normal_layers_given = normal_layers->count() > 0;
    args->frame_steps_given = frame_steps->count() > 0;
    args->normal_bits_given = normal_bits->count() > 0;
    args->fit_given = fit->count() > 0;
    return run_convert(*args);
  };
}

}  // namespace geomip::tools
