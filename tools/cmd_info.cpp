// geomip info MESH... [--json]: topology and size of mesh files, counted on the triangles as read.
#include "mesh/mesh_io.h"
#include "mesh/mesh_topology.h"
#include "tools/commands.h"
#include "tools/report.h"

#include <iostream>
#include <memory>

namespace geomip::tools {
namespace {

struct InfoArgs {
  std::vector<std::string> meshes;
  bool json = false;
};

int run_info(const InfoArgs& args) {
  nlohmann::json all = nlohmann::json::array();
  for (const auto& path : args.meshes) {
    const TriMesh mesh = read_mesh(path);
    const TopologyReport report = analyze_topology(mesh);
    if (args.json) {
      nlohmann::json j = topology_to_json(report);
      j["file"] = path;
      all.push_back(std::move(j));
    } else {
      std::cout << path << "\n" << topology_to_text(report);
    }
  }
  if (args.json) std::cout << (all.size() == 1 ? all[0] : all).dump(2) << "\n";
  return kExitOk;
}

}  // namespace

CommandRunner add_info_command(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Report a mesh's topology: vertices, faces, components, boundary "
                                             "loops, genus, manifoldness, degeneracies, bounding box");
  cmd->add_option("mesh", args->meshes, "Mesh file(s): .obj .ply .off .stl")->required();
  cmd->add_flag("--json", args->json, "Machine-readable output (one object, or an array for several meshes)");
  return [args] { return run_info(*args); };
}

}  // namespace geomip::tools
