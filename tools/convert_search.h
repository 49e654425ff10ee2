// An encoder that tries several configurations of one mesh's pack and keeps the one whose prefixes are
// closest to the mesh: `geomip convert --choose-loop` (the automatic two-square loops), `geomip convert
// --search` and `geomip rd --search` (the loops, automatic 8- to 64-patch layouts, fitted samples, the
// parameterization's L∞ pass and more framed steps).
//
// Which configuration is best depends on the mesh (docs/measurements.md, "A loop through the tips", "Where
// the horse's error is" and "Equal-error quad layouts"; docs/codec-v3.md): among the two-square loops the
// horse prefers the one through its ends, the bunny and cow the one through the tips; with the equal-error
// K-patch layouts the horse takes 16 patches and the armadillo 64, the bunny and venus keep two squares;
// fitted samples gain up to +1.7 dB above 16 KB on the horse and nothing on the bunny. So the search
// measures instead of guessing: each candidate is converted (geometry only), its prefixes at the scored sizes
// are decoded and measured against the mesh as `geomip rd` measures them (PSNR of the symmetric RMS surface
// distance), and the candidate with the highest mean PSNR over the sizes wins.
//
// Guarantees:
// - The winner's pack is byte for byte what `geomip convert` writes with the winner's switches (the
//   conversion is deterministic); with normal maps the winner alone is converted again with them.
// - Every candidate is scored at the same sizes: those of SearchOptions::sizes below the largest candidate's
//   geometry-only pack (at least one: that pack's size when all are larger); a pack smaller than a size is
//   scored there whole (what a reader of that many bytes gets).
// - A candidate whose layout does not exist for the mesh (no protrusion tips, no K-quad layout) or that
//   repeats an earlier one is not built; one whose prefix at a scored size decodes to nothing (it ends inside
//   a larger manifest) is not chosen.
// - Deterministic: the same mesh and options choose the same candidate.
//
// Cost: one pipeline per candidate (the K-patch layouts' parameterizations are the slowest, the fit adds
// about 15 s at level 8), then one decode and one distance measurement per candidate and size.
#pragma once

#include "tools/convert_pipeline.h"
#include "tools/model_inputs.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace geomip::tools {

/// One configuration: a layout (a two-square loop, or an automatic K-patch layout at its own level),
/// whether the samples are fitted (ConvertOptions::fit), the parameterization's L∞ pass and the framed steps.
struct SearchCandidate {
  LoopKind loop = LoopKind::kPlain;
  int patches = 2;
  int level = 8;
  bool fit = false;
  /// Sweeps of the parameterization's L∞ pass (ConvertOptions::linf_sweeps); 0 = the caller's setting.
  std::size_t linf_sweeps = 0;
  /// Local frames on this many wavelet steps (ConvertOptions::frame_steps); -1 = ConvertOptions' default.
  int frame_steps = -1;
  /// Two squares must be named (`--patches 2`): the plain loop of a shape they stretch, which `convert`
  /// without --patches would move to 16 patches (kStretchedTwoSquares).
  bool two_squares_named = false;
  /// "plain", "tips", "ends" or "8 patches", then " level N" when the level is not `default_level`, then
  /// " + fit" when fitted, then " + L∞ pass" with linf_sweeps, then " + frame steps N" when not the default.
  std::string name(int default_level) const;
  /// The switches of `geomip convert` that build this candidate ("--end-loop --fit", "--patches 8 --level
  /// 7 --no-fit", "--tip-loop --fit --linf-sweeps 1000", "--patches 2 --fit", "--no-fit"): the fit always
  /// named, so that the switches do not depend on the default (fit_by_default()).
  std::string switches(int default_level) const;
};

/// The automatic K-patch layouts `--search` tries: 8 patches (equal area), 16, 32 and 64 (equal error). Which
/// wins depends on the mesh: on the mean prefix PSNR the horse's best is 16 patches, the armadillo's 64 (both
/// above every two-square candidate), the bunny's 8 (docs/measurements.md, "Equal-error quad layouts").
inline constexpr int kSearchLayouts[] = {8, 16, 32, 64};
/// The prefix sizes `--search` scores (issue #14's range, 1.5 to 32 KB).
inline constexpr std::size_t kSearchSizes[] = {1500, 2000, 4700, 8800, 16000, 32000};
/// The framed steps `--search` tries on its best layout: 3 (the default), 4 or 5 (docs/codec-v3.md, "More
/// framed steps": each helps some meshes at some sizes and costs others). Tangential components 4× coarser
/// instead of 2× lost 0.6…1.7 dB in the mean on the horse with every framing, so they are not tried.
inline constexpr int kSearchFrameSteps[] = {3, 4, 5};
/// The L∞ pass `--search` tries on its best layout (after the fit): it moves samples towards the most
/// stretched triangles (protrusions); on the horse +0.15 / +0.41 dB on the mean of 18 prefix sizes up to /
/// above 16 KB (docs/measurements.md, "The L∞ pass in the search").
inline constexpr std::size_t kSearchLinfSweeps = 1000;

