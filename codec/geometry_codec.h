// Progressive wavelet coding of one model's geometry images (or normal maps): a set of (2^n+1)² grids of
// 3-channel floats, one per patch, glued along their sides by seams.
//
// Pipeline (encoder): quantize each channel to integers on a fixed step (uniform over the model) → integer
// lifting wavelet transform per patch (wavelet.h; border lines are never updated, so a seam's coefficients
// depend only on the seam's samples) → embedded bit-plane coding of the coefficients (bitplane_coder.h)
// driven by the context-adaptive binary arithmetic coder (arithmetic_coder.h). Every sample shared by several
// patches (seam sides, corners) is coded once, by its owner (the lowest patch·grid index among the copies);
// the decoder copies it to the other patches before the inverse transform, so every decoded prefix is
// watertight with bit-identical seam samples.
//
// Version 3 (docs/codec-v3.md): the detail coefficients of the finest steps are coded in local frames
// (normal, tangent, bitangent) that the decoder derives from its own coarser reconstruction, the tangential
// components one bit-plane coarser; row and column details are weighted above diagonal ones. Version 4: the
// wavelet may have an update step (wavelet.h), so the coarse levels are averages, not subsamples. Version 7:
// the samples are quantized GeometryCodecOptions::headroom_bits finer and the stream ends that many weighted
// planes above plane 0 (GeometryCodecHeader::bottom_bitplane), so the coarse bands keep more precision for
// the same bytes.
//
// The output is a list of segments, one per bit-plane pass, coarsest information first. Segments are
// self-delimiting only through their sizes (stored by the container, pack.h); a decoder given the first k
// complete segments plus a byte prefix of segment k+1 reconstructs the best approximation those bytes allow.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "codec/status.h"
#include "codec/wavelet.h"  // WaveletFilter (defined there, with the transform it selects)

