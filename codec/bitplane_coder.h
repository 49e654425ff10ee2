// Embedded bit-plane coding of the integer wavelet coefficients (wavelet.h) of all patches of one model,
// three channels (x, y, z) per sample: set-partitioning in hierarchical trees per wavelet band (SPECK:
// Pearlman, Islam, Nagaraj & Said 2004; EZBC: Hsiang & Woods 2000) driven by the context-adaptive binary
// arithmetic coder (arithmetic_coder.h).
//
// Bands. Per patch: the coarse band (the samples at multiples of 2^steps) and, for each step k = steps..1
// (coarse to fine), three detail bands — row details (odd, even), column details (even, odd), diagonal
// details (odd, odd) multiples of s = 2^(k−1) (see wavelet.h). Bands are visited coarse band first, then by
// step from coarse to fine, orientation, patch.
//
// Weighting. The synthesis function of an interpolating-wavelet coefficient at spacing s has an L2 norm ∝ s,
// so the coder orders bits by the weighted magnitude |c|·2^offset with offset = k − 1 for the details of step
// k and offset = steps for the coarse band. Weighted bit-plane b of a band is its plain bit-plane b − offset;
// bands skip the weighted planes below their offset. With orientation weights (codec header version 3) the
// row- and column-detail bands and the coarse band get offset + 1: the synthesis norms of the cubic
// interpolating wavelet are about 1.13·2^(k−1) for rows and columns and 0.80·2^(k−1) for diagonals, a factor
// √2 that the nearest whole plane rounds up to 2.
//
// Deferred steps (version 3, BitplaneLayout::start_plane): the detail bands of such a step are not visited in
// the weighted planes above its start plane; just before it, encoder and decoder call a hook with the
// decoder's reconstruction so far (geometry_codec puts those coefficients into local frames there). The
// decoder decodes its planes in ranges between hooks, all patches synchronized at each hook.
//
// Joint channels. One quadtree per band over sample positions, with magnitude max(|x|, |y|, |z|). A node is
// significant at plane p when its magnitude is ≥ 2^p. Each plane: (1) sorting pass, for every band: each
// insignificant node of the band's list (LIS) is tested; a significant node is split into its (up to four)
// children, recursively (the last child of a significant node is inferred significant when its siblings were
// not); a significant leaf (sample) codes the significance of each channel (the last inferred when needed)
// and the signs, and joins the band's significant-sample list (LSP); (2) refinement pass, for every band:
// each sample significant before this plane codes bit p of its significant channels and the significance of
// the others. (Sorting comes first because it gives more surface PSNR, the product's measure, though less
// grid PSNR: docs/measurements.md.)
// Contexts: node significance by band class (coarse / row-or-column / diagonal), step (1, 2, ≥
// 3), quadtree depth (0, 1, 2, ≥ 3), number of significant 4-neighbours at the same depth (0, 1, ≥ 2) and the
// significance of the parent (the same place one step coarser, same orientation); channel significance by
// class, channel and whether another channel is significant; the first refinement bit of a coefficient by
// class; later refinement bits and signs are coded as raw (bypass) bits (context-coding them saves almost
// nothing and raw bits decode several times faster: docs/measurements.md).
//
// Segments. One segment per weighted bit-plane, from top_bitplane down to 0; the arithmetic coder is flushed
// at each segment end and the contexts carry over. Samples whose `coded` mask entry is 0 (seam copies owned
// by another sample) are never coded and decode as 0.
//
// Independent patches (BitplaneLayout::independent_patches, codec header version 2). The first
// `joint_segments` planes are coded by one coder for all patches, as in version 1 (the small coarse planes:
// shared contexts learn twice as fast, and nothing is gained by parallel decoding there); then every patch
// gets its own coder, starting from the joint coder's contexts, with its own bands and range coder (parents
// are in the same patch anyway), and such a segment is
//   varint byte sizes of the P streams | the streams' bytes interleaved,
// the interleave a function of the sizes alone: byte k of stream p is placed at (k + ½)/size_p, merged by
// that time. So the decoder takes the streams apart before decoding and runs the patches in parallel, and
// a byte prefix of a segment holds the same fraction of every patch's plane — close to the order of one
// joint coder. Per-patch coders from the first plane (separate contexts, sizes, flushes) and patch-major
// order both cost surface PSNR at low rates; the joint start (geometry_codec: joint until 2 KB) and the
// interleave remove both (figures: docs/measurements.md). Version 1 (independent_patches false): one stream
// for all patches throughout; still decoded.
//
// Decoding reconstructs each significant coefficient at the middle of its remaining uncertainty interval
// (known bits down to plane q: |c| ∈ [known, known + 2^q), reconstructed as known + 2^(q−1)); insignificant
// ones as 0. (3/8 of the interval, the usual choice for Laplacian data, loses surface PSNR here:
// docs/measurements.md.) Given complete segments plus a byte prefix of the next,
// it stops at the first symbol that would need a byte past the prefix (the range decoder's prefix property),
// so everything decoded is exactly what the encoder coded.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "codec/status.h"

