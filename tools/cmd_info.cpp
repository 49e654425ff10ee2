// geomip info MESH|PACK... [--json]: topology and size of mesh files, counted on the triangles as read; for a
// .gip pack, its models (levels, the viewer's frame) and chunk table (what a viewer receives, in order).
#include "codec/pack.h"
#include "codec/status.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tools/commands.h"
#include "tools/pack_file.h"
#include "tools/report.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace geomip::tools {
namespace {

struct InfoArgs {
  std::vector<std::string> meshes;
  bool json = false;
  bool self_intersections = false;
};

const char* kind_name(codec::ChunkKind kind) {
  switch (kind) {
    case codec::ChunkKind::kGeometry: return "geometry";
    case codec::ChunkKind::kNormals: return "normals";
    case codec::ChunkKind::kHoleMask: return "hole_mask";
  }
  return "unknown";
}

bool is_pack(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gip";
}

// A model axis as "+x" … "-z" when `row` (a row of a normalization's linear part) has one non-zero entry,
// else its unit direction as "(x, y, z)" (3 decimals).
std::string axis_name(const double* row) {
  const double norm = std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
  for (int c = 0; c < 3; ++c)
    if (row[c] != 0 && row[(c + 1) % 3] == 0 && row[(c + 2) % 3] == 0)
      return std::string(row[c] > 0 ? "+" : "-") + static_cast<char>('x' + c);
  char text[64];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", norm > 0 ? row[0] / norm : 0.0,
                norm > 0 ? row[1] / norm : 0.0, norm > 0 ? row[2] / norm : 0.0);
  return text;
}

// The viewer's frame stored in a model's normalization (mesh/view_frame.h, `geomip convert --up, --front`):
// the model axes shown as up (+y, row 1), front (+x, row 0: what --front names; a lying animal's head) and
// camera side (+z, row 2: the side the default camera looks at, turned towards +x; an upright shape's face);
// all "none" when the normalization is the identity or all zero (no frame stored: the viewer fits the decoded
// box, y up).
void add_view_frame(const std::array<double, 16>& n, nlohmann::json& model) {
  const std::array<double, 16> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const bool none = n == identity || n == std::array<double, 16>{};
  model["up"] = none ? "none" : axis_name(&n[4]);
  model["front"] = none ? "none" : axis_name(&n[0]);
  model["camera_side"] = none ? "none" : axis_name(&n[8]);
}

// The pack's header and manifest as JSON: per model its grids and streams, then every chunk in file order with
// the byte count a reader has once that chunk is complete ("cumulative").
nlohmann::json pack_info(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_pack_file(path);
  codec::PackInfo info;
  const codec::Status status = codec::read_pack_info(bytes, info);
  if (status != codec::Status::kOk) {
    throw InvalidInput(path + ": not a readable geomip pack (" + std::string(codec::status_message(status)) + ")");
  }
  nlohmann::json j;
  j["file"] = path;
  j["format_version"] = info.version;
  j["bytes"] = bytes.size();
  j["manifest_bytes"] = info.manifest_end;
  if (info.file_size() != bytes.size()) j["bytes_laid_out"] = info.file_size();
  nlohmann::json models = nlohmann::json::array();
  for (const auto& m : info.models) {
    nlohmann::json mj;
    mj["name"] = m.name;
    mj["level"] = m.geometry.level;
    mj["patches"] = m.geometry.num_patches;
    mj["geometry_passes"] = m.geometry.top_bitplane - m.geometry.bottom_bitplane + 1;
    mj["normals"] = m.has_normals;
    if (m.has_normals) {
      mj["normal_level"] = m.normals.level;
      mj["normal_layers"] = m.normal_layers;
      mj["normal_passes"] = m.normal_passes();
      if (m.normal_layers == 2) mj["normal_base_passes"] = m.normal_base_passes;
    }
    mj["hole_mask"] = !m.hole_mask.empty();
    add_view_frame(m.normalization, mj);
    models.push_back(std::move(mj));
  }
  nlohmann::json chunks = nlohmann::json::array();
  std::vector<std::uint64_t> first_level(info.models.size(), 0);
  for (const auto& c : info.chunks) {
    const std::uint64_t end = c.offset + c.size;
    chunks.push_back({{"model", c.model}, {"kind", kind_name(c.kind)}, {"pass", c.pass}, {"bytes", c.size},
                      {"cumulative", end}});
    if (c.kind == codec::ChunkKind::kGeometry && c.pass == 0 && c.model >= 0 &&
        static_cast<std::size_t>(c.model) < first_level.size())
      first_level[c.model] = end;
  }
  std::uint64_t first = info.manifest_end;
  for (std::uint64_t e : first_level) first = std::max(first, e);
  j["first_level_bytes"] = first;  // every model's first geometry pass: the coarsest model a viewer can show
  j["models"] = std::move(models);
  j["chunks"] = std::move(chunks);
  return j;
}

