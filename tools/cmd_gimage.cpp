// geomip gimage MESH... [--points CORR.json] --level N -o DIR: consistent parameterization (as `geomip
// param`), then per model DIR/<stem>.geometry.exr (float32 xyz) and DIR/<stem>.normals.exr (half unit
// normals), one tiled ROUND_UP MIP pyramid per patch (gimage/exr_io.h).
#include "gimage/exr_io.h"
#include "gimage/fit.h"
#include "gimage/resample.h"
#include "mesh/errors.h"
#include "param/consistent_parameterization.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/model_inputs.h"
#include "tools/progress.h"
#include "tools/report.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace geomip::tools {
namespace {

struct GimageArgs {
  ModelArgs common;
  int level = 0;
  int normal_level = -1;
  bool fit = false;  ///< least-squares fitted samples (gimage/fit.h)
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run_gimage(const GimageArgs& args) {
  if (args.level < 0 || args.level > kMaxGeometryImageLevel) {
    throw InvalidInput("--level " + std::to_string(args.level) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  if (args.normal_level >= 0 &&
      (args.normal_level < args.level || args.normal_level > kMaxGeometryImageLevel)) {
    throw InvalidInput("--normal-level " + std::to_string(args.normal_level) + " is outside [" +
                       std::to_string(args.level) + ", " + std::to_string(kMaxGeometryImageLevel) + "]");
  }
  const PreparedModels models =
      prepare_models(args.common.meshes, args.common.points, "geomip gimage",
                     args.common.quiet || args.common.json, args.common.patches, loop_kind(args.common),
                     args.common.equal_area_layout, args.common.layout_error_weights);
  check_output_directory(args.common.output);
  {
    std::vector<std::string> planned;  // the files written below, checked before the work
    for (const auto& input : models.inputs) {
      const std::string stem = (std::filesystem::path(args.common.output) / input.name).string();
      planned.push_back(stem + ".geometry.exr");
      planned.push_back(stem + ".normals.exr");
    }
    check_planned_outputs(args.common.output, planned);
  }

  ParameterizationOptions options;
  apply_sampling(args.common, options);
  options.measure_mvc_baseline = false;
  ProgressBar bar("gimage", !args.common.quiet && !args.common.json);
  options.progress = bar.callback();
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> result = parameterize_consistently(models.inputs, options);
  const double param_seconds = seconds_since(t0);
  bar.finish();
  // Only now: a failed parameterization leaves no (empty) output directory behind.
  const CreatedDirectories created = make_output_directory(args.common.output);

  nlohmann::json summary = nlohmann::json::array();
  // Every model's two images or none: an image that cannot be written leaves no other behind.
  AtomicFileSet files;
  std::string report;  // printed once the files are in place
  for (std::size_t i = 0; i < result.size(); ++i) {
    t0 = std::chrono::steady_clock::now();
    ResampleOptions resample;
    resample.normal_level = args.normal_level;
    GeometryImages images = resample_geometry(result[i], args.level, resample);
    const double resample_seconds = seconds_since(t0);
    double fit_seconds = 0;
    if (args.fit) {
      t0 = std::chrono::steady_clock::now();
      FitOptions fit;
      fit.quad_split = QuadSplit::kShorter;  // as `geomip remesh` and `geomip decode` split the quads by default
      fit.measure_after = false;
      images = fit_geometry_images(result[i].mesh, images, fit).images;
      fit_seconds = seconds_since(t0);
    }
    const std::string stem = (std::filesystem::path(args.common.output) / models.inputs[i].name).string();
    GeometryImageFileInfo info;
    // The file name only: an absolute path would leak the converting machine's directories into the file.
    info.source_mesh = std::filesystem::path(models.paths[i]).filename().string();
    info.adjacency = images.adjacency;
    t0 = std::chrono::steady_clock::now();
    const auto geometry_bytes = files.add_file(stem + ".geometry.exr", [&](const std::string& file) {
      write_geometry_image_exr(file, images.geometry, info);
    });
    info.kind = "normals";
    const auto normals_bytes = files.add_file(stem + ".normals.exr", [&](const std::string& file) {
      write_geometry_image_exr(file, images.normals, info, {true, 64});
    });
    const double write_seconds = seconds_since(t0);
    if (args.common.json) {
      summary.push_back({{"mesh", models.paths[i]},
                         {"geometry", stem + ".geometry.exr"},
                         {"normals", stem + ".normals.exr"},
                         {"patches", images.geometry.size()},
                         {"level", args.level},
                         {"normal_level", images.normals.front().level},
                         {"geometry_bytes", geometry_bytes},
                         {"normals_bytes", normals_bytes},
                         {"uncovered_samples", images.uncovered_samples},
                         {"resample_seconds", resample_seconds},
                         {"write_seconds", write_seconds},
                         {"fit", args.fit}});
      if (args.fit) summary.back()["fit_seconds"] = fit_seconds;
    } else if (!args.common.quiet) {
      report += string_printf(
          "gimage %s → %s.geometry.exr (%zu patches, %d², %.1f KiB), %s.normals.exr (%d², %.1f KiB); "
          "resampled in %.3f s",
          models.paths[i].c_str(), stem.c_str(), images.geometry.size(), images.geometry.front().size(),
          geometry_bytes / 1024.0, stem.c_str(), images.normals.front().size(), normals_bytes / 1024.0,
          resample_seconds);
      if (args.fit) report += string_printf(", fitted in %.3f s", fit_seconds);
      report += "\n";
    }
  }
  files.commit();
  std::fputs(report.c_str(), stdout);
  if (args.common.json) {
    std::cout << nlohmann::json{{"models", summary}, {"param_seconds", param_seconds}}.dump(
                     2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  } else if (!args.common.quiet) {
    std::printf("parameterization %.2f s\n", param_seconds);
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_gimage_command(CLI::App& app) {
  auto args = std::make_shared<GimageArgs>();
  CLI::App* cmd = app.add_subcommand(
      "gimage",
      "Geometry images (paper §4, Gu et al. 2002): parameterize as `geomip param`, resample each patch on a "
      "(2^N+1)² grid and write DIR/<stem>.geometry.exr (float32 xyz) and DIR/<stem>.normals.exr (half "
      "normals), "
      "one tiled MIP pyramid per patch whose level l is the nested (2^(N-l)+1)² grid.");
  add_model_options(cmd, args->common);
  cmd->add_option("--level", args->level, "Grid level N in [0, 10]: (2^N+1)² samples per patch")->required();
  cmd->add_option("--normal-level", args->normal_level,
                  "Normal map level in [N, 10] (default N+1, at most 10)")
      ->check(CLI::Range(0, 10));
  cmd->add_flag("--fit,!--no-fit", args->fit,
                "Move every level-N sample along its normal so that the level-N remesh is a least-squares fit of "
                "the surface, not its interpolant (gimage/fit.h; seams stay bit-identical; coarser MIP levels are "
                "the nested samples, not refitted); --no-fit: samples on the surface (default)");
  return [args] { return run_gimage(*args); };
}

}  // namespace geomip::tools
