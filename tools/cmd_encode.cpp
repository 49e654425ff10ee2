// geomip encode DIR_or_EXR... -o PACK: geometry images written by `geomip gimage` (DIR/<stem>.geometry.exr,
// and <stem>.normals.exr beside it when present) → a progressive .gip pack. The models of one pack must share
// their patch layout when they are to be morphed (gimage run on a consistent set).
#include "codec/pack.h"
#include "gimage/exr_io.h"
#include "mesh/errors.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/convert_pipeline.h"
#include "tools/pack_models.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace geomip::tools {
namespace {

namespace fs = std::filesystem;

struct EncodeArgs {
  std::vector<std::string> inputs;
  std::string output;
  int quantization_bits = 14;
  int normal_bits = codec::PackWriteOptions{}.normal_codec.quantization_bits;
  bool normal_bits_given = false;
  bool no_normals = false;
  bool json = false;
  bool quiet = false;
};

constexpr const char* kGeometrySuffix = ".geometry.exr";

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// The geometry EXR files named by the arguments: files as given, directories expanded to their
/// *.geometry.exr in name order.
std::vector<std::string> geometry_files(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::directory_iterator(in))
        if (ends_with(entry.path().filename().string(), kGeometrySuffix)) found.push_back(entry.path().string());
      if (found.empty()) throw InvalidInput(in + ": no *.geometry.exr in this directory (run `geomip gimage`)");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (!fs::exists(in, ec)) {
      throw InvalidInput(in + ": no such file or directory");
    } else {
      files.push_back(in);
    }
  }
  if (files.empty()) throw InvalidInput("no input: give DIR or FILE.geometry.exr");
  return files;
}

// finest_grids() with the file named in its message.
std::vector<GeometryImage> grids_of(const GeometryImageFile& file, const std::string& path) {
  try {
    return finest_grids(file);
  } catch (const InvalidInput& e) {
    throw InvalidInput(path + ": " + e.what());
  }
}

GeometryImages load_images(const std::string& geometry_path, bool normals, std::string& name) {
  const GeometryImageFile file = read_geometry_image_exr(geometry_path);
  if (file.info.kind != "geometry")
    throw InvalidInput(geometry_path + ": holds '" + file.info.kind + "', not geometry (give the .geometry.exr)");
  GeometryImages images;
  images.geometry = grids_of(file, geometry_path);
  if (file.info.level < 1)  // convert's range: a level-0 image (2×2 samples) has no wavelet step to code
    throw InvalidInput(geometry_path + ": a level-" + std::to_string(file.info.level) +
                       " geometry image; a pack needs level 1 or finer (as geomip convert --level)");
  images.adjacency = file.info.adjacency;
  if (images.adjacency.size() != 4 * images.geometry.size())
    throw InvalidInput(geometry_path + ": its patch adjacency does not list 4 sides per patch");
  name = fs::path(file.info.source_mesh.empty() ? geometry_path : file.info.source_mesh).stem().string();
  if (ends_with(geometry_path, kGeometrySuffix) && file.info.source_mesh.empty())
    name = fs::path(geometry_path.substr(0, geometry_path.size() - 13)).filename().string();
  if (normals && ends_with(geometry_path, kGeometrySuffix)) {
    const std::string normals_path =
        geometry_path.substr(0, geometry_path.size() - std::string(kGeometrySuffix).size()) + ".normals.exr";
    std::error_code ec;
    if (fs::exists(normals_path, ec)) {
      const GeometryImageFile n = read_geometry_image_exr(normals_path);
      images.normals = grids_of(n, normals_path);
      if (images.normals.size() != images.geometry.size())
        throw InvalidInput(normals_path + ": a different number of patches than " + geometry_path);
    }
  }
  return images;
}

int run_encode(const EncodeArgs& args) {
  check_pack_output_name(args.output);
  check_quantization_switches(args.quantization_bits, args.normal_bits, args.normal_bits_given,
                              args.no_normals);
  const std::vector<std::string> files = geometry_files(args.inputs);
  std::vector<std::string> inputs = files;  // the geometry files and the normal maps beside them
  for (const std::string& path : files)
    if (ends_with(path, kGeometrySuffix))
      inputs.push_back(path.substr(0, path.size() - std::string(kGeometrySuffix).size()) + ".normals.exr");
  for (const std::string& input : inputs) note_input_file(input);
  check_output_file(args.output);  // refuses an output that is one of the inputs noted above
  std::vector<codec::PackModelInput> models;
  bool any_normals = false;
  for (const std::string& path : files) {
    std::string name;
    const GeometryImages images = load_images(path, !args.no_normals, name);
    any_normals = any_normals || !images.normals.empty();
    models.push_back(pack_model_input(name, images, nullptr, !args.no_normals));
  }
  // Names become file names on decode: distinct, safe ones (a geometry image's source_mesh is file data).
  std::vector<std::string> names;
  for (const auto& m : models) names.push_back(m.name);
  const std::vector<std::string> unique = model_file_names(names);
  for (std::size_t i = 0; i < models.size(); ++i) models[i].name = unique[i];
  codec::PackWriteOptions write;
  write.normals = !args.no_normals;
  write.geometry.quantization_bits = args.quantization_bits;
  write.normal_codec.quantization_bits = args.normal_bits;
  if (!models.empty()) write.geometry.joint_bytes = geometry_joint_bytes(models.front().geometry.size());
  std::vector<std::uint8_t> pack;
  try {
    pack = codec::write_pack(models, write);
  } catch (const std::invalid_argument& e) {
    throw InvalidInput(e.what());
  }
  write_file_atomically(args.output, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(pack.data()), static_cast<std::streamsize>(pack.size()));
  });
  codec::PackInfo info;
  codec::read_pack_info(pack, info);
  if (args.json) {
    std::cout << nlohmann::json{{"pack", args.output},
                                {"bytes", pack.size()},
                                {"manifest_bytes", info.manifest_end},
                                {"chunks", info.chunks.size()},
                                {"models", models.size()},
                                {"normals", any_normals && !args.no_normals}}
                     .dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  } else if (!args.quiet) {
    std::printf("encode %zu model(s) → %s: %zu bytes (manifest %zu, %zu chunks)%s\n", models.size(),
                args.output.c_str(), pack.size(), info.manifest_end, info.chunks.size(),
                any_normals && !args.no_normals ? ", with normal maps" : ", geometry only");
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_encode_command(CLI::App& app) {
  auto args = std::make_shared<EncodeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "encode",
      "Geometry images (`geomip gimage` output: a directory or <stem>.geometry.exr files, normal maps picked "
      "up beside them) → a progressive .gip pack. Hole masks are not in EXR files: use `geomip convert` for "
      "open meshes.");
  cmd->add_option("inputs", args->inputs, "Directories or .geometry.exr files")->required();
  cmd->add_option("-o,--output", args->output, "Output pack file (.gip)")->required();
  cmd->add_option("--bits", args->quantization_bits,
                  "Position quantization bits over the largest bounding-box extent (default 14)");
  CLI::Option* normal_bits =
      cmd->add_option("--normal-bits", args->normal_bits,
                      "Normal-map quantization bits in [6, 16] (default 10), as in convert");
  cmd->add_flag("--no-normals", args->no_normals, "Geometry-only pack");
  cmd->add_flag("--json", args->json, "Machine-readable summary on stdout");
  cmd->add_flag("-q,--quiet", args->quiet, "No report");
  return [args, normal_bits] {
    args->normal_bits_given = normal_bits->count() > 0;
    return run_encode(*args);
  };
}

}  // namespace geomip::tools
