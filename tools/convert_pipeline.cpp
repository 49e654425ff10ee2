#include "tools/convert_pipeline.h"

#include "codec/normal_mesh.h"
#include "codec/parallel.h"
#include "gimage/fit.h"
#include "gimage/hole_mask.h"
#include "gimage/resample.h"
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "param/consistent_parameterization.h"
#include "tools/pack_models.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace geomip::tools {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Moves the finest steps' samples of every patch onto the surface along their predicted normals.
void normal_mesh(GeometryImages& images, const TriMesh& surface, int steps, const ConvertOptions& options,
                 ConvertResult& result) {
  const SurfaceQuery query(surface);
  const codec::SurfaceCrossing crossing = [&](const codec::Point3d& origin, const codec::Point3d& direction,
                                              const codec::Point3d& hint,
                                              double radius) -> std::optional<codec::Point3d> {
    const auto hit = query.crossing_near(Eigen::Vector3d(origin[0], origin[1], origin[2]),
                                         Eigen::Vector3d(direction[0], direction[1], direction[2]),
                                         Eigen::Vector3d(hint[0], hint[1], hint[2]), radius);
    if (!hit) return std::nullopt;
    return codec::Point3d{hit->x(), hit->y(), hit->z()};
  };
  codec::NormalMeshOptions normal;
  normal.steps = steps;
  normal.max_shift = options.normal_mesh_max_shift;
  normal.fold_guard_from_step = options.normal_mesh_fold_guard;
  normal.filter = options.filter;  // the filter write_pack() codes with (below)
  double shift_sum = result.normal_mesh_mean_shift * static_cast<double>(result.normal_mesh_moved);
  for (GeometryImage& image : images.geometry) {
    codec::Grid3 grid{image.level, std::move(image.values)};
    const codec::NormalMeshStats stats = codec::normal_mesh_resample(grid, crossing, normal);
    image.values = std::move(grid.values);
    result.normal_mesh_candidates += stats.candidates;
    result.normal_mesh_moved += stats.moved;
    result.normal_mesh_would_fold += stats.would_fold;
    shift_sum += stats.mean_shift * static_cast<double>(stats.moved);
  }
  if (result.normal_mesh_moved > 0)
    result.normal_mesh_mean_shift = shift_sum / static_cast<double>(result.normal_mesh_moved);

  // The normal maps follow the moved samples: each interior texel takes the surface normal nearest the point
  // the geometry image now puts at its (u,v) (bilinear in the geometry grid). Border texels keep theirs: the
  // border samples do not move, and seam texels stay bit-identical across patches.
  for (std::size_t p = 0; p < images.normals.size() && p < images.geometry.size(); ++p) {
    const GeometryImage& geometry = images.geometry[p];
    GeometryImage& normals = images.normals[p];
    const int n = normals.size();
    const double scale = static_cast<double>(geometry.size() - 1) / static_cast<double>(n - 1);
    codec::parallel_for(n - 2, 0, [&](int row) {
      const int b = row + 1;
      for (int a = 1; a < n - 1; ++a) {
        const double x = a * scale, y = b * scale;
        const int i = std::min(static_cast<int>(x), geometry.size() - 2);
        const int j = std::min(static_cast<int>(y), geometry.size() - 2);
        const double fx = x - i, fy = y - j;
        const Eigen::Vector3d point =
            (1 - fy) * ((1 - fx) * geometry.sample(i, j).cast<double>() + fx * geometry.sample(i + 1, j).cast<double>()) +
            fy * ((1 - fx) * geometry.sample(i, j + 1).cast<double>() + fx * geometry.sample(i + 1, j + 1).cast<double>());
        const Eigen::Vector3d unit = query.normal_near(point);
        float* texel = normals.at(a, b);
        for (int c = 0; c < 3; ++c) texel[c] = static_cast<float>(unit[c]);
      }
    });
  }
}

