// geomip remesh MESH... [--points CORR.json] [--level K] [--adaptive EPS [--max-depth N]] -o DIR [--ply] [--glb [--draco[=BITS]]]:
// consistent parameterization (as `geomip param`), then the uniform level-K remesh of every model,
// DIR/<stem>.M<K>.obj (and .ply) (gimage/uniform_remesh.h), and/or the adaptive remesh
// DIR/<stem>.adaptive.obj (gimage/adaptive_remesh.h): watertight, consistently oriented, one face list for
// all models of a consistent set.
#include "gimage/adaptive_remesh.h"
#include "gimage/fit.h"
#include "gimage/resample.h"
#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh_io.h"
#include "param/consistent_parameterization.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/model_inputs.h"
#include "tools/pack_models.h"
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

struct RemeshArgs {
  ModelArgs common;
  int level = -1;        ///< -1: no uniform remesh
  double adaptive = -1;  ///< ε; < 0: no adaptive remesh
  int max_depth = 8;
  bool measure_samples = false;
  bool ply = false;
  bool glb = false;
  bool untangle = false;
  int draco = 0;  ///< the GLB's Draco position bits, 0 = no Draco
  bool fit = false;  ///< least-squares fitted samples (gimage/fit.h) for the uniform remesh
  std::string quad_split = "shorter";
};

