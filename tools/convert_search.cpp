#include "tools/convert_search.h"

#include "codec/pack.h"
#include "codec/parallel.h"
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "tools/pack_models.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <utility>

namespace geomip::tools {
namespace {

const char* loop_name(LoopKind kind) {
  switch (kind) {
    case LoopKind::kTips:
      return "tips";
    case LoopKind::kEnds:
      return "ends";
    case LoopKind::kPlain:
      break;
  }
  return "plain";
}

struct Built {
  SearchCandidate candidate;
  PreparedModels models;
  ConvertResult geometry;  ///< geometry-only conversion
  double seconds = 0;
};

}  // namespace

std::string SearchCandidate::name(int default_level) const {
  std::string s = patches == 2 ? loop_name(loop) : std::to_string(patches) + " patches";
  if (level != default_level) s += " level " + std::to_string(level);
  if (fit) s += " + fit";
  if (linf_sweeps > 0) s += " + L∞ pass";
  if (frame_steps >= 0 && frame_steps != ConvertOptions{}.frame_steps)
    s += " + frame steps " + std::to_string(frame_steps);
  return s;
}

std::string SearchCandidate::switches(int default_level) const {
  std::string s;
  auto add = [&](const std::string& w) { s += (s.empty() ? "" : " ") + w; };
  if (loop == LoopKind::kTips) add("--tip-loop");
  if (loop == LoopKind::kEnds) add("--end-loop");
  if (patches != 2 || (loop == LoopKind::kPlain && two_squares_named))
    add("--patches " + std::to_string(patches));
  if (level != default_level) add("--level " + std::to_string(level));
  // Named either way, so that the switches keep building this candidate if the default (fit_by_default())
  // moves.
  add(fit ? "--fit" : "--no-fit");
  if (linf_sweeps > 0) add("--linf-sweeps " + std::to_string(linf_sweeps));
  if (frame_steps >= 0 && frame_steps != ConvertOptions{}.frame_steps)
    add("--frame-steps " + std::to_string(frame_steps));
  return s;
}

SearchResult search_conversion(const std::string& mesh, const ConvertOptions& options,
                               const SearchOptions& search, bool quiet) {
  using Clock = std::chrono::steady_clock;
  auto slide_rounds = [&](LoopKind kind) {
    return search.slide_seams >= 0 ? search.slide_seams : default_seam_slide_rounds(kind);
  };
  ConvertOptions geometry_options = options;
  geometry_options.normals = false;
  geometry_options.keep_inputs = true;  // the codec stage re-encodes them

  std::vector<Built> built;
  // The ConvertOptions of candidate `c` on top of `base`.
  auto candidate_options = [&](const SearchCandidate& c, ConvertOptions o) {
    o.level = c.level;
    o.fit = c.fit;
    if (c.linf_sweeps > 0) o.linf_sweeps = c.linf_sweeps;
    o.seam_slide_rounds = c.patches == 2 ? slide_rounds(c.loop) : 0;
    if (c.frame_steps >= 0) o.frame_steps = c.frame_steps;
    return o;
  };
  auto build = [&](const SearchCandidate& c, PreparedModels models) {
    const auto t0 = Clock::now();
    ConvertResult r = convert_models(models, candidate_options(c, geometry_options));
    built.push_back(
        {c, std::move(models), std::move(r), std::chrono::duration<double>(Clock::now() - t0).count()});
  };

  // The plain loop first: its errors (unreadable mesh, genus the two squares cannot hold) are the user's.
  build({LoopKind::kPlain, 2, options.level, options.fit},
        prepare_models({mesh}, "", "geomip convert", quiet, 2, LoopKind::kPlain));
  if (built.front().geometry.two_squares_l2_stretch >= kStretchedTwoSquares)
    built.front().candidate.two_squares_named = true;
  const PreparedModels& first = built.front().models;
  const TriMesh reference =
      first.originals.front().positions.empty() ? first.inputs.front().mesh : first.originals.front();

  if (search.loops) {
    for (LoopKind kind : {LoopKind::kTips, LoopKind::kEnds}) {
      PreparedModels m = prepare_models({mesh}, "", "geomip convert", true, 2, kind);
      const ParameterizationInput& in = m.inputs.front();
      if (in.side_guides.empty()) continue;  // no tips: the plain loop again
      bool seen = false;
      for (const Built& b : built) {
        const ParameterizationInput& o = b.models.inputs.front();
        seen =
            seen || (b.candidate.patches == 2 && o.partition_points == in.partition_points &&
                     o.side_guides == in.side_guides && slide_rounds(b.candidate.loop) == slide_rounds(kind));
      }
      if (!seen) build({kind, 2, options.level, options.fit}, std::move(m));
    }
  }
  for (const int k : search.layout_patches) {
    const int level = options.level + default_grid_level(static_cast<std::size_t>(k)) - default_grid_level(2);
    if (k <= 2 || level < 1) continue;
    std::optional<PreparedModels> m;
    try {
      m = prepare_models({mesh}, "", "geomip convert", true, k, LoopKind::kPlain);
    } catch (const InvalidInput& e) {  // no such layout on this mesh: not a candidate
      if (search.log) search.log("search: no " + std::to_string(k) + "-patch layout (" + e.what() + ")");
    }
    if (m) build({LoopKind::kPlain, k, level, options.fit}, std::move(*m));
  }

  // The sizes: those below the largest pack. A candidate whose whole pack is smaller than a size is scored
  // there with its whole pack (what a reader with that many bytes gets from it), so a small pack of a
  // coarse candidate does not take the larger sizes away from the others; the fit and the framings, built
  // later, are scored at the same sizes.
  SearchResult result;
  std::size_t largest = 0;
  for (const Built& b : built) largest = std::max(largest, b.geometry.pack.size());
  for (std::size_t s : search.sizes)
    if (s < largest) result.sizes.push_back(s);
  if (result.sizes.empty()) result.sizes.push_back(largest);

  auto score = [&](const Built& b) {
    const auto t0 = Clock::now();
    CandidateScore s;
    s.candidate = b.candidate;
    s.pack_bytes = b.geometry.pack.size();
    s.psnr_db = prefix_psnr(b.geometry.pack, result.sizes, reference);
    double sum = 0;
    for (double p : s.psnr_db) sum += p;  // NaN stays NaN: not eligible
    s.mean_psnr_db = sum / static_cast<double>(s.psnr_db.size());
    s.seconds = b.seconds + std::chrono::duration<double>(Clock::now() - t0).count();
    if (search.log) {
      char line[160];
      std::snprintf(line, sizeof line, "search: %s: %.2f dB (%zu B, %.1f s)",
                    s.candidate.name(options.level).c_str(), s.mean_psnr_db, s.pack_bytes, s.seconds);
      search.log(line);
    }
    result.scores.push_back(s);
  };
  auto best_index = [&] {
    std::size_t best = result.scores.size();
    for (std::size_t i = 0; i < result.scores.size(); ++i) {
      const double p = result.scores[i].mean_psnr_db;
      if (std::isfinite(p) && (best == result.scores.size() || p > result.scores[best].mean_psnr_db))
        best = i;
    }
    return best;
  };
  for (const Built& b : built) score(b);
  std::size_t best = best_index();
  if (best == result.scores.size())
    throw SolverFailure("convert search: no candidate's prefixes decode at every scored size");

  if (search.fit && !options.fit) {
    SearchCandidate c = built[best].candidate;
    c.fit = true;
    build(c, built[best].models);  // a copy: the unfitted candidate may still win
    score(built.back());
    best = best_index();
  }
  if (search.linf_sweeps > 0 && options.linf_sweeps == 0) {
    SearchCandidate c = built[best].candidate;
    c.linf_sweeps = search.linf_sweeps;
    build(c, built[best].models);
    score(built.back());
    best = best_index();
  }

  // Codec tools on the best so far: the same geometry images encoded again (convert_models() would write
  // these bytes from the same switches: it encodes its images with pack_write_options()).
  const std::size_t layout_best = best;
  for (int fs : search.frame_steps_choices) {
    SearchCandidate c = built[layout_best].candidate;
    c.frame_steps = fs;
    const ConvertOptions o = candidate_options(c, geometry_options);
    if (o.frame_steps == candidate_options(built[layout_best].candidate, geometry_options).frame_steps ||
        o.frame_steps > o.level)
      continue;
    const auto t0 = Clock::now();
    Built b{c, {}, {}, 0};
    b.geometry = built[layout_best].geometry;
    b.geometry.pack = codec::write_pack(b.geometry.inputs,
                                        pack_write_options(o, b.geometry.inputs.front().geometry.size()));
    b.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    built.push_back(std::move(b));
    score(built.back());
  }
  best = best_index();

  Built& winner = built[best];
  result.chosen = winner.candidate;
  // A codec variant shares its layout's models.
  PreparedModels& winner_models = winner.models.inputs.empty() ? built[layout_best].models : winner.models;
  if (options.normals || options.keep_inputs) {
    result.converted = convert_models(winner_models, candidate_options(winner.candidate, options));
  } else {
    result.converted = std::move(winner.geometry);
    result.converted.inputs.clear();
  }
  result.models = std::move(winner_models);
  return result;
}

SearchOptions full_search_options() {
  SearchOptions s;
  s.layout_patches.assign(std::begin(kSearchLayouts), std::end(kSearchLayouts));
  s.fit = true;
  s.linf_sweeps = kSearchLinfSweeps;
  s.sizes.assign(std::begin(kSearchSizes), std::end(kSearchSizes));
  s.frame_steps_choices.assign(std::begin(kSearchFrameSteps), std::end(kSearchFrameSteps));
  return s;
}

nlohmann::json search_json(const SearchResult& result, int default_level) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json candidates = nlohmann::json::array();
  for (const CandidateScore& c : result.scores) {
    nlohmann::json psnr = nlohmann::json::array();
    for (double p : c.psnr_db) psnr.push_back(number(p));
    candidates.push_back({{"name", c.candidate.name(default_level)},
                          {"switches", c.candidate.switches(default_level)},
                          {"mean_psnr_db", number(c.mean_psnr_db)},
                          {"psnr_db", psnr},
                          {"geometry_bytes", c.pack_bytes},
                          {"seconds", c.seconds}});
  }
  return {{"chosen", result.chosen.name(default_level)},
          {"switches", result.chosen.switches(default_level)},
          {"sizes", result.sizes},
          {"candidates", candidates}};
}

nlohmann::json relayout_json(const RelayoutChoice& choice) {
  if (choice.candidates.empty()) return nullptr;
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json layouts = nlohmann::json::array();
  for (const RelayoutChoice::Candidate& c : choice.candidates) {
    nlohmann::json psnr = nlohmann::json::array();
    for (double p : c.psnr_db) psnr.push_back(number(p));
    layouts.push_back(
        {{"patches", c.patches},
         {"error_weights", c.error_weights},
         {"level", c.level},
         {"mean_psnr_db", number(c.mean_psnr_db)},
         {"psnr_db", psnr},
         {"geometry_bytes", c.geometry_bytes},
         {"not_built", c.not_built.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.not_built)}});
  }
  return {{"two_squares_l2_stretch", choice.two_squares_l2_stretch},
          {"sizes", choice.sizes},
          {"chosen_patches", choice.chosen_patches},
          {"chosen_error_weights", choice.chosen_error_weights},
          {"seconds", choice.seconds},
          {"layouts", layouts}};
}

}  // namespace geomip::tools
