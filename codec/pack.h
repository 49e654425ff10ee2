// The .gip pack: one static, streamable file holding the progressively coded geometry images (and normal
// maps) of one or more consistent models.
//
// Layout (all integers little-endian; varint = unsigned LEB128):
//   [fixed header]
//     versions 4 on: magic "GEOMIPK\x1a" (8) | format version u16 | manifest size varint (1–4 bytes) |
//                manifest CRC32 u32   (15–18 bytes; from version 11 on the CRC covers the version too:
//                manifest_crc())
//     versions 1–3: magic (8) | format version u16 | flags u16 (0) | manifest size u32 | manifest CRC32 u32
//                (kPackHeaderSize = 20 bytes)
//   [manifest, manifest-size bytes]
//     models (name, normalization transform, geometry / normal codec headers, hole masks), seams, and the
//     chunk table: for each chunk (a model, kind and bit-plane pass, implied by the canonical order) its
//     size. Chunk offsets follow from the sizes: chunk 0 starts right after the manifest. Version 4 (the
//     header diet, docs/codec-v3.md): the table holds payload sizes only; the CRC32s trail the chunks
//     (below). Doubles (normalization, codec origin and step) are stored as float32 where that is exact,
//     behind one bit each; the codec header is stored without its 32 bytes of float64 origin/step, which
//     follow compactly. Versions 1–3: each table entry is size + CRC32 of the chunk; doubles as float64; the
//     codec header as GeometryCodecHeader::serialize() gives it. Version 7: each codec header's seam table
//     follows it in a compact form (pack.cpp, write_seams).
//   [chunks, in table order]
//     ordered coarse → fine across all models (pass 0 of every model, then pass 1, ...; normal-map passes
//     trail the geometry passes), so any byte prefix of the file is a coarser level of detail of every model.
//     Version 4: consecutive chunks form CRC groups — a chunk whose payload has at least crc_group_bytes
//     (a manifest field; the writer's default 256) is a group of its own, smaller neighbours are gathered
//     until their payloads reach it (so the tiny top-plane chunks share one CRC) — and the last chunk of a
//     group ends with a u32 CRC32 of the group's payloads (the file bytes from the group's first payload up
//     to that trailer). ChunkInfo::size counts that trailer, so chunks still tile the file.
// Designed for HTTP range requests: read kPackHeaderSize bytes, then the manifest, then chunks in order.
// Decoders never throw or assert on bytes; they return a Status.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "codec/geometry_codec.h"
#include "codec/normal_layers.h"
#include "codec/status.h"