void print_pack(const nlohmann::json& j) {
  std::printf(
      "%s: geomip pack, format %d, %llu bytes (header and manifest %llu), first level of detail after %llu "
      "bytes\n",
      j["file"].get<std::string>().c_str(), j["format_version"].get<int>(),
      static_cast<unsigned long long>(j["bytes"].get<std::uint64_t>()),
      static_cast<unsigned long long>(j["manifest_bytes"].get<std::uint64_t>()),
      static_cast<unsigned long long>(j["first_level_bytes"].get<std::uint64_t>()));
  if (j.contains("bytes_laid_out")) {
    const auto laid_out = j["bytes_laid_out"].get<std::uint64_t>(), have = j["bytes"].get<std::uint64_t>();
    std::printf(
        laid_out > have
            ? "  truncated: the manifest lays out %llu bytes; the chunks past byte %llu are missing\n"
            : "  the manifest lays out %llu bytes; the %llu bytes past them are not part of the pack\n",
        static_cast<unsigned long long>(laid_out),
        static_cast<unsigned long long>(laid_out > have ? have : have - laid_out));
  }
  for (std::size_t m = 0; m < j["models"].size(); ++m) {
    const auto& mj = j["models"][m];
    const std::string up = mj["up"].get<std::string>();
    const std::string frame = up == "none" ? "frame none"
                                           : "up " + up + ", front " + mj["front"].get<std::string>() +
                                                 ", camera side " + mj["camera_side"].get<std::string>();
    std::string normals;
    if (mj["normals"].get<bool>()) {
      normals = ", normal maps";
      if (mj["normal_layers"].get<int>() == 2)
        normals += " in two layers (passes 0-" + std::to_string(mj["normal_base_passes"].get<int>() - 1) +
                   " the first)";
    }
    std::printf("  model %zu '%s': %d patches of (2^%d+1)^2 samples, %d geometry passes%s%s; %s\n", m,
                codec::one_line(mj["name"].get<std::string>()).c_str(), mj["patches"].get<int>(),
                mj["level"].get<int>(), mj["geometry_passes"].get<int>(), normals.c_str(),
                mj["hole_mask"].get<bool>() ? ", hole mask" : "", frame.c_str());
  }
  std::printf("  chunks (file order): model kind pass bytes -> cumulative\n");
  for (const auto& c : j["chunks"]) {
    std::printf("    %d %-9s %2d %9llu -> %llu\n", c["model"].get<int>(), c["kind"].get<std::string>().c_str(),
                c["pass"].get<int>(), static_cast<unsigned long long>(c["bytes"].get<std::uint64_t>()),
                static_cast<unsigned long long>(c["cumulative"].get<std::uint64_t>()));
  }
}

int run_info(const InfoArgs& args) {
  // Checked before any output: a pack holds coefficients, not triangles, and which triangles cross depends
  // on how it is decoded (prefix, level, untangling).
  if (args.self_intersections) {
    for (const auto& path : args.meshes) {
      if (is_pack(path))
        throw InvalidInput("--self-intersections counts the triangles of a mesh, and " + path +
                           " is a pack: decode it first (geomip decode PACK -o MESH.obj, then geomip info "
                           "--self-intersections MESH.obj)");
    }
  }
  nlohmann::json all = nlohmann::json::array();
  for (const auto& path : args.meshes) {
    if (is_pack(path)) {
      nlohmann::json j = pack_info(path);
      if (!args.json) print_pack(j);
      all.push_back(std::move(j));
      continue;
    }
    const TriMesh mesh = read_mesh(path);
    const TopologyReport report = analyze_topology(mesh);
    std::optional<SelfIntersections> crossings;
    if (args.self_intersections) crossings = count_self_intersections(mesh);
    if (args.json) {
      nlohmann::json j = topology_to_json(report);
      j["file"] = path;
      if (args.self_intersections)
        j["self_intersections"] =
            crossings ? nlohmann::json{{"pairs", crossings->pairs}, {"faces", crossings->faces}}
                      : nlohmann::json(nullptr);
      all.push_back(std::move(j));
    } else {
      std::cout << path << "\n" << topology_to_text(report);
      if (args.self_intersections) {
        if (crossings)
          std::printf("  self-intersections: %zu faces in %zu crossing pairs\n", crossings->faces,
                      crossings->pairs);
        else
          std::printf(
              "  self-intersections: not counted (not a manifold, consistently oriented mesh: geomip repair "
              "first)\n");
      }
    }
  }
  if (args.json)
    std::cout
        << (all.size() == 1 ? all[0] : all).dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
        << "\n";
  return kExitOk;
}

}  // namespace

CommandRunner add_info_command(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Report a mesh's topology: vertices, faces, components, boundary "
                                             "loops, genus, manifoldness, degeneracies, bounding box; or a .gip "
                                             "pack's models, levels, view frames (up and front axes) and chunk "
                                             "table");
  cmd->add_option("mesh", args->meshes, "Mesh file(s): .obj .ply .off .stl .gltf .glb, or packs: .gip")->required();
  cmd->add_flag("--json", args->json, "Machine-readable output (one object, or an array for several meshes)");
  cmd->add_flag(
      "--self-intersections", args->self_intersections,
      "Also count the triangles that cross other triangles of the mesh (CGAL, exact predicates; "
      "seconds on a million faces); JSON: self_intersections {pairs, faces}, null where the mesh is "
      "not manifold and oriented. Meshes only: a pack is refused (decode it first)");
  return [args] { return run_info(*args); };
}

}  // namespace geomip::tools