namespace geomip::codec {

/// Coefficients of one patch: per channel, (2^level+1)² int32 row-major (grid[j·size + i]), as left by
/// wavelet_forward().
using PatchCoefficients = std::array<std::vector<std::int32_t>, 3>;

struct BitplaneLayout {
  int level = 0;        ///< grid level n of every patch (0..12)
  int steps = 0;        ///< wavelet steps applied (0..level)
  int num_patches = 0;  ///< patches (≥ 1)
  /// true: each patch has its own contexts and its own stream in every segment (the segment is the varint
  /// byte sizes of the P streams, then their bytes interleaved), so patches decode in parallel. false: one
  /// joint stream (format of codec header version 1).
  bool independent_patches = true;
  /// With independent_patches: the first joint_segments segments are one joint stream (as version 1), then
  /// every patch coder continues from the joint coder's contexts (≥ 0).
  int joint_segments = 0;
  /// Orientation weights (codec header version 3): row- and column-detail bands (and the coarse band) are
  /// weighted one bit-plane above the diagonal ones of the same step (their synthesis norms differ by about
  /// √2; see band_offset()). false: all orientations alike (versions 1 and 2).
  bool orientation_weights = false;
  /// Deferred steps (codec header version 3): start_plane[k] ≥ 0 (k = 1..steps) makes the detail bands of
  /// step k skip every weighted plane above start_plane[k] (they are not tested at all there); −1: coded from
  /// the top as usual. Before the first plane ≤ top that is some step's start plane, the encoder and the
  /// decoder call their `before_plane` hooks (see encode_bitplanes()), which is where geometry_codec puts
  /// the local frames of those steps' coefficients.
  std::array<int, 13> start_plane = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
  /// Deferred bands use contexts of their own (classes 3 and 4 beside coarse, row/column and diagonal).
  bool own_deferred_contexts = false;
  /// The lowest weighted plane coded (codec header version 7): the stream ends after it, so a band of
  /// offset o keeps its plain planes ≥ bottom_bitplane − o and loses the ones below (reconstructed at the
  /// middle of what is left, as in any prefix). 0: every plane, lossless on the integers.
  int bottom_bitplane = 0;
};

/// Weighted offset of a band: its plain bit-plane p is coded in weighted plane p + offset. Coarse band
/// (orient 0, k = steps + 1): steps (+1 with orientation_weights); detail band of step k (orient 1 row, 2
/// column, 3 diagonal): k − 1, +1 for rows and columns with orientation_weights.
int band_offset(const BitplaneLayout& layout, int k, int orient);

/// Largest plain bit-plane a coefficient may reach: magnitudes must stay below 2^(kMaxCoefficientPlane + 1).
inline constexpr int kMaxCoefficientPlane = 29;

struct BitplaneEncoding {
  /// Most significant weighted plane (at least layout.bottom_bitplane); segments.size() == top_bitplane −
  /// layout.bottom_bitplane + 1.
  int top_bitplane = 0;
  std::vector<std::vector<std::uint8_t>> segments;  ///< one per weighted plane, most significant first
  int joint_segments = 0;  ///< leading segments coded jointly (the decoder's BitplaneLayout::joint_segments)
};

/// Encodes `coefficients` (num_patches entries) under `coded` (per patch, (2^level+1)² bytes, non-zero =
/// this sample is coded; the others are skipped and their coefficients ignored). \throw std::invalid_argument
/// on inconsistent sizes or a coefficient magnitude ≥ 2^(kMaxCoefficientPlane+1). `joint_bytes` > 0
/// (independent patches only): instead of layout.joint_segments, code planes jointly until they hold at
/// least that many bytes; the count is returned in BitplaneEncoding::joint_segments.
///
/// Deferred steps (layout.start_plane): `before_plane(plane, view, coefficients)` is called before coding
/// each weighted plane that is some step's start plane, with `view` the decoder's reconstruction of every
/// coefficient at that point (what decode_bitplanes() would output given the planes above: zero for
/// deferred bands not yet started; the hook may use it as scratch) and the encoder's own copy of the
/// coefficients, which the hook may change for the bands starting at this plane (their magnitudes must stay
/// below 2^(plane − offset + 1)).
using EncodeHook = std::function<void(int plane, std::vector<PatchCoefficients>& view,
                                      std::vector<PatchCoefficients>& coefficients)>;
BitplaneEncoding encode_bitplanes(const BitplaneLayout& layout,
                                  const std::vector<PatchCoefficients>& coefficients,
                                  const std::vector<std::vector<std::uint8_t>>& coded,
                                  std::size_t joint_bytes = 0, const EncodeHook& before_plane = {});

struct BitplaneDecodeResult {
  std::size_t segments_complete = 0;  ///< complete segments decoded
  bool partial = false;               ///< symbols of a partial tail were used
};

/// Decodes: `segments` are complete segments in order, `partial_tail` (possibly empty) a byte prefix of the
/// next. `out` is resized to num_patches patches of 3 zero-filled channels and receives the reconstruction.
/// Independent patches decode on up to `max_threads` threads (0: one per hardware thread); the result does
/// not depend on the thread count. Returns kOk, kInvalidArgument (layout or mask sizes wrong) or kCorrupt
/// (more segments than planes, a tail after the last plane, stream sizes that do not fit their segment, a
/// coefficient beyond kMaxCoefficientPlane); never throws on bytes, never reads outside them, and always
/// leaves `out` holding the reconstruction of what was decoded.
/// Deferred steps: `before_plane(plane, view)` is called, once all planes above were decoded completely,
/// before decoding each plane that is some step's start plane, with the same `view` as the encoder's hook got
/// (scratch for the hook).
using DecodeHook = std::function<void(int plane, std::vector<PatchCoefficients>& view)>;
/// What a decode hook reads of its view (optional): the hook at `plane` reads only the positions (i, j) with
/// i and j multiples of 2^view_shift(plane) (0: the whole grid). The decoder then reconstructs the view
/// only there (the detail bands of steps ≤ the shift have no position there); the view's other values are
/// unspecified (left from earlier hooks). Saves the hooks of the coarse steps most of a full reconstruction.
using HookViewShift = std::function<int(int plane)>;

/// Incremental decoding (a class because its state is reused): the decoder keeps its significance lists,
/// contexts, range-decoder states and its place inside the plane it stopped in, and each update() continues
/// from there, so every byte is decoded once however the stream arrives. After any sequence of updates
/// whose last one got `segments` and `partial_tail`, result and reconstruct() are bit for bit those of
/// decode_bitplanes() on the same arguments (for streams of the encoder; after a kCorrupt the decoder stops
/// and may hold more than a one-shot decode of a later prefix would).
class BitplaneDecoder {
 public:
  BitplaneDecoder();
  ~BitplaneDecoder();
  BitplaneDecoder(BitplaneDecoder&&) noexcept;
  BitplaneDecoder& operator=(BitplaneDecoder&&) noexcept;