namespace geomip::codec {

/// The most bytes a fixed header takes (versions 1–3: exactly this; version 4: 15–18). A reader that holds
/// this many bytes of a pack (or all of a shorter source) can always read the fixed header, and the
/// manifest always ends at or after it.
inline constexpr std::size_t kPackHeaderSize = 20;
/// Format version written. Version 11 (this one): version 10 with two-layer normal maps (normal_layers.h):
/// a model's normal-map entry may say 2 (instead of 1) and then holds the xyz stream's header, how many of
/// its passes the pack carries (layer 1), one orientation bit per patch, and the header of the layer-2
/// stream (octahedral residuals in frames around layer 1's normals, no seams); the normal chunks are layer
/// 1's passes, then layer 2's (PackModelInfo::normal_layers). Version 10: version 9 with codec headers of
/// version 7 too (a bottom bit-plane: the samples quantized GeometryCodecOptions::headroom_bits finer and the
/// stream ending that many weighted planes above plane 0, so the coarse bands keep more precision for the
/// same bytes; docs/codec-v3.md, "Headroom for the coarse bands"; the same container). Version 9: version 8
/// with a fourth form of seam table, the code of a closed genus-0 quad layout in canonical order
/// (layout_code.h: about 4 bits per quad; the armadillo's 64-patch table 139 → 29 bytes;
/// PackWriteOptions::canonical_layout puts a layout in that order). Version 8: version 7 with codec headers
/// of version 6 too (cell frames: local frames from the coarse grid's normals and a table of octahedral
/// cells; geometry_codec.cpp, docs/codec-v3.md "Cell frames"; the same container). Version 7: version 6 with
/// compact seam tables — a codec header's seams follow it as "the same as the header before", one entry per
/// side pair bit-packed (every layout's table), or the explicit list (pack.cpp, write_seams; docs/codec-v3.md
/// "Seam tables"): the four animals with a 64-quad layout at level 8 show their first level of detail after
/// 609 bytes instead of 3,554 (manifest 511 bytes instead of 3,456). Version 6: version 4's container, codec
/// headers of versions 3 to 5 (the encoder writes 5: the geometry's wavelet filter kCubicLong,
/// docs/codec-v3.md "Longer lifting filters"). Version 5: the same container, codec headers of versions 3 and
/// 4 (4: the wavelet's lifting update, docs/codec-v3.md "Lifting update"); each bump lets an older reader say
/// "unsupported version" instead of failing on the codec header. Version 4: the header diet — CRC32 trailers
/// per chunk group instead of a CRC per chunk in the up-front table, a varint manifest size, compact doubles
/// and codec headers (above); codec headers of version 3. Version 3: codec header version 3 (local frames,
/// orientation weights; docs/codec-v3.md). Version 2: bit-plane segments hold one stream per patch (codec
/// header version 2), decoded in parallel. Version 1: one joint stream per segment. Versions 1–10 are still
/// read. "Version 4" in the layout notes means versions 4 and later.
inline constexpr std::uint16_t kPackVersion = 11;
inline constexpr std::uint16_t kOldestPackVersion = 1;

enum class ChunkKind : std::uint8_t {
  kGeometry = 0,  ///< one bit-plane pass of a model's geometry stream
  kNormals = 1,   ///< one bit-plane pass of a model's normal-map stream
  kHoleMask = 2,  ///< a model's fine hole masks (the manifest holds coarse ones)
};

struct ChunkInfo {
  int model = 0;
  ChunkKind kind = ChunkKind::kGeometry;
  int pass = 0;              ///< bit-plane pass of that model's stream (0 = most significant)
  std::uint64_t offset = 0;  ///< from the start of the file (derived from the sizes)
  std::uint32_t size = 0;    ///< bytes in the file, the CRC trailer included (offset + size = next offset)
  /// Versions 1–3: the chunk's CRC32 from the table. Version 4: 0 (the CRC is in the file, see crc_bytes).
  std::uint32_t crc32 = 0;
  /// Version 4: 4 when the chunk closes its CRC group (its last 4 bytes are the group's CRC32), else 0.
  std::uint32_t crc_bytes = 0;
  /// Index of the first chunk of this chunk's CRC group (versions 1–3: the chunk itself). The chunks of a
  /// group are verified together, when the last one's trailer has arrived.
  std::size_t group_first = 0;
  std::uint32_t payload_size() const { return size - crc_bytes; }  ///< the codec segment's bytes
};

struct PackModelInfo {
  std::string name;  ///< source mesh name (file stem)
  /// Row-major 4×4 transform from model units to the normalized frame the viewer uses (unit bounding box,
  /// centred); identity when not known.
  std::array<double, 16> normalization{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  GeometryCodecHeader geometry;
  bool has_normals = false;
  GeometryCodecHeader normals;  ///< valid when has_normals: the xyz normal stream (layer 1 of two)
  /// 1: the normal chunks are passes of the xyz stream `normals`. 2 (format 11): its first
  /// `normal_base_passes` passes (layer 1), then the passes of `normal_residual` (layer 2: the normal in
  /// frames around layer 1's, normal_layers.h); the decoded normals take layer 1's seams.
  int normal_layers = 1;
  int normal_base_passes = 0;            ///< with normal_layers 2, in [1, passes of normals]
  NormalOrientation normal_orientation;  ///< with normal_layers 2: one entry per patch
  GeometryCodecHeader normal_residual;   ///< with normal_layers 2: same level and patches, no seams
  /// With normal_layers 2: layer 2's pass q is placed after geometry pass q + normal_residual_delay (layer
  /// 1's pass p, as one-layer maps, after geometry pass p + the pack's normals delay).
  int normal_residual_delay = 0;
  /// Normal-map chunks in the pack (layer 1's passes, then layer 2's).
  int normal_passes() const;
  /// Per patch, per quad of the level-hole_mask_level grid (2^L × 2^L, row-major), 1 = the quad covers a
  /// filled hole of the source mesh (geomip repair) and is left out of decoded meshes. Empty = no holes.
  /// The manifest holds the masks 2 levels coarser than the pack's (a coarse quad is masked when half of its
  /// quads are); the fine masks arrive in a kHoleMask chunk once the geometry is fine enough to need them.
  std::vector<std::vector<std::uint8_t>> hole_mask;
  int hole_mask_level = 0;       ///< L of hole_mask (the coarse masks)
  int fine_hole_mask_level = 0;  ///< level of the masks in the kHoleMask chunk (= L when there is none)
};

struct PackInfo {
  std::uint16_t version = kPackVersion;
  std::vector<PackModelInfo> models;
  std::vector<ChunkInfo> chunks;
  std::size_t manifest_end = 0;  ///< kPackHeaderSize + manifest size: where chunk 0 starts
  std::uint64_t file_size() const {
    return chunks.empty() ? manifest_end : chunks.back().offset + chunks.back().size;
  }
};

/// Reads the fixed header only: the number of bytes the manifest ends at. kTruncated if `bytes` ends inside
/// the fixed header (never with kPackHeaderSize bytes or more), kCorrupt on a bad magic (or a bad field),
/// kUnsupportedVersion on another format version.
Status read_pack_header(std::span<const std::uint8_t> bytes, std::size_t& manifest_end);

/// Reads header + manifest (verifying its CRC). kTruncated if `bytes` ends before the manifest does.
Status read_pack_info(std::span<const std::uint8_t> bytes, PackInfo& out);

// ---- writing -------------------------------------------------------------------------------------------

struct PackModelInput {
  std::string name;
  std::array<double, 16> normalization{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::vector<Grid3> geometry;  ///< per patch
  std::vector<Grid3> normals;   ///< per patch, or empty (geometry-only pack)
  std::vector<PatchSeam> seams;
  std::vector<std::vector<std::uint8_t>> hole_mask;  ///< as PackModelInfo::hole_mask; may be empty
  int hole_mask_level = -1;                          ///< level of hole_mask's grid; -1 = the geometry's level
};

struct PackWriteOptions {
  GeometryCodecOptions geometry;  ///< defaults: 14 bits with 4 of headroom, the kCubicLong wavelet
  /// Normal maps: no local frames (they are unit vectors, not displacements on a surface); the lifting update
  /// on (bunny: 20 % lower mean angular error at 10–80 KB of normal stream, the same at full decode in 0.98×
  /// the bytes; docs/codec-v3.md, "Lifting update").
  /// Headroom as the geometry's (codec header version 7, since 2026-12-07): on the bunny, horse, venus and
  /// armadillo (level-9 maps) 2.8–38 % lower mean angular error from 160 KB of normal stream on, up to 5 %
  /// lower below (one point +0.07 %), the whole stream 0.90–0.99× the bytes at a mean error of
  /// 0.047–0.051° instead of 10 bits' lossless 0.042° (docs/codec-v3.md, "Headroom on normal maps").
  GeometryCodecOptions normal_codec{.quantization_bits = 10,
                                    .headroom_bits = 4,
                                    .filter = WaveletFilter::kCubic,
                                    .steps = -1,
                                    .frame_steps = 0,
                                    .tangential_shift = 0,
                                    .orientation_weights = false,
                                    .lifting_update = true};
  /// 2: two-layer normal maps (format 11, normal_layers.h): layer 1 the first passes of the xyz stream above
  /// that hold at least normal_base_bytes_per_texel bytes per texel (bunny: about 20 KB), layer 2 the
  /// residual in frames around layer 1's normals, coded with normal_codec too. 1: the xyz stream alone, as
  /// every pack before format 11. Maps too small for a layer 2 (the xyz stream ends within layer 1's bytes)
  /// keep one layer.
  int normal_layers = 2;
  double normal_base_bytes_per_texel = 0.038;
  /// Layer 2's quantization step as a multiple of the xyz stream's nominal step (2 / 2^quantization_bits of
  /// normal_codec): its bits are the fewest (at most normal_codec's) that make the residual's step no
  /// larger than that.
  double normal_residual_step = 1.0;
  bool normals = true;  ///< false: geometry-only pack (for rate–distortion against Draco)
  /// CRC groups (format version 4, see the layout above): chunks with smaller payloads share one CRC32
  /// trailer until their payloads reach this many bytes; ≥ 1. Larger values save 4 bytes per merged chunk;
  /// a viewer that decodes verified chunks only (partial_chunks = false) waits for a whole group.
  std::size_t crc_group_bytes = 256;
  /// Normal-map pass p is placed after geometry pass p + normals_delay of every model.
  int normals_delay = 4;
  /// Hole masks: the manifest carries them this many levels coarser (fewer bytes before the first model);
  /// the full masks follow in a chunk after the first geometry pass at which the geometry passes of all
  /// models reach hole_mask_after_bytes.
  int coarse_hole_mask_levels = 2;
  std::size_t hole_mask_after_bytes = 4096;
  /// Store the patches of a closed genus-0 quad layout in the canonical order of layout_code.h (patches
  /// renumbered, grids, normal maps and hole masks turned so that side 0 is the side each patch is reached
  /// by), whose seam table takes a few bits per quad; a decoder then returns the patches in that order. Every
  /// model must have the same table (a consistent set); otherwise, or for other layouts, nothing moves.
  /// `geomip convert` sets it (its layouts are its own); false keeps the caller's patch order and sides.
  bool canonical_layout = false;
};

/// Encodes and lays out a pack in memory. Throws std::invalid_argument on bad input (models whose patch
/// layouts differ, NaN, ...).
std::vector<std::uint8_t> write_pack(const std::vector<PackModelInput>& models,
                                     const PackWriteOptions& options = {});

// ---- decoding ------------------------------------------------------------------------------------------

struct PackDecodeOptions {
  /// Use only the first max_bytes bytes of the buffer (as if only they had arrived).
  std::size_t max_bytes = std::numeric_limits<std::size_t>::max();
  bool normals = true;  ///< decode normal maps when the pack has them
  /// Also use the bytes not yet verified: a byte prefix of the first incomplete chunk (embedded streams)
  /// and, in version 4, the complete chunks of its CRC group before it.
  bool partial_chunks = true;
  int drop_finest_steps = 0;  ///< see GeometryDecodeOptions
  int max_threads = 0;        ///< per-patch decoding threads, see GeometryDecodeOptions
};

struct DecodedModel {
  std::string name;
  std::array<double, 16> normalization{};
  std::vector<Grid3> geometry;  ///< per patch, model units
  std::vector<Grid3> normals;   ///< per patch (empty when not decoded / not in pack)
  std::vector<PatchSeam> seams;
  std::vector<std::vector<std::uint8_t>> hole_mask;  ///< as PackModelInfo::hole_mask
  int hole_mask_level = 0;
  int detail_level = 0;             ///< finest level that received detail
  /// Complete geometry passes decoded (with partial_chunks, version 4: those of the open CRC group too).
  std::size_t geometry_passes = 0;
};

struct PackDecodeResult {
  /// kOk: every chunk decoded. kTruncated: the bytes end early; `models` hold what the prefix gives (empty if
  /// it ends inside the manifest). kCorrupt: a chunk (version 4: a CRC group) failed its CRC (decoding
  /// stopped at the last good pass of every model) or the manifest is damaged. kUnsupportedVersion: another
  /// format version. With options.partial_chunks, the chunks of the first group not verified (version 4:
  /// its trailer has not arrived; versions 1–3: the first incomplete chunk) are used as far as they have
  /// arrived, unverified, as a partial chunk always was; if that group's CRC fails once it is complete, its
  /// streams decode again without it.
  Status status = Status::kOk;
  PackInfo info;
  std::vector<DecodedModel> models;
  std::size_t chunks_decoded = 0;  ///< complete, CRC-checked chunks used (in file order: the first ones)
  std::size_t bytes_used = 0;      ///< bytes of the buffer that contributed
};

/// Decodes a pack or a byte prefix of one. One-shot: a PackDecoder given `bytes` once.
PackDecodeResult decode_pack(std::span<const std::uint8_t> bytes, const PackDecodeOptions& options = {});

/// Incremental decoding of a pack as its bytes arrive (a class because its state is reused): update() takes
/// the longer prefix received so far and decodes only what is new in it (GeometryDecoder per model and
/// stream: each byte is decoded once), result() gives the models. After any sequence of updates, result()
/// equals decode_pack() of the last update's bytes with the same options bit for bit (for packs of the
/// encoder; a chunk or CRC group that fails its CRC after unverified bytes of it were decoded makes the
/// streams fed from it decode again from their verified chunks, as decode_pack() would).
class PackDecoder {
 public:
  explicit PackDecoder(const PackDecodeOptions& options = {});
  ~PackDecoder();
  PackDecoder(PackDecoder&&) noexcept;
  PackDecoder& operator=(PackDecoder&&) noexcept;

