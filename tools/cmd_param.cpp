// geomip param MESH... -o DIR [--points CORR.json]: consistent parameterization (paper §3), written as
// DIR/<stem>.param.obj (per-patch texture coordinates) and DIR/<stem>.param.json (layout and figures).
#include "mesh/errors.h"
#include "param/consistent_parameterization.h"
#include "param/unit_square.h"
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
#include <limits>
#include <memory>

namespace geomip::tools {
namespace {

struct ParamArgs {
  ModelArgs common;
  bool no_baseline = false;
  unsigned threads = 0;  // 0 = one per hardware thread
};

nlohmann::json stretch_json(const StretchValues& s) { return {{"l2", s.l2}, {"linf", s.linf}}; }

void write_param_obj(std::ostream& out, const ModelParameterization& m, const std::string& name) {
  out << "# geomip consistent parameterization of " << name << "\n"
      << "# " << m.patches.size() << " patches; v: the (repaired) mesh's vertices in order";
  if (m.split_vertices) out << ", the last " << m.split_vertices << " added by the partition";
  out << "; vt: per-patch (u,v) in the unit square\n";
  char line[128];
  for (const auto& p : m.mesh.positions) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    out << line;
  }
  std::size_t vt_base = 1;
  for (std::size_t k = 0; k < m.patches.size(); ++k) {
    const auto& patch = m.patches[k];
    out << "g patch" << k << "\n";
    for (const auto& uv : patch.uv) {
      std::snprintf(line, sizeof line, "vt %.17g %.17g\n", uv.x(), uv.y());
      out << line;
    }
    for (const auto& t : patch.triangles) {
      out << "f";
      for (int c : t) out << ' ' << patch.vertices[c] + 1 << '/' << vt_base + c;
      out << "\n";
    }
    vt_base += patch.uv.size();
  }
}

nlohmann::json param_json(const ModelParameterization& m, const std::string& mesh_path,
                          const ParameterizationInput& in) {
  const std::vector<int>& partition_points = in.partition_points;
  nlohmann::json j;
  j["mesh"] = mesh_path;
  j["vertices"] = m.mesh.positions.size();
  j["triangles"] = m.mesh.triangles.size();
  j["split_vertices"] = m.split_vertices;
  j["partition_points"] = partition_points;
  j["auxiliary_points"] = in.auxiliary_points;
  if (!in.side_guides.empty()) j["side_guides"] = in.side_guides;  // a loop through the tips (as CORR.json)
  const auto& kCorner = unit_square_corners();
  nlohmann::json patches = nlohmann::json::array();
  std::size_t flipped = 0;
  double smallest = std::numeric_limits<double>::infinity(), largest = 0.0;
  for (std::size_t k = 0; k < m.patches.size(); ++k) {
    const auto& p = m.patches[k];
    nlohmann::json corners = nlohmann::json::array();
    for (int c = 0; c < 4; ++c) corners.push_back({{"vertex", p.corners[c]}, {"u", kCorner[c].x()}, {"v", kCorner[c].y()}});
    nlohmann::json sides = nlohmann::json::array();
    for (int s = 0; s < 4; ++s) sides.push_back(p.sides[s]);
    patches.push_back({{"patch", k},
                       {"vertices", p.vertices.size()},
                       {"triangles", p.triangles.size()},
                       {"base_vertices", p.base_vertices},
                       {"corners", corners},
                       {"sides", sides},
                       {"stretch_mvc", stretch_json(p.mvc_stretch)},
                       {"stretch", stretch_json(p.stretch)},
                       {"flipped", p.flipped},
                       {"boundary_off_chord", p.boundary_off_chord},
                       {"mvc_fallback", p.mvc_fallback}});
    double area = 0.0;  // of the patch's surface, in the mesh's units
    for (const auto& t : p.triangles) {
      const auto& a = m.mesh.positions[p.vertices[t[0]]];
      area += 0.5 * (m.mesh.positions[p.vertices[t[1]]] - a).cross(m.mesh.positions[p.vertices[t[2]]] - a).norm();
    }
    patches.back()["area"] = area;
    smallest = std::min(smallest, area);
    largest = std::max(largest, area);
    flipped += p.flipped;
  }
  j["patches"] = patches;
  j["area_balance"] = largest > 0 ? smallest / largest : 0.0;  // smallest / largest patch area
  nlohmann::json adjacency = nlohmann::json::array();
  for (const auto& a : m.adjacency) {
    adjacency.push_back({{"patch", a.patch},
                         {"side", a.side},
                         {"other_patch", a.other_patch},
                         {"other_side", a.other_side},
                         {"reversed", a.reversed}});
  }
  j["adjacency"] = adjacency;
  nlohmann::json features = nlohmann::json::array();
  for (const auto& f : m.features) features.push_back({{"vertex", f.vertex}, {"patch", f.patch}, {"u", f.uv.x()}, {"v", f.uv.y()}});
  j["features"] = features;
  j["flipped_triangles"] = flipped;
  j["warp_events"] = m.warp_events;
  j["seam_mismatches"] = m.seam_mismatches;
  const StageSeconds& s = m.seconds;
  j["seconds"] = {{"partition", s.partition},
                  {"progressive_mesh", s.progressive_mesh},
                  {"base_embedding", s.base_embedding},
                  {"feature_warp", s.feature_warp},
                  {"coarse_to_fine", s.coarse_to_fine},
                  {"final_optimization", s.final_optimization},
                  {"mvc_baseline", s.mvc_baseline}};
  return j;
}

int run_param(const ParamArgs& args) {
  check_output_directory(args.common.output);  // before the work, not after it
  const PreparedModels models =
      prepare_models(args.common.meshes, args.common.points, "geomip param",
                     args.common.quiet || args.common.json, args.common.patches, loop_kind(args.common),
                     args.common.equal_area_layout, args.common.layout_error_weights);
  const std::vector<ParameterizationInput>& inputs = models.inputs;
  const std::vector<std::string>& paths = models.paths;
  {
    std::vector<std::string> planned;  // the files written below, checked before the work
    for (const auto& input : inputs) {
      const std::string stem = (std::filesystem::path(args.common.output) / input.name).string();
      planned.push_back(stem + ".param.obj");
      planned.push_back(stem + ".param.json");
    }
    check_planned_outputs(args.common.output, planned);
  }

  ParameterizationOptions options;
  apply_sampling(args.common, options);
  options.measure_mvc_baseline = !args.no_baseline;
  options.threads = args.threads;
  ProgressBar bar("param", !args.common.quiet && !args.common.json);
  options.progress = bar.callback();
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<ModelParameterization> result = parameterize_consistently(inputs, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bar.finish();

  // Only now: a failed run leaves no (empty) output directory behind.
  const CreatedDirectories created = make_output_directory(args.common.output);
  nlohmann::json summary = nlohmann::json::array();
  // Every model's .param.obj and .param.json or none: a file that cannot be written leaves no other behind.
  AtomicFileSet files;
  std::string report;  // printed once the files are in place
  for (std::size_t i = 0; i < result.size(); ++i) {
    const std::string stem = (std::filesystem::path(args.common.output) / inputs[i].name).string();
    files.add(stem + ".param.obj", [&](std::ostream& out) { write_param_obj(out, result[i], paths[i]); });
    nlohmann::json j = param_json(result[i], paths[i], inputs[i]);
    if (!inputs[i].layout_quads.empty()) j["layout_quads"] = inputs[i].layout_quads;  // corners: partition_points
    j["seconds"]["total_all_models"] = seconds;
    files.add(stem + ".param.json", [&](std::ostream& out) {
      out << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    });
    if (args.common.json) {
      summary.push_back({{"mesh", paths[i]}, {"obj", stem + ".param.obj"}, {"json", stem + ".param.json"},
                         {"patches", j["patches"].size()}, {"flipped_triangles", j["flipped_triangles"]}});
    } else if (!args.common.quiet) {
      report += "param " + paths[i] + " → " + stem + ".param.obj\n";
      for (const auto& p : result[i].patches) {
        report += string_printf("  patch: %zu vertices, L2 stretch %.4f, Linf %.3f", p.vertices.size(),
                                p.stretch.l2, p.stretch.linf);
        if (p.mvc_stretch.l2 > 0)
          report += string_printf(" (MVC: %.4f, %.3f)", p.mvc_stretch.l2, p.mvc_stretch.linf);
        report += string_printf(", %zu flipped%s\n", p.flipped, p.mvc_fallback ? ", optimized MVC kept" : "");
      }
    }
  }
  files.commit();
  std::cout << report;
  if (args.common.json) {
    std::cout << nlohmann::json{{"models", summary}, {"seconds", seconds}}.dump(
                     2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  } else if (!args.common.quiet) {
    std::printf("%.2f s\n", seconds);
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_param_command(CLI::App& app) {
  auto args = std::make_shared<ParamArgs>();
  CLI::App* cmd = app.add_subcommand(
      "param",
      "Consistent parameterization (paper §3): partition into quad patches, progressive mesh, mean-value "
      "embedding, stretch optimization, feature alignment, coarse-to-fine. Writes DIR/<stem>.param.obj and "
      "DIR/<stem>.param.json per model. Open or non-manifold meshes are repaired first.");
  add_model_options(cmd, args->common);
  cmd->add_flag("--no-baseline", args->no_baseline, "Skip the full-patch MVC embedding used as stretch baseline");
  cmd->add_option("--threads", args->threads,
                  "Threads over the patches (default 0: all cores); the output is the same for any count")
      ->check(CLI::Range(0u, 256u));
  return [args] { return run_param(*args); };
}

}  // namespace geomip::tools