/// Gauss–Newton passes of the fit for a pack. One: means of three jittered copies of the 1.5-32 KB prefixes
/// with one, two and three passes agree within 0.07 dB on the bunny, the horse and venus, and the bunny's
/// whole packs within 0.02 dB (docs/codec-v3.md, "A faster fit"); each pass is a full set of closest-point
/// queries. `geomip remesh --fit` and `gimage --fit`, whose remeshes are not quantized, keep FitOptions'
/// three.
constexpr int kConvertFitIterations = 1;

/// fit_geometry_images() against `surface`, the quads of `mask` (at `mask_level` ≤ the images' level) left out.
GeometryImages fit_images(const GeometryImages& images, const TriMesh& surface, const HoleMaskResult& mask,
                          int mask_level) {
  FitOptions fit;
  fit.quad_split = QuadSplit::kShorter;  // what `geomip decode` does with a pack
  fit.measure_after = false;             // only the images are used
  fit.iterations = kConvertFitIterations;
  if (!mask.quads.empty())
    fit.hole_quads = refine_hole_quads(mask.quads, mask_level, images.geometry.front().level);
  return fit_geometry_images(surface, images, fit).images;
}

}  // namespace

const TriMesh& view_frame_mesh(const PreparedModels& models) {
  const bool repaired = !models.originals.empty() && !models.originals[0].triangles.empty();
  return repaired ? models.originals[0] : models.inputs.at(0).mesh;
}

std::size_t geometry_joint_bytes(std::size_t patches) {
  return 1024 * std::max<std::size_t>(patches, 2);
}

codec::PackWriteOptions pack_write_options(const ConvertOptions& options, std::size_t patches) {
  codec::PackWriteOptions write;
  write.geometry.joint_bytes = geometry_joint_bytes(patches);
  write.canonical_layout = true;  // convert's layouts are its own: their seam tables take a few bits per quad
  write.normals = options.normals;
  write.geometry.quantization_bits = options.quantization_bits;
  write.normal_codec.quantization_bits = options.normal_bits;
  write.normal_codec.headroom_bits = options.normal_headroom_bits;
  write.normal_layers = options.normal_layers;
  write.geometry.frame_steps = options.frame_steps;
  write.geometry.tangential_shift = options.tangential_shift;
  write.geometry.orientation_weights = options.orientation_weights;
  write.geometry.lifting_update = options.lifting_update;
  write.geometry.cell_frames = options.cell_frames;
  write.geometry.headroom_bits = options.cell_frames ? options.headroom_bits : 0;  // version 7 builds on 6
  write.geometry.filter = options.filter;
  return write;
}

void check_quantization_switches(int bits, int normal_bits, bool normal_bits_given, bool no_normals) {
  if (bits < 8 || bits > 24) throw InvalidInput("--bits " + std::to_string(bits) + " is outside [8, 24]");
  if (normal_bits < 6 || normal_bits > 16)
    throw InvalidInput("--normal-bits " + std::to_string(normal_bits) + " is outside [6, 16]");
  if (no_normals && normal_bits_given)
    throw InvalidInput(
        "--normal-bits sets the normal maps' quantization, and --no-normals writes none: drop one");
}

int default_grid_level(std::size_t patches) {
  constexpr int kTwoSquares = 8;
  const double two_squares = 2.0 * std::pow((1 << kTwoSquares) + 1, 2);
  // The coarsest level that keeps as many samples, not below the default framed steps (3): a layout too fine
  // for that is refused for its patch count anyway.
  int level = kTwoSquares;
  while (level > codec::GeometryCodecOptions{}.frame_steps &&
         static_cast<double>(patches) * std::pow((1 << (level - 1)) + 1, 2) >= two_squares)
    --level;
  return level;
}

int relayout_level(int level, int patches) {
  const int coarser = level + default_grid_level(static_cast<std::size_t>(patches)) - default_grid_level(2);
  return coarser >= 1 ? coarser : 0;
}

