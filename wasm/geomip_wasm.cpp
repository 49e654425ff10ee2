// The C API that the WASM build exports (scripts/build-wasm; used by web/geomip.js, which is the API for
// JavaScript). A decoder object owns the bytes received so far; decoding reads them through codec/'s public
// pack API (codec::PackDecoder, codec::read_pack_info) and morph/'s SceneDecoder, exactly as the native tools
// and viewer do, so the grids are bit-identical to theirs (tests/web/wasm_decoder_test.mjs checks every byte
// prefix). Decoding is incremental: each decoder keeps codec state between calls, so every received byte is
// decoded once (a new state is started only when the decode settings change). Every pointer returned points into the decoder's own storage and stays valid until the next call
// that decodes or appends on the same decoder (the WASM heap may also move when it grows: JavaScript copies
// out at once). Nothing here throws on bytes; bad bytes give a status, as in codec/status.h.
#include <emscripten/emscripten.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "codec/pack.h"
#include "codec/status.h"
#include "morph/scene_model.h"

namespace {

using geomip::codec::Status;

struct Decoder {
  std::vector<std::uint8_t> bytes;
  geomip::codec::PackInfo info;
  Status info_status = Status::kTruncated;
  // Incremental state of gip_decode (grids) and gip_decode_scene, with the settings each was made for.
  std::unique_ptr<geomip::codec::PackDecoder> grids;
  bool grids_normals = false;
  std::unique_ptr<geomip::morph::SceneDecoder> scenes;
  int scenes_bands = 0, scenes_align = -1;
  geomip::codec::PackDecodeResult result;
  std::vector<geomip::morph::SceneModel> scene;
  Status scene_status = Status::kTruncated;
  std::size_t scene_bytes_used = 0;
};

const geomip::codec::DecodedModel* model_at(const Decoder* d, int m) {
  if (d == nullptr || m < 0 || m >= static_cast<int>(d->result.models.size())) return nullptr;
  return &d->result.models[static_cast<std::size_t>(m)];
}

const geomip::morph::SceneModel* scene_at(const Decoder* d, int m) {
  if (d == nullptr || m < 0 || m >= static_cast<int>(d->scene.size())) return nullptr;
  return &d->scene[static_cast<std::size_t>(m)];
}

template <typename T>
bool in_range(const std::vector<T>& v, int i) {
  return i >= 0 && i < static_cast<int>(v.size());
}

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE Decoder* gip_create() {
  return new Decoder();
}
EMSCRIPTEN_KEEPALIVE void gip_destroy(Decoder* d) {
  delete d;
}

/// Room for n more bytes at the end of the received bytes; write them there, then gip_commit(n). Null when
/// n would take the total past 2 GiB (a pack's chunk sizes are 31-bit, but no browser stream needs more).
EMSCRIPTEN_KEEPALIVE std::uint8_t* gip_reserve(Decoder* d, std::uint32_t n) {
  if (d == nullptr || n > 0x7fffffffu - d->bytes.size()) return nullptr;
  const std::size_t at = d->bytes.size();
  d->bytes.resize(at + n);
  return d->bytes.data() + at;
}
/// Keeps the first `n` bytes of the last reservation (fewer than reserved: the rest is dropped).
EMSCRIPTEN_KEEPALIVE void gip_commit(Decoder* d, std::uint32_t reserved, std::uint32_t n) {
  if (d == nullptr || n > reserved || reserved > d->bytes.size()) return;
  d->bytes.resize(d->bytes.size() - reserved + n);
}
EMSCRIPTEN_KEEPALIVE double gip_size(const Decoder* d) {
  return d ? static_cast<double>(d->bytes.size()) : 0;
}

EMSCRIPTEN_KEEPALIVE const char* gip_status_message(int status) {
  if (status < 0 || status >= geomip::codec::kStatusCount) return "unknown status";
  static std::string message;
  message = std::string(geomip::codec::status_message(static_cast<Status>(status)));
  return message.c_str();
}

// ---- layout (header + manifest) ------------------------------------------------------------------------

/// Reads the header and manifest from the bytes so far: kOk, kTruncated (the manifest has not arrived:
/// gip_needed() says how many bytes it needs), kCorrupt, kUnsupportedVersion.
EMSCRIPTEN_KEEPALIVE int gip_read_info(Decoder* d) {
  if (d == nullptr) return static_cast<int>(Status::kInvalidArgument);
  d->info = {};
  d->info_status = geomip::codec::read_pack_info(d->bytes, d->info);
  return static_cast<int>(d->info_status);
}
/// Bytes needed before gip_read_info can succeed: the header size, then where the manifest ends.
EMSCRIPTEN_KEEPALIVE double gip_needed(const Decoder* d) {
  if (d == nullptr) return 0;
  std::size_t manifest_end = 0;
  if (geomip::codec::read_pack_header(d->bytes, manifest_end) != Status::kOk)
    return static_cast<double>(geomip::codec::kPackHeaderSize);
  return static_cast<double>(manifest_end);
}
EMSCRIPTEN_KEEPALIVE double gip_manifest_end(const Decoder* d) {
  return d && d->info_status == Status::kOk ? static_cast<double>(d->info.manifest_end) : 0;
}
EMSCRIPTEN_KEEPALIVE double gip_file_size(const Decoder* d) {
  return d && d->info_status == Status::kOk ? static_cast<double>(d->info.file_size()) : 0;
}
EMSCRIPTEN_KEEPALIVE int gip_num_chunks(const Decoder* d) {
  return d && d->info_status == Status::kOk ? static_cast<int>(d->info.chunks.size()) : 0;
}
/// Field f of chunk c: 0 model, 1 kind (0 geometry, 1 normals, 2 hole mask), 2 pass, 3 offset, 4 size.
EMSCRIPTEN_KEEPALIVE double gip_chunk(const Decoder* d, int c, int f) {
  if (d == nullptr || d->info_status != Status::kOk || !in_range(d->info.chunks, c)) return -1;
  const auto& chunk = d->info.chunks[static_cast<std::size_t>(c)];
  switch (f) {
    case 0:
      return chunk.model;
    case 1:
      return static_cast<double>(chunk.kind);
    case 2:
      return chunk.pass;
    case 3:
      return static_cast<double>(chunk.offset);
    case 4:
      return chunk.size;
    default:
      return -1;
  }
}

// ---- grids (codec::decode_pack) ------------------------------------------------------------------------

/// Decodes every byte received so far (codec::decode_pack, one thread). Returns the codec::Status.
EMSCRIPTEN_KEEPALIVE int gip_decode(Decoder* d, int normals) {
  if (d == nullptr) return static_cast<int>(Status::kInvalidArgument);
  if (!d->grids || d->grids_normals != (normals != 0)) {
    geomip::codec::PackDecodeOptions options;
    options.normals = normals != 0;
    options.max_threads = 1;
    d->grids = std::make_unique<geomip::codec::PackDecoder>(options);
    d->grids_normals = normals != 0;
  }
  d->grids->update(d->bytes);
  d->result = d->grids->result();
  return static_cast<int>(d->result.status);
}
EMSCRIPTEN_KEEPALIVE double gip_bytes_used(const Decoder* d) {
  return d ? static_cast<double>(d->result.bytes_used) : 0;
}
EMSCRIPTEN_KEEPALIVE int gip_chunks_decoded(const Decoder* d) {
  return d ? static_cast<int>(d->result.chunks_decoded) : 0;
}
EMSCRIPTEN_KEEPALIVE int gip_num_models(const Decoder* d) {
  return d ? static_cast<int>(d->result.models.size()) : 0;
}
EMSCRIPTEN_KEEPALIVE const char* gip_model_name(const Decoder* d, int m) {
  const auto* model = model_at(d, m);
  return model ? model->name.c_str() : "";
}
EMSCRIPTEN_KEEPALIVE const double* gip_model_normalization(const Decoder* d, int m) {
  const auto* model = model_at(d, m);
  return model ? model->normalization.data() : nullptr;
}
/// Field f of model m: 0 patches, 1 geometry level, 2 normal-map level (−1: none decoded), 3 hole-mask
/// level (−1: no mask), 4 detail level, 5 complete geometry passes.
EMSCRIPTEN_KEEPALIVE int gip_model_field(const Decoder* d, int m, int f) {
  const auto* model = model_at(d, m);
  if (model == nullptr) return -1;
  switch (f) {
    case 0:
      return static_cast<int>(model->geometry.size());
    case 1:
      return model->geometry.empty() ? -1 : model->geometry[0].level;
    case 2:
      return model->normals.empty() ? -1 : model->normals[0].level;
    case 3:
      return model->hole_mask.empty() ? -1 : model->hole_mask_level;
    case 4:
      return model->detail_level;
    case 5:
      return static_cast<int>(model->geometry_passes);
    default:
      return -1;
  }
}
/// Patch p's grid of model m: (2^level+1)² xyz floats, row-major (codec::Grid3). what: 0 geometry,
/// 1 normals. Null when absent.
EMSCRIPTEN_KEEPALIVE const float* gip_grid(const Decoder* d, int m, int p, int what) {
  const auto* model = model_at(d, m);
  if (model == nullptr) return nullptr;
  const auto& grids = what == 0 ? model->geometry : model->normals;
  return in_range(grids, p) ? grids[static_cast<std::size_t>(p)].values.data() : nullptr;
}
/// Patch p's hole mask of model m: 4^L bytes (L = hole-mask level), 1 = quad left out. Null when none.
EMSCRIPTEN_KEEPALIVE const std::uint8_t* gip_hole_mask(const Decoder* d, int m, int p) {
  const auto* model = model_at(d, m);
  if (model == nullptr || !in_range(model->hole_mask, p)) return nullptr;
  return model->hole_mask[static_cast<std::size_t>(p)].data();
}

// ---- scene models (morph::decode_scene: what the desktop viewer draws) ----------------------------------

/// Decodes the bytes so far into scene models in the normalized frame (morph::decode_scene): `bands` wavelet
/// bands per model for the wavelet-schedule morph (1 = geometry only), models 1.. aligned to model 0 when
/// `align`. Returns the codec::Status (no models yet: kTruncated).
EMSCRIPTEN_KEEPALIVE int gip_decode_scene(Decoder* d, int bands, int align) {
  if (d == nullptr || bands < 1 || bands > 8) return static_cast<int>(Status::kInvalidArgument);
  if (!d->scenes || d->scenes_bands != bands || d->scenes_align != (align != 0)) {
    geomip::morph::DecodeSettings settings;
    settings.bands = bands;
    settings.align = align != 0;
    d->scenes = std::make_unique<geomip::morph::SceneDecoder>(settings);
    d->scenes_bands = bands;
    d->scenes_align = align != 0;
  }
  d->scene.clear();
  d->scene_status = Status::kTruncated;
  d->scene_bytes_used = 0;
  try {
    d->scene = d->scenes->update(d->bytes, d->scene_status, d->scene_bytes_used);
  } catch (const std::exception&) {  // models of different layouts (make_scene_model's preconditions)
    d->scene.clear();
    d->scene_status = Status::kCorrupt;
  }
  return static_cast<int>(d->scene_status);
}
EMSCRIPTEN_KEEPALIVE double gip_scene_bytes_used(const Decoder* d) {
  return d ? static_cast<double>(d->scene_bytes_used) : 0;
}
EMSCRIPTEN_KEEPALIVE int gip_scene_count(const Decoder* d) {
  return d ? static_cast<int>(d->scene.size()) : 0;
}
EMSCRIPTEN_KEEPALIVE const char* gip_scene_name(const Decoder* d, int m) {
  const auto* s = scene_at(d, m);
  return s ? s->name.c_str() : "";
}
/// Field f of scene model m: 0 level, 1 patches, 2 bands, 3 normal level (−1 none), 4 hole level (−1 none),
/// 5 detail level, 6 positions (floats), 7 normals (floats), 8 holes (bytes).
EMSCRIPTEN_KEEPALIVE int gip_scene_field(const Decoder* d, int m, int f) {
  const auto* s = scene_at(d, m);
  if (s == nullptr) return -1;
  switch (f) {
    case 0:
      return s->level;
    case 1:
      return s->num_patches;
    case 2:
      return s->bands;
    case 3:
      return s->normals.empty() ? -1 : s->normal_level;
    case 4:
      return s->holes.empty() ? -1 : s->hole_level;
    case 5:
      return s->detail_level;
    case 6:
      return static_cast<int>(s->positions.size());
    case 7:
      return static_cast<int>(s->normals.size());
    case 8:
      return static_cast<int>(s->holes.size());
    default:
      return -1;
  }
}
/// what: 0 positions, 1 normals (floats); 2 holes (bytes, as a float* cast: read it as Uint8).
EMSCRIPTEN_KEEPALIVE const void* gip_scene_data(const Decoder* d, int m, int what) {
  const auto* s = scene_at(d, m);
  if (s == nullptr) return nullptr;
  switch (what) {
    case 0:
      return s->positions.empty() ? nullptr : s->positions.data();
    case 1:
      return s->normals.empty() ? nullptr : s->normals.data();
    case 2:
      return s->holes.empty() ? nullptr : s->holes.data();
    default:
      return nullptr;
  }
}

}  // extern "C"