namespace geomip::codec {

/// How two patch sides are glued (same convention as geomip::SideLink in param/mesh_partition.h, repeated
/// here so codec/ builds without param/). Side s of a (2^n+1)² grid, parameter k ∈ [0, 2^n]:
/// s = 0: (i, j) = (k, 0); s = 1: (2^n, k); s = 2: (2^n − k, 2^n); s = 3: (0, 2^n − k). `reversed`: sample k
/// of this side is sample 2^n − k of the other side.
struct PatchSeam {
  int patch = 0;
  int side = 0;
  int other_patch = 0;
  int other_side = 0;
  bool reversed = true;
};

/// A (2^level+1)² grid of 3-channel floats, row-major: values[3·(j·size + i) + c].
struct Grid3 {
  int level = 0;
  std::vector<float> values;
  int size() const { return (1 << level) + 1; }
};

struct GeometryCodecOptions {
  /// Quantization: the finest details keep quantization_bits over the largest bounding-box extent of all
  /// patches (in [1, 24]); the samples themselves are quantized headroom_bits finer (below), the origin is
  /// the bounding-box minimum. With headroom_bits 0, full decoding is lossless up to this quantization (error
  /// ≤ step/2 per coordinate) when frame_steps is 0; near-lossless with frames (see frame_steps).
  int quantization_bits = 14;
  /// Headroom of the coarser bands (codec header version 7): the samples are quantized on (largest extent)
  /// / 2^(quantization_bits + headroom_bits) and the stream ends at weighted bit-plane headroom_bits
  /// (BitplaneLayout::bottom_bitplane), so the finest band keeps about quantization_bits of precision and
  /// the coarser ones, weighted higher, keep up to headroom_bits more, which is where a prefix's error
  /// sits: with 14 bits and no headroom the coarse bands reach their last plane before the fine ones, and
  /// the bunny's and the horse's 32 KB prefixes were 1.3–2.1 dB below what finer coarse bands give
  /// (docs/codec-v3.md, "Headroom for the coarse bands"). Capped at 24 − quantization_bits; 0 = the version-6
  /// stream. Needs cell_frames.
  int headroom_bits = 4;
  /// kCubicLong by default (codec header version 5): +0.16 … +0.29 dB over kCubic on the mean of the
  /// bunny's, horse's, venus's and armadillo's pack-prefix curves (docs/codec-v3.md, "Longer lifting
  /// filters"); kCubic: more grid and surface PSNR than kLinear at every byte count, and fewer bytes in all
  /// (docs/measurements.md; tests/bench/codec_bench.cpp --rd).
  WaveletFilter filter = WaveletFilter::kCubicLong;
  /// Wavelet steps; -1 = all the way down to the 2×2 grid of corners (level 0).
  int steps = -1;
  /// The top bit-planes are coded by one coder for all patches until they hold this many bytes; the planes
  /// after that by one coder per patch, decoded in parallel (see bitplane_coder.h). 0: per patch from the
  /// first plane.
  std::size_t joint_bytes = 2048;
  /// Local frames (codec header version 3; docs/codec-v3.md): the detail coefficients of the finest
  /// `frame_steps` wavelet steps are coded as (normal, tangent, bitangent) components in an integer frame
  /// built from the decoder's own reconstruction of the coarser surface (the normal of the surface the
  /// coarser levels predict at that sample), identical on both sides (integer arithmetic only). 0: xyz
  /// coefficients throughout (then full decoding is lossless up to the quantization); with frames it is
  /// near-lossless (the frame rotation rounds: about one quantization step per coordinate, plus the
  /// tangential shift below).
  int frame_steps = 3;
  /// Tangential components of framed coefficients are quantized 2^tangential_shift times coarser than the
  /// normal one (they move samples along the surface and barely change the surface distance); in [0, 8].
  int tangential_shift = 1;
  /// Weight row and column detail bands one bit-plane above diagonal ones (their synthesis norms differ by
  /// about √2; codec header version 3).
  bool orientation_weights = true;
  /// The wavelet's update step on interior lines (wavelet.h; codec header version 4): the coarse levels a
  /// prefix holds are local averages of the surface rather than subsamples of it. Lossless like the plain
  /// transform; +1.4 to +2.7 dB on the bunny's and the horse's pack prefixes from 1.5 to 16 KB
  /// (docs/codec-v3.md, "Lifting update").
  bool lifting_update = true;
  /// Cell frames (codec header version 6): the frames of the framed steps from normals of the step's coarse
  /// grid and a table of 4,096 octahedral direction cells, instead of version 5's per-sample integer frame
  /// from the finest reconstruction (3 square roots, 9 divisions and an extra inverse transform per framed
  /// step). The same bytes and PSNR within ±0.1 dB on the bunny's and the horse's prefixes; the bunny's full
  /// decode 197 M → 162 M instructions (docs/codec-v3.md, "Cell frames"). false: version 5's stream
  /// (ablations).
  bool cell_frames = true;
};

/// The small fixed parameters the decoder needs besides the segments (stored in the pack manifest).
/// serialize()/parse() give a compact byte form; parse() never trusts bytes.
struct GeometryCodecHeader {
  /// Stream layout: 1 = one joint stream for all patches (packs of format version 1), 2 = one stream per
  /// patch in every segment, decoded in parallel, 3 = version 2 plus local frames and orientation weights,
  /// 4 = version 3 plus the lifting update flag, 5 = version 4 plus the filter kCubicLong, 6 = version 5 with
  /// cell frames (the frames from the coarse grid's normals and a table of octahedral cells), 7 = version 6
  /// with a bottom bit-plane (written by this encoder when headroom_bits > 0; 6 otherwise).
  int version = 6;
  int level = 0;        ///< grid level n of every patch
  int num_patches = 0;  ///< patches per model
  int steps = 0;        ///< wavelet steps actually applied
  WaveletFilter filter = WaveletFilter::kCubic;
  double origin[3] = {0, 0, 0};  ///< dequantized value = origin + step · integer
  double step = 1;
  int top_bitplane = 0;  ///< most significant (weighted) bit-plane coded; one segment per plane down to
                         ///< bottom_bitplane
  /// Version 7: the lowest weighted bit-plane coded (GeometryCodecOptions::headroom_bits); 0 before.
  int bottom_bitplane = 0;
  /// Version 2: the first joint_segments segments are one joint stream, the others per patch (≤ planes).
  int joint_segments = 0;
  /// Version 3: see GeometryCodecOptions. frame_start[k − 1] (k = 1..frame_steps) is the weighted bit-plane
  /// at which the framed details of step k start (≤ top_bitplane).
  bool orientation_weights = false;
  /// Version 4: the wavelet transform has the update step (GeometryCodecOptions::lifting_update).
  bool lifting_update = false;
  int frame_steps = 0;
  int tangential_shift = 0;
  std::vector<int> frame_start;
  std::vector<PatchSeam> seams;

