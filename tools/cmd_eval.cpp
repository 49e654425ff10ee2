// geomip eval ORIGINAL APPROX [--json]: Metro-style surface distance, symmetric Hausdorff/RMS and PSNR.
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/error_map.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace geomip::tools {
namespace {

struct EvalArgs {
  std::string original;
  std::string approx;
  SurfaceDistanceOptions options;
  bool no_vertices = false;
  bool json = false;
  bool quiet = false;
  std::string error_map;           // APPROX coloured by its distance to ORIGINAL
  std::string error_map_original;  // ORIGINAL coloured by its distance to APPROX
  double error_map_scale_pct = 0;  // full red, % of the diagonal; 0 = the 99th percentile of the face RMS
};

nlohmann::json one_sided_to_json(const OneSidedDistance& d) {
  return {{"max", d.max},
          {"mean", d.mean},
          {"rms", d.rms},
          {"samples", d.samples()},
          {"vertex_samples", d.vertex_samples},
          {"edge_samples", d.edge_samples},
          {"face_samples", d.face_samples},
          {"max_at", {d.max_at.x(), d.max_at.y(), d.max_at.z()}}};
}

/// The 99th percentile of the finite face RMS values of the maps (0 when there are none).
double percentile_99(const std::vector<const OneSidedDistance*>& maps) {
  std::vector<float> values;
  for (const OneSidedDistance* m : maps) {
    for (float e : m->face_rms) {
      if (std::isfinite(e)) values.push_back(e);
    }
  }
  if (values.empty()) return 0;
  const std::size_t k = std::min(values.size() - 1, values.size() * 99 / 100);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

template <typename... T>
std::string format(const char* fmt, T... values) {
  char buffer[200];
  std::snprintf(buffer, sizeof buffer, fmt, values...);
  return buffer;
}

int run_eval(EvalArgs args) {
  args.options.sample_vertices = !args.no_vertices;
  args.options.error_maps = !args.error_map.empty() || !args.error_map_original.empty();
  if (!args.error_map.empty() && !args.error_map_original.empty() &&
      std::filesystem::weakly_canonical(args.error_map) ==
          std::filesystem::weakly_canonical(args.error_map_original))
    throw InvalidInput("--error-map and --error-map-original are both " + args.error_map +
                       ": one map would overwrite the other");
  note_input_file(args.original);
  note_input_file(args.approx);
  for (const std::string* path : {&args.error_map, &args.error_map_original}) {
    if (path->empty()) continue;
    check_output_file(*path);  // a directory is named as one before its missing extension
    if (mesh_format_from_path(*path) != MeshFormat::kPly)
      throw InvalidInput(*path + ": an error map is written as PLY (.ply)");
  }
  const TriMesh original = read_mesh(args.original);
  const TriMesh approx = read_mesh(args.approx);
  const auto start = std::chrono::steady_clock::now();
  SurfaceDistance d;
  try {
    d = measure_surface_distance(original, approx, args.options);
  } catch (const InvalidInput& e) {  // name the files: the library only knows "original" and "approx"
    throw InvalidInput(args.original + " vs " + args.approx + ": " + e.what());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool finite_psnr = std::isfinite(d.psnr_db);

  double scale = 0;  // error-map colour scale, in the meshes' units
  if (args.options.error_maps) {
    std::vector<const OneSidedDistance*> maps;
    if (!args.error_map.empty()) maps.push_back(&d.approx_to_original);
    if (!args.error_map_original.empty()) maps.push_back(&d.original_to_approx);
    scale =
        args.error_map_scale_pct > 0 ? args.error_map_scale_pct / 100 * d.bbox_diagonal : percentile_99(maps);
    if (!(scale > 0)) scale = d.bbox_diagonal * 1e-6;  // coincident surfaces: everything blue
    ErrorMapOptions map_options;
    map_options.scale = scale;
    map_options.diagonal = d.bbox_diagonal;
    AtomicFileSet files;  // both maps or neither
    if (!args.error_map.empty()) {
      map_options.comment = args.approx + " (distance to " + args.original + ")";
      files.add(args.error_map,
                [&](std::ostream& out) { write_error_map(approx, d.approx_to_original, map_options, out); });
    }
    if (!args.error_map_original.empty()) {
      map_options.comment = args.original + " (distance to " + args.approx + ")";
      files.add(args.error_map_original, [&](std::ostream& out) {
        write_error_map(original, d.original_to_approx, map_options, out);
      });
    }
    files.commit();
  }

  if (args.json) {
    nlohmann::json j;
    j["original"] = args.original;
    j["approx"] = args.approx;
    j["bbox_diagonal"] = d.bbox_diagonal;
    j["hausdorff"] = d.hausdorff;
    j["rms"] = d.rms;
    j["hausdorff_pct"] = d.hausdorff_pct;
    j["rms_pct"] = d.rms_pct;
    j["psnr_db"] = finite_psnr ? nlohmann::json(d.psnr_db) : nlohmann::json(nullptr);  // null: +infinity
    j["original_to_approx"] = one_sided_to_json(d.original_to_approx);
    j["approx_to_original"] = one_sided_to_json(d.approx_to_original);
    if (args.options.error_maps) j["error_map_scale_pct"] = 100 * scale / d.bbox_diagonal;
    j["seed"] = args.options.seed;
    j["seconds"] = seconds;
    std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return kExitOk;
  }
  if (args.quiet) return kExitOk;  // the error maps are written; nothing to say
  auto row = [&](const char* name, const OneSidedDistance& s) {
    std::cout << format("%s  %8zu samples  max %.6g  mean %.6g  rms %.6g  (max at %.6g %.6g %.6g)\n", name,
                        s.samples(), s.max, s.mean, s.rms, s.max_at.x(), s.max_at.y(), s.max_at.z());
  };
  std::cout << "original " << args.original << " (" << original.num_triangles() << " faces), approx "
            << args.approx << " (" << approx.num_triangles() << " faces)\n"
            << format("bounding-box diagonal of original: %.6g\n", d.bbox_diagonal);
  row("original -> approx", d.original_to_approx);
  row("approx -> original", d.approx_to_original);
  std::cout << format("symmetric Hausdorff: %.6g (%.4f%% of diagonal)\n", d.hausdorff, d.hausdorff_pct)
            << format("symmetric RMS:       %.6g (%.4f%% of diagonal)\n", d.rms, d.rms_pct)
            << (finite_psnr ? format("PSNR: %.2f dB\n", d.psnr_db) : std::string("PSNR: inf dB\n"))
            << format("time: %.2f s\n", seconds);
  if (args.options.error_maps) {
    std::cout << format("error map colour scale: red = %.4f%% of diagonal", 100 * scale / d.bbox_diagonal);
    if (!args.error_map.empty()) std::cout << "; " << args.error_map;
    if (!args.error_map_original.empty()) std::cout << "; " << args.error_map_original;
    std::cout << "\n";
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Metro-style surface distance between ORIGINAL and APPROX: both sampled (vertices + area-uniform face "
      "samples), exact closest-point distances both ways; symmetric Hausdorff and RMS in % of ORIGINAL's "
      "bounding-box diagonal, PSNR = 20·log10(diagonal / RMS) (inf for identical surfaces; JSON null)");
  cmd->add_option("original", args->original, "Reference mesh: .obj .ply .off .stl .gltf .glb")->required();
  cmd->add_option("approx", args->approx, "Approximating mesh, same coordinate frame")->required();
  // Bounded: each sample is a closest-point query and 56 bytes, so 10^8 is minutes and ~6 GB already.
  cmd->add_option("--samples", args->options.face_samples,
                  "Area-uniform face samples on each surface, in [1, 10^8] (default: 10 per face, 10k..1M)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000000}));
  cmd->add_option("--edge-samples", args->options.edge_samples,
                  "Samples spaced by length along each surface's edges, in [0, 10^8] (default 0)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{100000000}));
  cmd->add_flag("--no-vertices", args->no_vertices, "Do not sample the meshes' vertices");
  cmd->add_option("--seed", args->options.seed, "Seed of the random face samples (same seed, same result)");
  cmd->add_option("--threads", args->options.threads, "Worker threads (default: all cores)");
  cmd->add_option("--error-map", args->error_map,
                  "Write APPROX as PLY coloured by its distance to ORIGINAL (per face: RMS of its samples; "
                  "quality = % of diagonal) for MeshLab or Blender");
  cmd->add_option("--error-map-original", args->error_map_original,
                  "Write ORIGINAL as PLY coloured by its distance to APPROX");
  cmd->add_option("--error-map-scale", args->error_map_scale_pct,
                  "Distance shown as red, in % of the diagonal (default: the 99th percentile of face RMS)")
      ->check(positive_number());
  cmd->add_flag("--json", args->json,
                "Machine-readable output: hausdorff_pct, rms_pct, psnr_db (null = +inf), raw values, "
                "per-direction max/mean/rms and sample counts, bbox_diagonal");
  cmd->add_flag("-q,--quiet", args->quiet,
                "No report (--error-map files are still written; --json still prints)");
  return [args] { return run_eval(*args); };
}

}  // namespace geomip::tools
