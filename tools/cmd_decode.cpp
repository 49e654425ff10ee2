// geomip decode PACK [--bytes N] [--level K] [--draco[=BITS]] -o MESH: decodes a .gip pack (or only its first
// N bytes, as if only they had arrived) and writes each model as a mesh (glTF optionally Draco-compressed).
#include "codec/pack.h"
#include "codec/status.h"
#include "gimage/resample.h"
#include "mesh/errors.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh_io.h"
#include "mesh/view_frame.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/pack_file.h"
#include "tools/pack_models.h"
#include "tools/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>

namespace geomip::tools {
namespace {

struct DecodeArgs {
  std::string pack;
  std::string output;
  long long bytes = -1;
  int level = -1;
  int draco = 0;  // glTF output: Draco position bits, 0 = no Draco
  std::string quad_split = "shorter";
  bool untangle = true;
  bool json = false;
  bool quiet = false;
};

// Bytes up to the end of the first geometry chunk (pass 0) of every model: the shortest prefix from which
// each model decodes to a shape.
std::uint64_t first_level_bytes(const codec::PackInfo& info) {
  std::uint64_t end = info.manifest_end;
  std::vector<char> seen(info.models.size(), 0);
  for (const codec::ChunkInfo& chunk : info.chunks) {
    const auto m = static_cast<std::size_t>(chunk.model);
    if (chunk.kind != codec::ChunkKind::kGeometry || m >= seen.size() || seen[m]) continue;
    seen[m] = 1;
    end = std::max(end, chunk.offset + chunk.size);
  }
  return end;
}

MeshFormat format_of(const std::string& path) {
  try {
    const MeshFormat f = mesh_format_from_path(path);
    if (f != MeshFormat::kStl) return f;
  } catch (const InvalidInput&) {
  }
  throw InvalidInput("-o " + path + ": the extension must be .obj, .ply, .off, .gltf or .glb");
}

int run_decode(const DecodeArgs& args) {
  note_input_file(args.pack);  // so that no output of this run, under any name, replaces it
  check_output_file(args.output);
  const MeshFormat format = format_of(args.output);
  const bool gltf = format == MeshFormat::kGltf || format == MeshFormat::kGlb;
  if (args.draco != 0 && !gltf)
    throw InvalidInput("--draco compresses glTF output: -o must end in .glb or .gltf, not " + args.output);
  if (args.draco < 0 || args.draco > 30)
    throw InvalidInput((args.draco < 0 ? std::string("--draco") : "--draco=" + std::to_string(args.draco)) +
                       ": position bits must be in 1..30");
  const std::vector<std::uint8_t> bytes = read_pack_file(args.pack);
  std::size_t manifest_end = 0;
  const codec::Status header = codec::read_pack_header(bytes, manifest_end);
  if (header == codec::Status::kCorrupt || (header == codec::Status::kTruncated && bytes.size() < 8)) {
    // The magic is there but the rest of the header is not what its version field promises: say so, not
    // "no header" (a version field set to 1–3 on a newer pack reads as a 20-byte header of the old layout).
    const bool magic = bytes.size() >= 8 && std::memcmp(bytes.data(), "GEOMIPK\x1a", 8) == 0;
    throw InvalidInput(args.pack +
                       (magic ? ": a corrupt geomip pack header (version " +
                                    std::to_string(bytes.size() >= 10 ? bytes[8] | bytes[9] << 8 : 0) +
                                    " with the layout of another version, or damaged sizes)"
                              : ": not a geomip pack (no GEOMIPK header)"));
  }
  // The format holds grids up to level 11, meshes are made up to level 10: a pack of a finer level is
  // refused from its manifest, before its grids are decoded (it took 400 MB to find out).
  if (codec::PackInfo info; codec::read_pack_info(bytes, info) == codec::Status::kOk) {
    for (const codec::PackModelInfo& model : info.models)
      if (model.geometry.level > kMaxGeometryImageLevel)
        throw InvalidInput(args.pack + ": model '" + model.name + "' has grids of level " +
                           std::to_string(model.geometry.level) + "; meshes are decoded up to level " +
                           std::to_string(kMaxGeometryImageLevel));
  }
  codec::PackDecodeOptions options;
  if (args.bytes >= 0) options.max_bytes = static_cast<std::size_t>(args.bytes);
  const auto t0 = std::chrono::steady_clock::now();
  codec::PackDecodeResult decoded = codec::decode_pack(bytes, options);
  const double decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  const bool prefix_asked = args.bytes >= 0;
  if (decoded.status == codec::Status::kTruncated && decoded.models.empty()) {
    // The bytes end inside the manifest: decode_pack() knows no chunk sizes, only the header's manifest size.
    if (prefix_asked && static_cast<std::size_t>(args.bytes) < bytes.size()) {
      // The whole file knows its chunks: name the prefix that does decode.
      codec::PackInfo whole;
      const bool known = codec::read_pack_info(bytes, whole) == codec::Status::kOk;
      throw InvalidInput(
          args.pack + ": the first " + std::to_string(args.bytes) +
          " bytes end inside the pack's manifest (" + std::to_string(manifest_end) + " bytes" +
          (known ? "; the first level of detail needs " + std::to_string(first_level_bytes(whole))
                 : std::string()) +
          ")");
    }
    if (manifest_end == 0)  // the fixed header itself is cut: its manifest size is not known yet
      throw InvalidInput(args.pack + ": the pack is truncated inside its header (the file has " +
                         std::to_string(bytes.size()) + " bytes)");
    throw InvalidInput(args.pack + ": the pack is truncated inside its manifest (the file has " +
                       std::to_string(bytes.size()) + " bytes, the manifest alone needs " +
                       std::to_string(manifest_end) + ")");
  }
  if (decoded.status == codec::Status::kTruncated && !prefix_asked) {
    const std::uint64_t first = first_level_bytes(decoded.info);
    throw InvalidInput(
        args.pack + ": the pack is truncated (" + std::to_string(bytes.size()) + " of " +
        std::to_string(decoded.info.file_size()) + " bytes); " +
        (bytes.size() < first
             ? "it holds no level of detail (the first needs " + std::to_string(first) + " bytes)"
             : "to decode the coarser model it holds, ask for it with --bytes " +
                   std::to_string(bytes.size())));
  }
  if (decoded.status != codec::Status::kOk && decoded.status != codec::Status::kTruncated) {
    throw InvalidInput(args.pack + ": " + std::string(codec::status_message(decoded.status)));
  }
  if (decoded.models.empty()) throw InvalidInput(args.pack + ": the pack holds no model");
  // The first level of detail: one complete geometry pass of every model. Before it a model's grids are
  // still zero (a mesh of zero extent), so a prefix shorter than that is refused, not written.
  const std::uint64_t first_level = first_level_bytes(decoded.info);
  for (const auto& model : decoded.models) {
    if (model.geometry_passes == 0) {
      const std::size_t given =
          prefix_asked ? std::min(bytes.size(), static_cast<std::size_t>(args.bytes)) : bytes.size();
      throw InvalidInput(args.pack + ": the first " + std::to_string(given) +
                         " bytes hold no level of detail; the first level needs " +
                         std::to_string(first_level) + " bytes");
    }
  }
  // Models of one pack may have grids of different levels (`geomip encode` of several geometry images).
  for (const auto& model : decoded.models) {
    const int level = model.geometry.front().level;
    if (args.level > level) {
      throw InvalidInput("--level " + std::to_string(args.level) + " is above " +
                         (decoded.models.size() == 1
                              ? std::string("the pack's level ")
                              : "model '" + codec::one_line(model.name) + "''s level ") +
                         std::to_string(level));
    }
  }
  auto output_level = [&](const codec::DecodedModel& model) {
    return args.level < 0 ? model.geometry.front().level : args.level;
  };

  // One model → OUTPUT is the mesh file; several → OUTPUT's stem gets each model's name, made safe and unique
  // (the names come from the pack: a crafted one must not lead outside OUTPUT's directory, and two models
  // of the same name must not overwrite each other).
  std::vector<std::string> paths, names;
  for (const auto& model : decoded.models) names.push_back(model.name);
  const std::vector<std::string> file_names = model_file_names(names);
  const std::filesystem::path out(args.output);
  for (std::size_t m = 0; m < decoded.models.size(); ++m) {
    paths.push_back(
        decoded.models.size() == 1
            ? args.output
            : (out.parent_path() / (out.stem().string() + "." + file_names[m] + out.extension().string()))
                  .string());
    check_output_file(paths.back());
  }
  const QuadSplit quad_split = args.quad_split == "fixed" ? QuadSplit::kFixed : QuadSplit::kShorter;
  nlohmann::json j_models = nlohmann::json::array();
  // The grids as decoded choose the quad split, also when their folds are opened before writing: the face
  // list stays what it was (the web loader's and `--no-untangle`'s), the same for every model of a layout.
  // Untangling opens the folds of the model's decoded grid (the pack's level); a coarser --level writes every
  // 2^k-th of those samples, and the report's counts (`untangle.level`) are the decoded grid's. An output
  // level below UntangleOptions::min_level is left as decoded, as grids of those levels always are (and a
  // crafted pack's claimed level 10 written at --level 0 no longer costs minutes).
  std::vector<char> untangle(decoded.models.size(), 0);
  for (std::size_t m = 0; m < decoded.models.size(); ++m)
    untangle[m] = args.untangle && output_level(decoded.models[m]) >= UntangleOptions{}.min_level;
  const bool any_untangled = std::find(untangle.begin(), untangle.end(), 1) != untangle.end();
  std::vector<codec::DecodedModel> as_decoded;
  if (any_untangled) as_decoded = decoded.models;
  const std::vector<codec::DecodedModel>& choosers = any_untangled ? as_decoded : decoded.models;
  // Every model's mesh or none: a model that cannot be written leaves the earlier ones unwritten too.
  AtomicFileSet files;
  std::string report;  // printed once the files are in place
  for (std::size_t m = 0; m < decoded.models.size(); ++m) {
    // The models of the same layout (a consistent pack: all of them) choose the quad split together, so they
    // keep one face list (as far as their hole masks agree).
    std::vector<const codec::DecodedModel*> same_layout;
    for (const auto& other : choosers) {
      if (other.geometry.size() == decoded.models[m].geometry.size() &&
          other.geometry.front().level == decoded.models[m].geometry.front().level)
        same_layout.push_back(&other);
    }
    const QuadSplitOptions split{.split = quad_split, .chosen_by = same_layout};
    UntangleStats untangled;
    if (untangle[m]) untangled = untangle_decoded_model(decoded.models[m], split);
    // glTF carries per-patch texture coordinates and the normal maps' normals (seams not welded); the
    // other formats get the welded mesh.
    const TexturedMesh textured = gltf ? decoded_textured_mesh(decoded.models[m], args.level, split) : TexturedMesh{};
    // OBJ/PLY/OFF: the welded mesh, with the normal maps' normals per vertex when the pack has them.
    WriteMeshOptions write_options;
    const TriMesh mesh = gltf ? TriMesh{}
                              : decoded_mesh_with_map_normals(decoded.models[m], args.level, split,
                                                              write_options.vertex_normals);
    const TriMesh& written = gltf ? textured.mesh : mesh;
    files.add(paths[m], [&](std::ostream& o) {
      if (gltf)
        write_gltf(textured.mesh, textured.attributes, o,
                   {.binary = format == MeshFormat::kGlb,
                    .draco_position_bits = args.draco,
                    .node_rotation = frame_rotation(decoded.info.models[m].normalization)});
      else
        write_mesh(mesh, o, format, write_options);
    });
    j_models.push_back({{"name", decoded.models[m].name},
                        {"mesh", paths[m]},
                        {"vertices", written.num_vertices()},
                        {"faces", written.num_triangles()},
                        {"detail_level", decoded.models[m].detail_level},
                        {"geometry_passes", decoded.models[m].geometry_passes}});
    if (args.untangle)
      j_models.back()["untangle"] = {{"applied", untangled.applied},
                                     {"folded_before", untangled.folded_before},
                                     {"folded_after", untangled.folded_after},
                                     {"moved", untangled.moved},
                                     {"max_move", untangled.max_move},
                                     {"sweeps", untangled.sweeps},
                                     {"level", decoded.models[m].geometry.front().level}};
    if (!args.quiet && !args.json) {
      report +=
          string_printf("decode %s → %s: %zu faces (level %d, detail up to level %d, %zu geometry passes)\n",
                        codec::one_line(decoded.models[m].name).c_str(), codec::one_line(paths[m]).c_str(),
                        written.num_triangles(), output_level(decoded.models[m]),
                        decoded.models[m].detail_level, decoded.models[m].geometry_passes);
    }
  }
  files.commit();
  std::fputs(report.c_str(), stdout);
  if (args.json) {
    std::cout << nlohmann::json{{"pack", args.pack},
                                {"status", std::string(codec::status_message(decoded.status))},
                                {"pack_bytes", decoded.info.file_size()},
                                {"bytes_used", decoded.bytes_used},
                                {"chunks_decoded", decoded.chunks_decoded},
                                {"chunks", decoded.info.chunks.size()},
                                {"decode_ms", decode_ms},
                                {"models", j_models}}
                     .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  } else if (!args.quiet) {
    std::printf("%zu of %llu bytes used, %zu of %zu chunks complete, decoded in %.1f ms\n", decoded.bytes_used,
                static_cast<unsigned long long>(decoded.info.file_size()), decoded.chunks_decoded,
                decoded.info.chunks.size(), decode_ms);
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_decode_command(CLI::App& app) {
  auto args = std::make_shared<DecodeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "decode", "Decode a .gip pack (or its first N bytes) to a mesh per model (OBJ, PLY, OFF, glTF or GLB by extension).");
  cmd->add_option("pack", args->pack, "The .gip pack")->required();
  cmd->add_option("-o,--output", args->output,
                  "Output mesh; with several models, <stem>.<model>.<ext> beside it")
      ->required();
  cmd->add_option("--bytes", args->bytes, "Decode as if only the first N bytes of the file had arrived")
      ->check(non_negative_number());
  cmd->add_option("--level", args->level, "Output grid level K (default: the pack's level)")
      ->check(non_negative_number());
  cmd->add_flag("--draco{14}", args->draco,
                "glTF output compressed by Draco (KHR_draco_mesh_compression): positions quantized to BITS bits "
                "(--draco=BITS, 1..30; default 14), normals 10, texture coordinates 12");
  cmd->add_option("--quad-split", args->quad_split,
                  "How grid quads become triangles: shorter (along the shorter diagonal; every model of the pack "
                  "chooses together, so they share one face list) or fixed (the layout's rule, as geomip remesh)")
      ->check(CLI::IsMember({"shorter", "fixed"}))
      ->capture_default_str();
  cmd->add_flag(
      "--untangle,!--no-untangle", args->untangle,
      "Open the decoded grids' folds before writing (default; samples of triangles that face against "
      "the surface around them slide along the decoded surface; grids of level 6 and finer: 20-93 % "
      "fewer self-intersecting faces, PSNR -0.52..+0.14 dB); --no-untangle writes the grids as decoded, "
      "as geomip rd measures them");
  cmd->add_flag("--json", args->json, "Machine-readable summary on stdout");
  cmd->add_flag("-q,--quiet", args->quiet, "No report");
  return [args] { return run_decode(*args); };
}

}  // namespace geomip::tools
