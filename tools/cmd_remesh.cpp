// geomip remesh MESH... [--points CORR.json] --level K -o DIR [--ply]: consistent parameterization (as
// `geomip param`), then the uniform level-K remesh of every model, DIR/<stem>.M<K>.obj (and .ply):
// watertight, consistently oriented, one face list for all models of a consistent set
// (gimage/uniform_remesh.h).
#include "gimage/resample.h"
#include "gimage/uniform_remesh.h"
#include "param/consistent_parameterization.h"
#include "param/errors.h"
#include "param/mesh_io.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/model_inputs.h"
#include "tools/progress.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace geomip::tools {
namespace {

struct RemeshArgs {
  ModelArgs common;
  int level = 0;
  bool ply = false;
};

int run_remesh(const RemeshArgs& args) {
  if (args.level < 0 || args.level > kMaxGeometryImageLevel) {
    throw InvalidInput("--level " + std::to_string(args.level) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  const PreparedModels models =
      prepare_models(args.common.meshes, args.common.points, "geomip remesh", args.common.quiet || args.common.json);
  std::filesystem::create_directories(args.common.output);

  ParameterizationOptions options;
  options.measure_mvc_baseline = false;
  ProgressBar bar("remesh", !args.common.quiet && !args.common.json);
  options.progress = bar.callback();
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> result = parameterize_consistently(models.inputs, options);
  const double param_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bar.finish();

  nlohmann::json summary = nlohmann::json::array();
  for (std::size_t i = 0; i < result.size(); ++i) {
    t0 = std::chrono::steady_clock::now();
    ResampleOptions resample;
    resample.normals = false;
    const UniformRemeshResult remesh =
        uniform_remesh(resample_geometry(result[i], args.level, resample), args.level);
    const double remesh_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string stem = (std::filesystem::path(args.common.output) / models.inputs[i].name).string() + ".M" +
                             std::to_string(args.level);
    write_file_atomically(stem + ".obj",
                          [&](std::ostream& out) { write_mesh(remesh.mesh, out, MeshFormat::kObj); });
    if (args.ply) {
      write_file_atomically(stem + ".ply",
                            [&](std::ostream& out) { write_mesh(remesh.mesh, out, MeshFormat::kPly); });
    }
    if (args.common.json) {
      nlohmann::json j{{"mesh", models.paths[i]},
                       {"obj", stem + ".obj"},
                       {"level", args.level},
                       {"vertices", remesh.mesh.positions.size()},
                       {"faces", remesh.mesh.triangles.size()},
                       {"remesh_seconds", remesh_seconds}};
      if (args.ply) j["ply"] = stem + ".ply";
      summary.push_back(j);
    } else if (!args.common.quiet) {
      std::printf("remesh %s → %s.obj: %zu vertices, %zu faces (resampled and remeshed in %.3f s)\n",
                  models.paths[i].c_str(), stem.c_str(), remesh.mesh.positions.size(),
                  remesh.mesh.triangles.size(), remesh_seconds);
    }
  }
  if (args.common.json) {
    std::cout << nlohmann::json{{"models", summary}, {"param_seconds", param_seconds}}.dump(2) << "\n";
  } else if (!args.common.quiet) {
    std::printf("parameterization %.2f s\n", param_seconds);
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_remesh_command(CLI::App& app) {
  auto args = std::make_shared<RemeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "remesh",
      "Uniform consistent remeshing (paper §4): parameterize as `geomip param`, resample every patch on its "
      "level-K grid and triangulate it, seams welded: DIR/<stem>.M<K>.obj, watertight and oriented, with one "
      "face "
      "list for all models of a consistent set.");
  add_model_options(cmd, args->common);
  cmd->add_option("--level", args->level, "Level K in [0, 10]: (2^K)² quads per patch")->required();
  cmd->add_flag("--ply", args->ply, "Also write DIR/<stem>.M<K>.ply (binary)");
  return [args] { return run_remesh(*args); };
}

}  // namespace geomip::tools