std::vector<double> prefix_psnr(const std::vector<std::uint8_t>& pack, const std::vector<std::size_t>& sizes,
                                const TriMesh& reference, const SurfaceDistanceOptions& distance,
                                bool sizes_in_parallel) {
  std::vector<double> out(sizes.size(), NAN);
  const auto measure = [&](int i, unsigned threads) {
    codec::PackDecodeOptions decode;
    decode.max_bytes = sizes[i];
    decode.normals = false;
    decode.max_threads = static_cast<int>(threads);
    const codec::PackDecodeResult result = codec::decode_pack(pack, decode);
    if (result.models.empty()) return;
    SurfaceDistanceOptions o = distance;
    o.threads = threads;
    out[i] = measure_surface_distance(reference, decoded_mesh(result.models.front()), o).psnr_db;
  };
  if (sizes_in_parallel) {
    codec::parallel_for(static_cast<int>(sizes.size()), 0, [&](int i) { measure(i, 1); });
  } else {
    for (int i = 0; i < static_cast<int>(sizes.size()); ++i) measure(i, 0);
  }
  return out;
}

SurfaceDistanceOptions relayout_distance_options() {
  SurfaceDistanceOptions o;
  o.face_samples = 100000;
  return o;
}

std::string error_weights_text(const std::vector<double>& weights) {
  std::string text;
  for (double w : weights) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", w);
    text += (text.empty() ? "" : ",") + std::string(buffer);
  }
  return text;
}

namespace {

// "16 patches", with " (error weights 1,0.5,2,0.25,4)" when `name_weights`.
std::string layout_name(int patches, const std::vector<double>& weights, bool name_weights) {
  return std::to_string(patches) + " patches" +
         (name_weights ? " (error weights " + error_weights_text(weights) + ")" : "");
}

}  // namespace

std::string RelayoutChoice::name(const Candidate& c) const {
  bool weights_vary = false;
  for (const Candidate& other : candidates)
    weights_vary = weights_vary || other.error_weights != c.error_weights;
  return layout_name(c.patches, c.error_weights, weights_vary);
}