int run_remesh(const RemeshArgs& args) {
  const bool uniform = args.level != -1 || args.adaptive < 0;
  const bool adaptive = args.adaptive >= 0;
  if (uniform && (args.level < 0 || args.level > kMaxGeometryImageLevel)) {
    throw InvalidInput(args.level == -1 ? std::string("give --level K and/or --adaptive EPS")
                                        : "--level " + std::to_string(args.level) + " is outside [0, " +
                                              std::to_string(kMaxGeometryImageLevel) + "]");
  }
  if (args.fit && !uniform) throw InvalidInput("--fit moves the uniform remesh's samples: give --level K too");
  if (args.draco != 0 && !args.glb) throw InvalidInput("--draco compresses the GLB: give --glb too");
  if (args.draco < 0 ||
      args.draco > 30)  // CLI11 reads --draco=0 as the flag's "off" (-1): say no number then
    throw InvalidInput((args.draco < 0 ? std::string("--draco") : "--draco=" + std::to_string(args.draco)) +
                       ": position bits must be in 1..30");
  if ((args.glb || args.ply) && !uniform)
    throw InvalidInput(
        std::string(args.glb ? "--glb" : "--ply") +
        " writes the uniform remesh: give --level K too (the adaptive remesh is written as OBJ)");
  if (adaptive && (args.max_depth < 0 || args.max_depth > kMaxGeometryImageLevel)) {
    throw InvalidInput("--max-depth " + std::to_string(args.max_depth) + " is outside [0, " +
                       std::to_string(kMaxGeometryImageLevel) + "]");
  }
  const PreparedModels models =
      prepare_models(args.common.meshes, args.common.points, "geomip remesh",
                     args.common.quiet || args.common.json, args.common.patches, loop_kind(args.common),
                     args.common.equal_area_layout, args.common.layout_error_weights);
  check_output_directory(args.common.output);
  {
    std::vector<std::string> planned;  // the files written below, checked before the work
    for (const auto& input : models.inputs) {
      const std::string base = (std::filesystem::path(args.common.output) / input.name).string();
      const std::string stem = base + ".M" + std::to_string(args.level);
      if (uniform) planned.push_back(stem + ".obj");
      if (uniform && args.ply) planned.push_back(stem + ".ply");
      if (uniform && args.glb) planned.push_back(stem + ".glb");
      if (adaptive) planned.push_back(base + ".adaptive.obj");
    }
    check_planned_outputs(args.common.output, planned);
  }
  // The remesh spans the input's bounding box: what Draco cannot quantize (--draco) is refused now.
  if (args.draco != 0) {
    for (std::size_t i = 0; i < models.inputs.size(); ++i)
      check_draco_positions(models.inputs[i].mesh.positions, models.paths[i]);
  }

  ParameterizationOptions options;
  apply_sampling(args.common, options);
  options.measure_mvc_baseline = false;
  ProgressBar bar("remesh", !args.common.quiet && !args.common.json);
  options.progress = bar.callback();
  auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> result = parameterize_consistently(models.inputs, options);
  const double param_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bar.finish();
  // Only now: a failed parameterization leaves no (empty) output directory behind.
  const CreatedDirectories created = make_output_directory(args.common.output);

  nlohmann::json summary = nlohmann::json::array();
  // Uniform: every model's images and remesh first, so that the models of a set choose the quad split
  // together (one face list), then the files.
  const QuadSplit split = args.quad_split == "fixed" ? QuadSplit::kFixed : QuadSplit::kShorter;
  std::vector<GeometryImages> uniform_images;
  std::vector<UniformRemeshResult> remeshes;
  std::vector<double> remesh_seconds_of, fit_seconds_of;
  for (std::size_t i = 0; i < result.size() && uniform; ++i) {
    t0 = std::chrono::steady_clock::now();
    ResampleOptions resample;
    resample.normals = args.glb;  // the GLB's normals come from the normal maps
    GeometryImages images = resample_geometry(result[i], args.level, resample);
    const double resample_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double fit_seconds = 0;
    if (args.fit) {
      t0 = std::chrono::steady_clock::now();
      FitOptions fit;
      fit.quad_split = split;
      fit.measure_after = false;
      images = fit_geometry_images(result[i].mesh, images, fit).images;
      fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    t0 = std::chrono::steady_clock::now();
    remeshes.push_back(uniform_remesh(images, args.level));
    remesh_seconds_of.push_back(resample_seconds +
                                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    fit_seconds_of.push_back(fit_seconds);
    uniform_images.push_back(std::move(images));
  }
  std::vector<const std::vector<Eigen::Vector3d>*> split_by;
  for (const auto& r : remeshes) split_by.push_back(&r.mesh.positions);
  if (split == QuadSplit::kShorter)
    for (auto& r : remeshes) split_along_shorter_diagonals(r, args.level, split_by);
  std::vector<UntangleStats> untangled(remeshes.size());
  std::vector<GeometryImages> as_resampled;  // with --untangle: the images as they were choose the split
  if (args.untangle) {
    // The split is chosen already (above); the GLB's and the untangling's choice come from the same images.
    as_resampled = uniform_images;
    std::vector<const GeometryImages*> choosers;
    for (const auto& g : as_resampled) choosers.push_back(&g);
    const int n = (1 << args.level) + 1;
    for (std::size_t i = 0; i < remeshes.size(); ++i) {
      untangled[i] = untangle_geometry_images(uniform_images[i], split, choosers);
      for (std::size_t p = 0; p < uniform_images[i].geometry.size(); ++p)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k) {
            const float* v = uniform_images[i].geometry[p].at(k, j);
            remeshes[i].mesh.positions[static_cast<std::size_t>(
                remeshes[i].grid_vertex[p][static_cast<std::size_t>(j) * n + k])] = {v[0], v[1], v[2]};
          }
    }
  }
  std::vector<const GeometryImages*> images_of_set;
  for (const auto& g : args.untangle ? as_resampled : uniform_images) images_of_set.push_back(&g);
  // Every file of the run or none: a .glb that cannot be written leaves no .obj or .ply of this run behind.
  AtomicFileSet files;
  std::string report;  // printed once the files are in place
  for (std::size_t i = 0; i < remeshes.size(); ++i) {
    const UniformRemeshResult& remesh = remeshes[i];
    const GeometryImages& images = uniform_images[i];
    const double remesh_seconds = remesh_seconds_of[i], fit_seconds = fit_seconds_of[i];
    const std::string stem = (std::filesystem::path(args.common.output) / models.inputs[i].name).string() +
                             ".M" + std::to_string(args.level);
    files.add(stem + ".obj", [&](std::ostream& out) { write_mesh(remesh.mesh, out, MeshFormat::kObj); });
    if (args.ply)
      files.add(stem + ".ply", [&](std::ostream& out) { write_mesh(remesh.mesh, out, MeshFormat::kPly); });
    if (args.glb) {
      const TexturedMesh textured = textured_mesh(images, split, images_of_set);
      files.add(stem + ".glb", [&](std::ostream& out) {
        write_gltf(textured.mesh, textured.attributes, out, {.binary = true, .draco_position_bits = args.draco});
      });
    }
    if (args.common.json) {
      nlohmann::json j{{"mesh", models.paths[i]},
                       {"obj", stem + ".obj"},
                       {"level", args.level},
                       {"vertices", remesh.mesh.positions.size()},
                       {"faces", remesh.mesh.triangles.size()},
                       {"remesh_seconds", remesh_seconds},
                       {"fit", args.fit}};
      if (args.fit) j["fit_seconds"] = fit_seconds;
      if (args.ply) j["ply"] = stem + ".ply";
      if (args.glb) j["glb"] = stem + ".glb";
      if (args.untangle)
        j["untangle"] = {{"folded_before", untangled[i].folded_before},
                         {"folded_after", untangled[i].folded_after},
                         {"moved", untangled[i].moved},
                         {"max_move", untangled[i].max_move}};
      summary.push_back(j);
    } else if (!args.common.quiet) {
      report += string_printf("remesh %s → %s.obj: %zu vertices, %zu faces (resampled and remeshed in %.3f s",
                              models.paths[i].c_str(), stem.c_str(), remesh.mesh.positions.size(),
                              remesh.mesh.triangles.size(), remesh_seconds);
      if (args.fit) report += string_printf(", fitted in %.3f s", fit_seconds);
      report += ")\n";
    }
  }
  double adaptive_tree_seconds = 0;  // resampling, quad errors and the shared tree, all models
  if (adaptive) {
    // One quadtree for the whole set: the maximum of the models' quad errors (eq. 6).
    t0 = std::chrono::steady_clock::now();
    ResampleOptions resample;
    resample.normals = false;
    std::vector<GeometryImages> images;
    std::vector<AdaptiveQuadErrors> errors;
    for (const auto& model : result) {
      images.push_back(resample_geometry(model, args.max_depth, resample));
      AdaptiveErrorOptions error_options;
      error_options.measure_samples = args.measure_samples;
      errors.push_back(adaptive_quad_errors(model, images.back(), error_options));
    }
    AdaptiveRemeshOptions tree_options;
    tree_options.epsilon = args.adaptive;
    const AdaptiveQuadtree tree = adaptive_quadtree(errors, images[0].adjacency, tree_options);
    const std::size_t leaves = tree.leaves().size();
    adaptive_tree_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (std::size_t i = 0; i < result.size(); ++i) {
      t0 = std::chrono::steady_clock::now();
      const TriMesh mesh = adaptive_remesh(images[i], tree);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const std::string path =
          (std::filesystem::path(args.common.output) / models.inputs[i].name).string() + ".adaptive.obj";
      files.add(path, [&](std::ostream& out) { write_mesh(mesh, out, MeshFormat::kObj); });
      if (args.common.json) {
        summary.push_back(nlohmann::json{{"mesh", models.paths[i]},
                                         {"obj", path},
                                         {"adaptive", args.adaptive},
                                         {"max_depth", args.max_depth},
                                         {"leaves", leaves},
                                         {"vertices", mesh.positions.size()},
                                         {"faces", mesh.triangles.size()},
                                         {"remesh_seconds", seconds}});
      } else if (!args.common.quiet) {
        report += string_printf(
            "remesh %s → %s: %zu vertices, %zu faces (eps %g, %zu leaves; triangulated in %.3f s)\n",
            models.paths[i].c_str(), path.c_str(), mesh.positions.size(), mesh.triangles.size(),
            args.adaptive, leaves, seconds);
      }
    }
  }
  files.commit();
  std::fputs(report.c_str(), stdout);
  if (args.common.json) {
    nlohmann::json j{{"models", summary}, {"param_seconds", param_seconds}};
    if (adaptive) j["adaptive_tree_seconds"] = adaptive_tree_seconds;
    std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else if (!args.common.quiet) {
    std::printf("parameterization %.2f s\n", param_seconds);
    if (adaptive) {
      std::printf("adaptive: resampling, quad errors and the shared quadtree %.3f s\n",
                  adaptive_tree_seconds);
    }
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_remesh_command(CLI::App& app) {
  auto args = std::make_shared<RemeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "remesh",
      "Consistent remeshing (paper §4): parameterize as `geomip param`, resample every patch on its level-K "
      "grid and triangulate it, seams welded: DIR/<stem>.M<K>.obj; and/or (--adaptive EPS) split a quadtree "
      "per "
      "patch until the plane-fit error is below EPS, restricted and crack-free: DIR/<stem>.adaptive.obj. "
      "Watertight and oriented, with one face list for all models of a consistent set.");
  add_model_options(cmd, args->common);
  cmd->add_option("--level", args->level, "Level K in [0, 10]: (2^K)² quads per patch")
      ->check(CLI::Range(0, kMaxGeometryImageLevel));
  cmd->add_option("--adaptive", args->adaptive,
                  "Adaptive remesh (paper §4, eq. 4-6) with error bound EPS (fraction of the bounding-box "
                  "diagonal): DIR/<stem>.adaptive.obj, one face list for a consistent set")
      ->check(non_negative_number());
  cmd->add_option("--max-depth", args->max_depth, "Adaptive: maximum quadtree depth N in [0, 10] (default 8)")
      ->needs("--adaptive");
  cmd->add_flag("--measure-samples", args->measure_samples,
                "Adaptive: measure each quad's geometry image samples too, not only the mesh vertices in it "
                "(stricter than the paper's eq. 4-5)")
      ->needs("--adaptive");
  cmd->add_flag("--fit,!--no-fit", args->fit,
                "Uniform remesh: move every sample along its normal so that the remesh is a least-squares fit of "
                "the surface, not its interpolant (gimage/fit.h; same faces, seams welded); --no-fit: samples on "
                "the surface (default)");
  cmd->add_option("--quad-split", args->quad_split,
                  "Uniform remesh: how grid quads become triangles: shorter (along the shorter diagonal, the "
                  "models of a set choosing together: one face list) or fixed (a rule of the layout alone, the "
                  "same for any shapes)")
      ->check(CLI::IsMember({"shorter", "fixed"}))
      ->capture_default_str();
  cmd->add_flag("--ply", args->ply, "Also write DIR/<stem>.M<K>.ply (binary)");
  cmd->add_flag(
      "--untangle", args->untangle,
      "Open the uniform remesh's folds as `geomip decode` does (samples of triangles that face against "
      "the surface around them slide along it; same faces): fewer self-intersecting triangles where "
      "the sampling is stretched. Off by default: the remesh stays the paper's");
  cmd->add_flag("--glb", args->glb,
                "Also write DIR/<stem>.M<K>.glb: glTF with each patch's (u,v) as TEXCOORD_0 and the normal "
                "maps' normals (seam vertices once per patch)");
  cmd->add_flag("--draco{14}", args->draco,
                "With --glb: compress it with Draco (KHR_draco_mesh_compression), positions quantized to BITS bits "
                "(--draco=BITS, 1..30; default 14), normals 10, texture coordinates 12");
  return [args] { return run_remesh(*args); };
}

}  // namespace geomip::tools
