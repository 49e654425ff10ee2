// geomip morph PACK --frames N [--schedule linear|wavelet] [--from A --to B] [--level K] -o DIR: the morph
// between two models of a consistent pack as N meshes with the same connectivity (paper §6; the viewer's
// schedules, morph/scene_model.h), for users without the viewer. Positions are in the pack's
// normalized frame (unit bounding box, centred), where the viewer morphs.
#include "codec/pack.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "morph/scene_model.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/pack_file.h"
#include "tools/pack_models.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

namespace geomip::tools {
namespace {

struct MorphArgs {
  std::string pack;
  std::string output;
  int frames = 10;
  std::string schedule = "linear";
  int bands = 5;
  bool bands_given = false;
  int from = 0, to = 1;
  int level = -1;
  bool no_align = false;
  bool quiet = false;
};

// `into`'s hole mask becomes the union of its own and `other`'s, at the finer of their two mask levels (a
// coarse mask quad covers 2^d × 2^d finer ones). A model without a mask takes the other's mask and level.
void unite_hole_masks(codec::DecodedModel& into, const codec::DecodedModel& other) {
  if (other.hole_mask.empty()) return;
  if (into.hole_mask.empty()) {
    into.hole_mask = other.hole_mask;
    into.hole_mask_level = other.hole_mask_level;
    return;
  }
  if (other.hole_mask.size() != into.hole_mask.size()) return;  // another layout: same_layout() refuses it
  const int level = std::max(into.hole_mask_level, other.hole_mask_level);
  const int n = 1 << level;
  auto at = [&](const codec::DecodedModel& m, std::size_t p, int i, int j) {
    const int shift = level - m.hole_mask_level, mn = 1 << m.hole_mask_level;
    const std::size_t q = static_cast<std::size_t>(j >> shift) * static_cast<std::size_t>(mn) +
                          static_cast<std::size_t>(i >> shift);
    return q < m.hole_mask[p].size() && m.hole_mask[p][q] != 0;
  };
  std::vector<std::vector<std::uint8_t>> united(into.hole_mask.size());
  for (std::size_t p = 0; p < united.size(); ++p) {
    united[p].resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        united[p][static_cast<std::size_t>(j) * n + i] = at(into, p, i, j) || at(other, p, i, j) ? 1 : 0;
  }
  into.hole_mask = std::move(united);
  into.hole_mask_level = level;
}

std::string frame_file_name(int k) {
  char name[32];
  std::snprintf(name, sizeof name, "morph_%04d.obj", k);
  return name;
}

int run_morph(const MorphArgs& args) {
  check_output_directory(args.output);
  note_input_file(args.pack);
  {  // an unwritable directory, a directory or the pack at a frame's place: found before the decode
    std::vector<std::string> frames;
    for (int k = 0; k < args.frames; ++k)
      frames.push_back((std::filesystem::path(args.output) / frame_file_name(k)).string());
    check_planned_outputs(args.output, frames);
  }
  const std::vector<std::uint8_t> bytes = read_pack_file(args.pack);
  // The manifest first: a pack of one model (or a damaged one) is refused before its grids are decoded.
  codec::PackInfo info;
  if (const codec::Status s = codec::read_pack_info(bytes, info); s != codec::Status::kOk)
    throw InvalidInput(args.pack + ": " + std::string(codec::status_message(s)));
  if (info.models.size() < 2)
    throw InvalidInput(args.pack +
                       " holds one model; a morph needs a pack of two or more (geomip convert --points)");
  codec::PackDecodeResult decoded = codec::decode_pack(bytes);
  if (decoded.status != codec::Status::kOk)
    throw InvalidInput(args.pack + ": " + std::string(codec::status_message(decoded.status)));
  const int count = static_cast<int>(decoded.models.size());
  if (count < 2)
    throw InvalidInput(args.pack +
                       " holds one model; a morph needs a pack of two or more (geomip convert --points)");
  if (args.from >= count || args.to >= count)
    throw InvalidInput(args.pack + " holds " + std::to_string(count) + " models; --from/--to out of range");
  const bool wavelet = args.schedule == "wavelet";
  if (args.bands_given && !wavelet)
    throw InvalidInput("--bands sets the wavelet schedule's bands: give --schedule wavelet too");
  if (args.from == args.to)
    throw InvalidInput("--from and --to are both model " + std::to_string(args.from) +
                       ": a morph needs two models");
  morph::DecodeSettings settings;
  settings.bands = wavelet ? args.bands : 1;
  settings.align = !args.no_align;
  codec::Status status = codec::Status::kOk;
  std::size_t used = 0;
  const std::vector<morph::SceneModel> scenes = morph::decode_scene(bytes, settings, status, used);
  if (scenes.size() != decoded.models.size()) throw InvalidInput(args.pack + ": no geometry to morph");
  const auto& a = scenes[args.from];
  const auto& b = scenes[args.to];
  if (!morph::same_layout(a, b))
    throw InvalidInput(args.pack + ": models " + std::to_string(args.from) + " and " + std::to_string(args.to) +
                       " do not share a patch layout");
  if (args.level > a.level)
    throw InvalidInput("--level " + std::to_string(args.level) + " is above the pack's level " +
                       std::to_string(a.level));

  // One template for every frame (seams, union of both hole masks): the same connectivity throughout.
  codec::DecodedModel frame = decoded.models[args.from];
  unite_hole_masks(frame, decoded.models[args.to]);

  const CreatedDirectories created = make_output_directory(args.output);
  const auto schedule = wavelet ? morph::MorphSchedule::kWavelet : morph::MorphSchedule::kLinear;
  // Every frame gets the same face list, and it is `geomip decode`'s for this pack: the quad split is chosen
  // by all the models of the morph's layout together, as decode chooses it (so attributes carry between a
  // morph frame and a decoded model by face index).
  std::vector<const codec::DecodedModel*> same_layout;
  for (const auto& model : decoded.models)
    if (model.geometry.size() == frame.geometry.size() &&
        model.geometry.front().level == frame.geometry.front().level)
      same_layout.push_back(&model);
  namespace fs = std::filesystem;
  const auto frame_name = frame_file_name;
  // Every frame's place must take a file (a directory of that name would stop the run half-way, leaving
  // this run's first frames beside an earlier run's last ones).
  for (int k = 0; k < args.frames; ++k) {
    std::error_code ec;
    const fs::path target = fs::path(args.output) / frame_name(k);
    if (fs::exists(target, ec) && !fs::is_regular_file(target, ec))
      throw InvalidInput((fs::path(args.output) / frame_name(k)).string() +
                         " is not a regular file: the frame cannot be written there");
  }
  // The frames go to a staging directory beside them first and are moved into place only when all are
  // written: a run that fails (a full disk) leaves an earlier run's frames as they were, not a mix of both.
  const fs::path staging = fs::path(args.output) / (".morph-partial-" + std::to_string(::getpid()));
  if (std::error_code ec; !fs::create_directory(staging, ec) && ec)
    throw IoError(args.output + ": cannot create the frames' staging directory " + staging.string() + ": " +
                  ec.message());
  struct RemoveStaging {
    fs::path path;
    ~RemoveStaging() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } remove_staging{staging};
  std::vector<std::string> report;
  for (int k = 0; k < args.frames; ++k) {
    const float t = args.frames == 1 ? 0.0f : static_cast<float>(k) / static_cast<float>(args.frames - 1);
    const auto positions = morph::evaluate_morph(a, b, t, schedule);
    for (std::size_t p = 0; p < positions.size(); ++p) frame.geometry[p].values = positions[p];
    const TriMesh mesh = decoded_mesh(frame, args.level, {.chosen_by = same_layout});
    const std::string path = (fs::path(args.output) / frame_name(k)).string();
    write_file_atomically((staging / frame_name(k)).string(),
                          [&](std::ostream& o) { write_mesh(mesh, o, MeshFormat::kObj); });
    char line[512];
    std::snprintf(line, sizeof line, "morph t=%.3f → %s: %zu vertices, %zu faces\n", t, path.c_str(),
                  mesh.num_vertices(), mesh.num_triangles());
    report.push_back(line);
  }
  for (int k = 0; k < args.frames; ++k)
    fs::rename(staging / frame_name(k), fs::path(args.output) / frame_name(k));
  if (!args.quiet)
    for (const std::string& line : report) std::fputs(line.c_str(), stdout);
  // Frames of an earlier, longer run in the same directory would read as part of this sequence
  // (morph_*.obj): those files, and only files of exactly that name, go.
  std::size_t stale = 0;
  for (int k = args.frames; k <= 9999; ++k) {
    std::error_code ignored;
    const std::filesystem::path path = std::filesystem::path(args.output) / frame_file_name(k);
    if (!std::filesystem::is_regular_file(path, ignored)) break;
    if (std::filesystem::remove(path, ignored)) ++stale;
  }
  if (stale > 0 && !args.quiet)
    std::printf("removed %zu frames of an earlier run (morph_%04d.obj on)\n", stale, args.frames);
  return kExitOk;
}

}  // namespace

CommandRunner add_morph_command(CLI::App& app) {
  auto args = std::make_shared<MorphArgs>();
  CLI::App* cmd = app.add_subcommand(
      "morph", "Morph between two models of a consistent .gip pack: N OBJ meshes with the same connectivity.");
  cmd->add_option("pack", args->pack, "The .gip pack (at least two consistent models)")->required();
  cmd->add_option("-o,--output", args->output, "Output directory (morph_0000.obj, ...)")->required();
  cmd->add_option("--frames", args->frames,
                  "Number of frames, t = 0 … 1 (frames of an earlier, longer run in DIR "
                  "are removed)")
      ->check(positive_number())
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--schedule", args->schedule, "linear, or wavelet (per-band schedule, paper §6.2)")
      ->check(CLI::IsMember({"linear", "wavelet"}));
  cmd->add_option("--bands", args->bands, "Wavelet bands of the wavelet schedule (with --schedule wavelet)")
      ->check(CLI::Range(2, 8))
      ->capture_default_str()
      ->each([args](const std::string&) { args->bands_given = true; });
  cmd->add_option("--from", args->from, "Source model index")->check(non_negative_number());
  cmd->add_option("--to", args->to, "Target model index")->check(non_negative_number());
  cmd->add_option("--level", args->level, "Output grid level (default: the pack's level)")
      ->check(non_negative_number());
  cmd->add_flag("--no-align", args->no_align,
                "Keep each model in its own frame (default: models are aligned to model 0 by the least-squares "
                "similarity over their corresponding samples, so the morph does not rotate or shrink)");
  cmd->add_flag("-q,--quiet", args->quiet, "No report");
  return [args] { return run_morph(*args); };
}

}  // namespace geomip::tools