ConvertResult convert_relayout_when_stretched(
    PreparedModels& models, ConvertOptions& options, const RelayoutLevel& level_for,
    const std::vector<std::vector<double>>& error_weight_sets,
    const std::function<PreparedModels(int patches, const std::vector<double>& error_weights)>& prepare,
    const std::function<void(double stretch, const std::vector<int>& layouts)>& before_switch,
    RelayoutChoice& choice) {
  choice = {};
  std::vector<RelayoutChoice::Candidate> candidates;
  std::vector<int> tried;
  bool left_to_us = false;
  for (int k : kStretchedShapeLayouts) {
    RelayoutChoice::Candidate c;
    c.patches = k;
    c.level = level_for(k, c.not_built);
    left_to_us = left_to_us || c.level >= 0;
    if (c.level >= 1) tried.push_back(k);
    for (const std::vector<double>& weights : error_weight_sets) {
      c.error_weights = weights;
      candidates.push_back(c);
    }
  }
  if (!left_to_us || models.inputs.size() != 1) return convert_models(models, options);
  // The two squares' parameterization tells; the rest of their pipeline runs only when they stay.
  ConvertOptions probe = options;
  probe.stop_when_stretched = kStretchedTwoSquares;
  ConvertResult first = convert_models(models, probe);
  if (!first.stopped_stretched) return first;
  const double stretch = first.two_squares_l2_stretch;
  choice.two_squares_l2_stretch = stretch;
  const auto t_choice = std::chrono::steady_clock::now();
  const TriMesh& reference =
      models.originals.front().positions.empty() ? models.inputs.front().mesh : models.originals.front();

  struct Built {
    PreparedModels models;
    ConvertOptions options;
    ConvertResult result;
    std::vector<std::uint8_t> geometry_pack;  // what `convert --no-normals` writes on this layout
  };
  std::vector<Built> built;
  std::vector<std::size_t> built_candidate;  // index into choice.candidates
  if (!tried.empty() && before_switch) before_switch(stretch, tried);
  // Three phases. (1) On threads: each candidate's layout — its mesh read and prepared, its quads chosen
  // (most of the choice's time). (2) In candidate order: a layout that an earlier candidate chose already is
  // not converted again. (3) On threads: the other layouts converted. Every candidate is computed on its
  // own, so the packs do not depend on the threads (the same bytes as one after the other). Threads: one per
  // candidate up to options.threads (0: the hardware's), fewer on meshes of over a million faces, so that the
  // choice's peak memory stays about that of one conversion there.
  const std::size_t faces = models.inputs.front().mesh.triangles.size();
  const int threads = std::max(
      1, std::min({options.threads > 0 ? options.threads
                                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency())),
                   static_cast<int>(
                       std::max<std::size_t>(1, kRelayoutFacesPerThread / std::max<std::size_t>(faces, 1))),
                   static_cast<int>(candidates.size())}));
  std::vector<std::optional<PreparedModels>> layouts(candidates.size());
  std::mutex progress_mutex;
  // Runs one candidate's step; a layout that does not fit this mesh (too few vertices, paths that fail, a
  // solver that gives up) is reported as not built.
  const auto attempt = [](RelayoutChoice::Candidate& c, const auto& step) {
    try {
      step();
    } catch (const InvalidInput& e) {
      c.not_built = e.what();
    } catch (const SolverFailure& e) {
      c.not_built = e.what();
    }
  };
  if (options.progress) options.progress("choose layouts", 0.0);
  codec::parallel_for(static_cast<int>(candidates.size()), threads, [&](int i) {
    RelayoutChoice::Candidate& c = candidates[static_cast<std::size_t>(i)];
    if (c.level < 1) return;
    attempt(c, [&] { layouts[static_cast<std::size_t>(i)] = prepare(c.patches, c.error_weights); });
  });
  std::vector<std::size_t> to_build;  // candidate indices
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const RelayoutChoice::Candidate& c = candidates[i];
    if (!layouts[i]) continue;
    const ParameterizationInput& in = layouts[i]->inputs.front();
    const auto same = std::find_if(to_build.begin(), to_build.end(), [&](std::size_t j) {
      const ParameterizationInput& earlier = layouts[j]->inputs.front();
      return candidates[j].patches == c.patches && earlier.partition_points == in.partition_points &&
             earlier.layout_quads == in.layout_quads;
    });
    if (same != to_build.end()) {
      candidates[i].not_built =
          "the same layout as with error weights " + error_weights_text(candidates[*same].error_weights);
      layouts[i].reset();
      continue;
    }
    to_build.push_back(i);
  }
  std::vector<std::optional<Built>> builds(to_build.size());
  std::vector<double> done(to_build.size(), 0.0);  // each conversion's progress, for one bar over all
  codec::parallel_for(static_cast<int>(to_build.size()), threads, [&](int t) {
    const std::size_t i = to_build[static_cast<std::size_t>(t)];
    RelayoutChoice::Candidate& c = candidates[i];
    attempt(c, [&] {
      Built b{std::move(*layouts[i]), options, {}, {}};
      layouts[i].reset();
      b.options.level = c.level;
      b.options.keep_inputs = true;  // the geometry-only pack is encoded again from them
      if (options.progress) {
        // One bar over all layouts: the conversions fill 0.9 of it, each named after its layout; the
        // measurements the last tenth.
        const std::string prefix =
            layout_name(c.patches, c.error_weights, error_weight_sets.size() > 1) + ": ";
        b.options.progress = [&options, &progress_mutex, &done, prefix, t](const char* stage, double f) {
          const std::lock_guard<std::mutex> lock(progress_mutex);
          done[static_cast<std::size_t>(t)] = f;
          double sum = 0;
          for (double d : done) sum += d;
          options.progress((prefix + stage).c_str(), 0.9 * sum / static_cast<double>(done.size()));
        };
      }
      b.result = convert_models(b.models, b.options);
      b.options.progress = options.progress;
      if (options.normals) {
        ConvertOptions geometry = b.options;
        geometry.normals = false;
        b.geometry_pack = codec::write_pack(
            b.result.inputs, pack_write_options(geometry, b.result.inputs.front().geometry.size()));
      } else {
        b.geometry_pack = b.result.pack;
      }
      if (!options.keep_inputs) b.result.inputs.clear();
      b.options.keep_inputs = options.keep_inputs;
      c.geometry_bytes = b.geometry_pack.size();
      builds[static_cast<std::size_t>(t)] = std::move(b);
    });
  });
  for (std::size_t t = 0; t < to_build.size(); ++t) {
    if (!builds[t]) continue;
    built.push_back(std::move(*builds[t]));
    built_candidate.push_back(to_build[t]);
  }
  choice.candidates = candidates;
  if (built.empty()) {
    // Two squares after all: their whole pipeline (the note on the stretch is the caller's).
    ConvertResult result = convert_models(models, options);
    result.param_seconds += first.param_seconds;
    return result;
  }

  // Sizes below the larger pack (a smaller pack is scored whole there), as the search scores them.
  std::size_t largest = 0;
  for (const Built& b : built) largest = std::max(largest, b.geometry_pack.size());
  for (std::size_t s : kStretchedChoiceSizes)
    if (s < largest) choice.sizes.push_back(s);
  if (choice.sizes.empty()) choice.sizes.push_back(largest);
  if (built.size() == 1) choice.sizes.clear();  // nothing to choose between: not measured
  std::size_t best = built.size();
  for (std::size_t i = 0; i < built.size() && built.size() > 1; ++i) {
    if (options.progress)
      options.progress("measure layouts",
                       0.9 + 0.1 * static_cast<double>(i) / static_cast<double>(built.size()));
    RelayoutChoice::Candidate& c = choice.candidates[built_candidate[i]];
    // One prefix at a time on every thread: one set of search trees in memory instead of one per thread.
    c.psnr_db =
        prefix_psnr(built[i].geometry_pack, choice.sizes, reference, relayout_distance_options(), false);
    double sum = 0;
    for (double p : c.psnr_db) sum += p;  // NaN stays NaN: not eligible
    c.mean_psnr_db = sum / static_cast<double>(c.psnr_db.size());
    if (std::isfinite(c.mean_psnr_db) &&
        (best == built.size() || c.mean_psnr_db > choice.candidates[built_candidate[best]].mean_psnr_db))
      best = i;
  }
  if (options.progress && built.size() > 1) options.progress("measure layouts", 1.0);
  if (best == built.size()) best = 0;  // one layout, or no prefix decodes on any: the first
  choice.seconds = seconds_since(t_choice);
  Built& winner = built[best];
  choice.chosen_patches = choice.candidates[built_candidate[best]].patches;
  choice.chosen_error_weights = choice.candidates[built_candidate[best]].error_weights;
  choice.chosen_level = winner.options.level;
  ConvertResult result = std::move(winner.result);
  result.two_squares_l2_stretch = stretch;
  result.param_seconds += first.param_seconds;  // the two squares' parameterization too
  for (std::size_t i = 0; i < built.size(); ++i)
    if (i != best) result.param_seconds += built[i].result.param_seconds;
  models = std::move(winner.models);
  options = winner.options;
  return result;
}