  /// Starts over. kInvalidArgument (and nothing to decode) on the errors of decode_bitplanes().
  Status reset(const BitplaneLayout& layout, int top_bitplane, std::vector<std::vector<std::uint8_t>> coded,
               int max_threads = 0, DecodeHook before_plane = {}, HookViewShift view_shift = {});
  /// Continues with a longer prefix of the stream: `segments` start with the complete segments of the
  /// previous call (same contents; the memory may have moved), `partial_tail` is a prefix of the next one
  /// and extends the previous call's tail when that segment is still the one in progress. Returns as
  /// decode_bitplanes(); kCorrupt is sticky. Cost: the symbols of the new bytes (plus the hooks reached).
  Status update(std::span<const std::span<const std::uint8_t>> segments,
                std::span<const std::uint8_t> partial_tail, BitplaneDecodeResult& result);
  /// The reconstruction of what was decoded (as decode_bitplanes()' `out`).
  void reconstruct(std::vector<PatchCoefficients>& out) const;
  /// Per patch, a counter that grows whenever an update() may have changed that patch's coefficients (joint
  /// planes and hooks change every patch): a patch whose counter did not change between two reconstruct()
  /// calls has the same coefficients.
  std::vector<std::uint64_t> patch_versions() const;

 private:
  struct State;
  /// reconstruct() at the positions whose coordinates are multiples of 2^shift only (see HookViewShift).
  void reconstruct_view(std::vector<PatchCoefficients>& out, int shift) const;
  std::unique_ptr<State> s_;
};

Status decode_bitplanes(const BitplaneLayout& layout, int top_bitplane,
                        const std::vector<std::vector<std::uint8_t>>& coded,
                        std::span<const std::span<const std::uint8_t>> segments,
                        std::span<const std::uint8_t> partial_tail, std::vector<PatchCoefficients>& out,
                        BitplaneDecodeResult& result, int max_threads = 0,
                        const DecodeHook& before_plane = {});

}  // namespace geomip::codec