  /// Continues with `bytes`: a prefix of the pack at least as long as the previous call's, with the same
  /// contents there (it may live elsewhere in memory; options.max_bytes still applies). Never throws on
  /// bytes. Cost: the CRCs and symbols of the new chunk bytes.
  void update(std::span<const std::uint8_t> bytes);
  /// The models of the bytes so far, as decode_pack() returns them; `drop_finest_steps` ≥ 0 overrides the
  /// options' (the banded morph's per-level reconstructions come from one decode), `normals` false leaves
  /// the normal maps out. Cost: the inverse transforms (no symbol is decoded again); cached per model while
  /// nothing new arrived and the drop is the same.
  PackDecodeResult result(int drop_finest_steps = -1, bool normals = true);
  /// As result(), but the grids are moved out of the per-model caches instead of copied (for a decoder whose
  /// result is taken once, as decode_pack() does); the next result() reconstructs them again.
  PackDecodeResult take_result(int drop_finest_steps = -1, bool normals = true);

 private:
  PackDecodeResult make_result(int drop_finest_steps, bool normals, bool take);
  struct State;
  std::unique_ptr<State> s_;
};

/// CRC-32 (IEEE 802.3, zlib's crc32).
std::uint32_t crc32(std::span<const std::uint8_t> bytes);
/// The manifest's CRC32 as format `version` stores it in the fixed header: from version 11 on of the format
/// version (2 bytes, little-endian) and the manifest, so that a damaged version is caught as any damaged
/// manifest byte (versions 10 and 11 would otherwise read one another's packs whenever the version-11 fields
/// are absent); before, of the manifest alone. For tools and tests that craft manifests.
std::uint32_t manifest_crc(std::uint16_t version, std::span<const std::uint8_t> manifest);

}  // namespace geomip::codec