bool fit_by_default(std::size_t model_count) {
  return model_count == 1;
}

ConvertResult convert_models(const PreparedModels& models, const ConvertOptions& options) {
  auto progress = [&](const char* stage, double fraction) {
    if (options.progress) options.progress(stage, fraction);
  };
  ConvertResult result;
  if (options.normal_mesh_steps > 0 && models.inputs.size() > 1) {
    throw InvalidInput("normal-mesh resampling moves samples off the parameterization, which the morphs of a "
                       "consistent set rely on: use it with one mesh");
  }
  const int normal_mesh_steps =
      options.normal_mesh_steps >= 0 ? options.normal_mesh_steps
                                     : (models.inputs.size() == 1 ? std::min(kAutoNormalMeshSteps, options.level) : 0);
  result.normal_mesh_steps = normal_mesh_steps;
  ParameterizationOptions param;
  param.measure_mvc_baseline = false;
  param.curvature_sampling = options.sampling_exponent > 0;
  param.sampling_weights.exponent = options.sampling_exponent;
  param.curvature_metric = options.curvature_metric;
  param.linf_sweeps = options.linf_sweeps;
  param.seam_slide_rounds = options.seam_slide_rounds;
  param.progress = [&](const char* stage, double fraction) { progress(stage, 0.8 * fraction); };
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> params = parameterize_consistently(models.inputs, param);
  result.param_seconds = seconds_since(t0);
  if (params.size() == 1 && params[0].patches.size() == 2)
    result.two_squares_l2_stretch =
        std::max(params[0].patches[0].stretch.l2, params[0].patches[1].stretch.l2);
  if (options.stop_when_stretched > 0 && result.two_squares_l2_stretch >= options.stop_when_stretched) {
    result.stopped_stretched = true;
    return result;
  }

  t0 = std::chrono::steady_clock::now();
  std::vector<codec::PackModelInput> inputs;
  std::optional<Eigen::Matrix3d> view_rotation;
  if (options.up && !models.inputs.empty())
    view_rotation = upright_rotation(view_frame_mesh(models), *options.up, options.front);
  if (view_rotation && view_rotation->isIdentity()) view_rotation.reset();  // the viewer's default: no bytes
  const int mask_level = options.hole_mask_level < 0 ? options.level : std::min(options.hole_mask_level, options.level);
  for (std::size_t m = 0; m < params.size(); ++m) {
    progress("resample", 0.8 + 0.1 * static_cast<double>(m) / static_cast<double>(params.size()));
    ResampleOptions resample;
    resample.normals = options.normals;
    resample.normal_level = options.normal_level;
    GeometryImages images = resample_geometry(params[m], options.level, resample);
    if (normal_mesh_steps > 0) normal_mesh(images, params[m].mesh, normal_mesh_steps, options, result);
    HoleMaskResult mask;
    const bool repaired = m < models.originals.size() && !models.originals[m].triangles.empty();
    if (repaired) mask = hole_mask(params[m], models.originals[m], mask_level);
    if (options.fit) images = fit_images(images, repaired ? models.originals[m] : params[m].mesh, mask, mask_level);
    if (repaired && options.snap_hole_borders) {
      // The samples are the geometry's; the quads kept are the decoder's, at the mask's level.
      if (mask_level == options.level) {
        result.snapped_samples += snap_hole_borders(images, mask, models.originals[m]);
      } else if (!mask.quads.empty()) {
        HoleMaskResult fine = hole_mask(params[m], models.originals[m], options.level);
        fine.quads = refine_hole_quads(mask.quads, mask_level, options.level);
        result.snapped_samples += snap_hole_borders(images, fine, models.originals[m]);
      }
    }
    result.masked_quads.push_back(mask.masked_quads);
    inputs.push_back(pack_model_input(models.inputs[m].name, images, &mask, options.normals));
    inputs.back().hole_mask_level = mask_level;
    if (view_rotation)
      inputs.back().normalization = view_normalization(models.inputs[m].mesh, *view_rotation);
  }
  result.resample_seconds = seconds_since(t0);

  progress("encode", 0.9);
  t0 = std::chrono::steady_clock::now();
  result.pack = codec::write_pack(
      inputs, pack_write_options(options, inputs.empty() ? 2 : inputs.front().geometry.size()));
  result.encode_seconds = seconds_since(t0);
  if (options.keep_inputs) result.inputs = std::move(inputs);
  progress("encode", 1.0);
  return result;
}

}  // namespace geomip::tools