  std::vector<std::uint8_t> serialize() const;
  /// Parses `bytes` exactly (all of them); kCorrupt on any inconsistency (level > 12, seams out of range,
  /// ...).
  static Status parse(std::span<const std::uint8_t> bytes, GeometryCodecHeader& out);
};

struct EncodedGeometry {
  GeometryCodecHeader header;
  std::vector<std::vector<std::uint8_t>> segments;  ///< one per bit-plane, most significant first
};

/// Encodes the patches (all of one level, same number as seams describe; seam samples must be bit-identical
/// in the glued patches — resample_geometry() guarantees it). Throws std::invalid_argument on bad input
/// (sizes differ, NaN, level > 12): this is the encoder, its inputs come from the program, not from bytes.
EncodedGeometry encode_geometry(const std::vector<Grid3>& patches, const std::vector<PatchSeam>& seams,
                                const GeometryCodecOptions& options = {});

/// Gives every seam copy (a sample that seams glue to a sample of a lower patch·grid index) its owner's
/// values, as decoding a stream with these seams does: afterwards the glued samples are bit-identical. For
/// grids decoded from a stream without seams (two-layer normal maps, normal_layers.h). Grids of another
/// level or count than the seams describe are left as they are. Cost: one pass over the patches' borders.
void copy_seam_samples(std::vector<Grid3>& patches, const std::vector<PatchSeam>& seams);

struct GeometryDecodeOptions {
  /// Zero the details of the finest `drop_finest_steps` wavelet steps (0 = keep all). The result stays on the
  /// full grid: the coarser level interpolated by the wavelet's own subdivision (for band-wise morphing).
  int drop_finest_steps = 0;
  /// Threads for the per-patch streams of a version-2 stream (0 = one per hardware thread, capped at the
  /// number of patches; 1 = decode on the calling thread only).
  int max_threads = 0;
};

struct DecodedGeometry {
  std::vector<Grid3> patches;         ///< header.num_patches grids of header.level, in the encoder's units
  std::size_t segments_complete = 0;  ///< complete segments decoded
  bool partial = false;               ///< a byte prefix of one more segment was also used
  /// Finest wavelet level that received any non-zero detail (0..level): the level of detail these bytes give.
  int detail_level = 0;
};

/// Decodes `segments` (complete, in order); `partial_tail`, if not empty, is a byte prefix of the next
/// segment. Never throws on bytes: returns kOk, or kCorrupt (bytes that cannot come from the encoder — the
/// result is then the best reconstruction up to that point, still watertight). A partial tail is not an
/// error. kCorrupt also for more segments than header.top_bitplane + 1, or a tail after the last one (the
/// planes that exist are still decoded). kInvalidArgument (and no patches) for a header that parse() would
/// refuse (built by hand) or a negative drop_finest_steps. Cost: proportional to the bytes decoded; a
/// version-2/3 stream decodes its patches on parallel threads (options.max_threads); version 3 adds the
/// frame construction of its framed steps (timings: tests/bench/codec_bench.cpp --pack, docs/codec-v3.md).
/// Incremental decoding of one model's stream (a class because its state is reused): update() continues from
/// where the previous prefix ended (BitplaneDecoder: each byte is decoded once), result() reconstructs what
/// was decoded — with any drop_finest_steps, so a banded morph takes all its bands from one decode.
/// After any sequence of updates whose last one got (segments, partial_tail), result() is bit for bit
/// decode_geometry() of the same arguments (streams of the encoder; after kCorrupt the decoder stops).
class GeometryDecoder {
 public:
  GeometryDecoder();
  ~GeometryDecoder();
  GeometryDecoder(GeometryDecoder&&) noexcept;
  GeometryDecoder& operator=(GeometryDecoder&&) noexcept;

  /// Starts over for a stream with this header. kInvalidArgument (then update() does nothing) for a header
  /// that parse() would refuse.
  Status reset(const GeometryCodecHeader& header, const GeometryDecodeOptions& options = {});
  /// Continues with a longer prefix of the stream (the arguments of decode_geometry(); the complete segments
  /// of the previous call come first, same contents, possibly elsewhere in memory). Returns as
  /// decode_geometry(); kCorrupt is sticky. Cost: the symbols of the new bytes.
  Status update(std::span<const std::span<const std::uint8_t>> segments,
                std::span<const std::uint8_t> partial_tail);
  /// What was decoded, as decode_geometry() would output it with `drop_finest_steps` (−1: the options'
  /// value). Cost: the inverse transforms (about a tenth of a full decode; the same grids are returned from
  /// a cache while nothing new was decoded).
  void result(DecodedGeometry& out, int drop_finest_steps = -1);
  /// As result(), but the grids are moved out of the cache instead of copied (for a decoder whose result is
  /// taken once, as decode_geometry() does); the next result() reconstructs them again.
  void take_result(DecodedGeometry& out, int drop_finest_steps = -1);

 private:
  void build_result(int drop_finest_steps);  // the grids of result() into the cache
  struct State;
  std::unique_ptr<State> s_;
};

Status decode_geometry(const GeometryCodecHeader& header,
                       std::span<const std::span<const std::uint8_t>> segments,
                       std::span<const std::uint8_t> partial_tail, DecodedGeometry& out,
                       const GeometryDecodeOptions& options = {});

}  // namespace geomip::codec