struct SearchOptions {
  /// The two-square loops: plain, through the tips (`--tip-loop`) and through the ends (`--end-loop`), each
  /// when the mesh has tips for it and its loop differs from the earlier ones.
  bool loops = true;
  /// Also the automatic K-patch layout for each K here (choose_quad_layout() with its default simplification
  /// for K), each at ConvertOptions::level + default_grid_level(K) − default_grid_level(2): about the samples
  /// of two squares at ConvertOptions::level (K = 8: one level coarser, K = 32: two). Empty = none.
  std::vector<int> layout_patches;
  /// Also the best layout with fitted samples (ConvertOptions::fit, when that is not already set for every
  /// candidate); tried on the best layout only (it costs a pipeline of its own, and what it gains depends on
  /// the mesh more than on the layout).
  bool fit = false;
  /// Then the best so far with the parameterization's L∞ pass of this many sweeps (a pipeline of its own,
  /// when ConvertOptions::linf_sweeps is 0); 0 = not tried.
  std::size_t linf_sweeps = 0;
  /// Then the best of those with local frames on each of these numbers of wavelet steps (the pack re-encoded
  /// from the same geometry images: seconds each). Empty = the default only.
  std::vector<int> frame_steps_choices;
  /// Prefix sizes in bytes whose PSNR is averaged (see the guarantees above).
  std::vector<std::size_t> sizes;
  /// --slide-seams N for every candidate; -1 = each loop's default (default_seam_slide_rounds()).
  int slide_seams = -1;
  /// Called with a line per candidate scored ("search: ends: 67.32 dB (98,839 B, 6.2 s)"); may be empty.
  std::function<void(const std::string&)> log;
};

struct CandidateScore {
  SearchCandidate candidate;
  double mean_psnr_db = NAN;    ///< NaN: a scored prefix decoded to nothing (not eligible)
  std::vector<double> psnr_db;  ///< per scored size
  std::size_t pack_bytes = 0;   ///< its geometry-only pack
  double seconds = 0;           ///< conversion and scoring
};

struct SearchResult {
  PreparedModels models;  ///< the chosen candidate's
  SearchCandidate chosen;
  std::vector<CandidateScore> scores;  ///< every candidate built, in build order
  std::vector<std::size_t> sizes;      ///< the sizes scored
  ConvertResult converted;             ///< the chosen candidate converted with the caller's options
};

/// What `--search` (convert and rd) tries: the loops, kSearchLayouts, the fit, kSearchLinfSweeps and
/// kSearchFrameSteps, scored at kSearchSizes.
SearchOptions full_search_options();

/// Builds `mesh`'s candidates (the plain loop at ConvertOptions::level always; the others as `search` asks;
/// each fitted when ConvertOptions::fit is set) and returns the best with `options` (normals, up, progress,
/// ...; level, fit and seam_slide_rounds are the candidate's). `quiet` silences the repair note. \throw as
/// prepare_models() and convert_models() for the plain loop; SolverFailure when no candidate decodes at every
/// scored size.
SearchResult search_conversion(const std::string& mesh, const ConvertOptions& options,
                               const SearchOptions& search, bool quiet);

/// The search as JSON (`convert --json` and `rd --json`): "chosen", "switches", "sizes" and per candidate its
/// "name", "switches", "mean_psnr_db" (null: not eligible), "psnr_db" per size (null: decoded to nothing),
/// "geometry_bytes" and "seconds". Names and switches are relative to `default_level`.
nlohmann::json search_json(const SearchResult& result, int default_level);

/// The layout choice of a stretched shape (convert_relayout_when_stretched()) as JSON (`convert --json`
/// and `rd --json`): null when nothing was tried, else "two_squares_l2_stretch", "sizes", "chosen_patches"
/// (0: the two squares kept) and per layout "patches", "level", "mean_psnr_db" and "psnr_db" per size (null:
/// not measured), "geometry_bytes" and "not_built" (null, or why), and "seconds" (building and measuring).
nlohmann::json relayout_json(const RelayoutChoice& choice);

}  // namespace geomip::tools
