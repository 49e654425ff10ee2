// geomip repair IN -o OUT: make a scanned mesh closed, manifold and clean, ready for parameterization.
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/model_inputs.h"
#include "tools/progress.h"
#include "tools/report.h"

#include <iostream>
#include <memory>
#include <sstream>

namespace geomip::tools {
namespace {

struct RepairArgs {
  std::string input;
  std::string output;
  bool no_fill = false;
  bool largest_component = false;
  bool ascii = false;
  bool json = false;
  bool quiet = false;
};

std::string summary(const RepairResult& r) {
  std::ostringstream s;
  auto item = [&](std::size_t n, const char* what) {
    if (n) s << (s.tellp() > 0 ? ", " : "") << what << " " << n;
  };
  if (r.removed_components) {
    s << "dropped " << r.removed_components << " smaller component" << (r.removed_components > 1 ? "s" : "")
      << " (" << r.removed_component_faces << " faces)";
  }
  item(r.removed_unreferenced_vertices, "removed unreferenced vertices:");
  item(r.merged_duplicate_vertices, "merged duplicate vertices:");
  item(r.removed_degenerate_faces, "removed degenerate/duplicate faces:");
  item(r.split_non_manifold_vertices, "split non-manifold vertices:");
  item(r.filled_holes, "filled holes:");
  item(r.added_vertices, "added vertices:");
  item(r.unfaired_holes, "holes left unfaired:");
  if (r.reoriented) s << (s.tellp() > 0 ? ", " : "") << "flipped all faces to point outward";
  return s.tellp() > 0 ? s.str() : "nothing to repair";
}

int run_repair(const RepairArgs& args) {
  note_input_file(args.input);
  check_output_file(args.output);
  MeshFormat out_format = MeshFormat::kObj;
  try {
    out_format = mesh_format_from_path(args.output);  // fail before the work
  } catch (const InvalidInput&) {  // its message lists the formats geomip reads, STL among them
    throw InvalidInput(args.output + ": not a mesh format geomip writes (.obj, .ply, .off, .gltf or .glb)");
  }
  if (out_format == MeshFormat::kStl) {
    std::cerr << "geomip repair: " << args.output
              << ": STL output is not supported (use .obj, .ply, .off, .gltf or .glb)\n";
    return kExitBadInput;
  }
  const TriMesh input = read_mesh(args.input);
  const TopologyReport before = analyze_topology(input);

  RepairOptions options;
  options.fill_holes = !args.no_fill;
  options.largest_component_only = args.largest_component;
  ProgressBar bar("repair", !args.quiet && !args.json);
  options.progress = bar.callback();
  const RepairResult result = repair_named(args.input, input, options);
  bar.finish();
  if (result.mesh.triangles.empty())
    throw InvalidInput(args.input + ": no face is left after repair (each one degenerate or removed)");
  const TopologyReport after = analyze_topology(result.mesh);

  WriteMeshOptions write_options;
  write_options.binary = !args.ascii;
  write_file_atomically(args.output, [&](std::ostream& out) {
    write_mesh(result.mesh, out, out_format, write_options);
  });

  if (args.json) {
    nlohmann::json j;
    j["input"] = args.input;
    j["output"] = args.output;
    j["before"] = topology_to_json(before);
    j["after"] = topology_to_json(after);
    j["removed_unreferenced_vertices"] = result.removed_unreferenced_vertices;
    j["merged_duplicate_vertices"] = result.merged_duplicate_vertices;
    j["removed_degenerate_faces"] = result.removed_degenerate_faces;
    j["split_non_manifold_vertices"] = result.split_non_manifold_vertices;
    j["filled_holes"] = result.filled_holes;
    j["unfaired_holes"] = result.unfaired_holes;
    j["added_vertices"] = result.added_vertices;
    j["reoriented"] = result.reoriented;
    j["removed_components"] = result.removed_components;
    j["removed_component_faces"] = result.removed_component_faces;
    std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else if (!args.quiet) {
    std::cout << "repair " << args.input << ": " << summary(result) << "\n"
              << "wrote " << args.output << ": " << after.vertices << " vertices, " << after.faces << " faces, "
              << after.boundary_loops << " boundary loops, genus "
              << (after.genus ? std::to_string(*after.genus) : std::string("undefined")) << ", "
              << (after.manifold ? "manifold" : "NOT manifold") << "\n";
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_repair_command(CLI::App& app) {
  auto args = std::make_shared<RepairArgs>();
  CLI::App* cmd = app.add_subcommand(
      "repair",
      "Make a scanned mesh ready for parameterization: drop unreferenced/duplicate vertices and degenerate faces, "
      "split non-manifold vertices, fill holes (CGAL triangulate+refine+fair), orient outward. Original vertices "
      "keep their positions and order; new vertices are appended. OUT is written atomically.");
  cmd->add_option("input", args->input, "Input mesh (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_option("-o,--output", args->output, "Output mesh (.obj .ply .off .gltf .glb)")->required();
  cmd->add_flag("--no-fill", args->no_fill, "Do not fill holes");
  cmd->add_flag("--largest-component", args->largest_component,
                "Keep only the largest connected component (by face count) and drop the others, then repair: "
                "param/convert take one connected surface per mesh");
  cmd->add_flag("--ascii", args->ascii, "Write PLY as ascii (default: binary little-endian)");
  cmd->add_flag("--json", args->json, "Machine-readable report on stdout");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress bar, no report");
  return [args] { return run_repair(*args); };
}

}  // namespace geomip::tools
