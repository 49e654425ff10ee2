#include "codec/pack.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <tuple>

#include "codec/arithmetic_coder.h"
#include "codec/byte_io.h"
#include "codec/layout_code.h"

namespace geomip::codec {
namespace {

using detail::ByteReader;
using detail::ByteWriter;

// The fuzz build (tests/fuzz) accepts every checksum so that mutated bytes reach the parsers behind them.
#ifdef GEOMIP_FUZZING_NO_CRC
constexpr bool kCheckCrc = false;
#else
constexpr bool kCheckCrc = true;
#endif

constexpr std::uint8_t kMagic[8] = {'G', 'E', 'O', 'M', 'I', 'P', 'K', 0x1a};

// Limits that keep a decoder of hostile bytes within bounded memory and time.
constexpr std::size_t kMaxModels = 64;
constexpr std::size_t kMaxNameSize = 4096;
constexpr std::size_t kMaxManifestSize = 64u << 20;
constexpr int kMaxPackLevel = 11;
constexpr std::uint64_t kMaxSamplesPerPack = std::uint64_t{1} << 25;
constexpr std::uint64_t kMaxPasses = 64;

enum NormalizationForm : std::uint8_t { kIdentity = 0, kScaleTranslate = 1, kFull = 2 };

bool is_identity(const std::array<double, 16>& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (m[4 * r + c] != (r == c ? 1.0 : 0.0)) return false;
  return true;
}
bool is_scale_translate(const std::array<double, 16>& m) {
  return m[1] == 0 && m[2] == 0 && m[4] == 0 && m[6] == 0 && m[8] == 0 && m[9] == 0 && m[12] == 0 &&
         m[13] == 0 && m[14] == 0 && m[15] == 1 && m[0] == m[5] && m[0] == m[10];
}

// Doubles of format version 4: one bit per value (in ⌈n/8⌉ bytes, value k in bit k % 8 of byte k / 8) says
// it is stored as float32 (4 bytes; only where that is exact, −0 and all), else as float64 (8 bytes). Older
// versions store float64 throughout.
bool exact_as_float(double v) {
  return std::isfinite(v) && std::abs(v) <= std::numeric_limits<float>::max() &&
         std::bit_cast<std::uint64_t>(static_cast<double>(static_cast<float>(v))) ==
             std::bit_cast<std::uint64_t>(v);
}

void write_doubles(ByteWriter& w, std::span<const double> values, std::uint16_t version) {
  if (version < 4) {
    for (double v : values) w.f64(v);
    return;
  }
  for (std::size_t k = 0; k < values.size(); k += 8) {
    std::uint8_t bits = 0;
    for (std::size_t i = k; i < std::min(values.size(), k + 8); ++i)
      if (exact_as_float(values[i])) bits |= static_cast<std::uint8_t>(1u << (i - k));
    w.u8(bits);
  }
  for (double v : values) {
    if (exact_as_float(v))
      w.u32(std::bit_cast<std::uint32_t>(static_cast<float>(v)));
    else
      w.f64(v);
  }
}

bool read_doubles(ByteReader& r, std::span<double> values, std::uint16_t version) {
  if (version < 4) return std::all_of(values.begin(), values.end(), [&](double& v) { return r.f64(v); });
  std::vector<std::uint8_t> bits((values.size() + 7) / 8);
  for (std::uint8_t& b : bits)
    if (!r.u8(b)) return false;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (bits[i / 8] >> (i % 8) & 1) {
      std::uint32_t f;
      if (!r.u32(f)) return false;
      values[i] = static_cast<double>(std::bit_cast<float>(f));
    } else if (!r.f64(values[i])) {
      return false;
    }
  }
  return true;
}

void write_normalization(ByteWriter& w, const std::array<double, 16>& m, std::uint16_t version) {
  if (is_identity(m)) {
    w.u8(kIdentity);
  } else if (is_scale_translate(m)) {
    w.u8(kScaleTranslate);
    const double values[4] = {m[0], m[3], m[7], m[11]};
    write_doubles(w, values, version);
  } else {
    w.u8(kFull);
    write_doubles(w, m, version);
  }
}

bool read_normalization(ByteReader& r, std::array<double, 16>& m, std::uint16_t version) {
  std::uint8_t form;
  if (!r.u8(form)) return false;
  m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (form == kIdentity) return true;
  if (form == kScaleTranslate) {
    double v[4];
    if (!read_doubles(r, v, version)) return false;
    m[0] = m[5] = m[10] = v[0];
    m[3] = v[1], m[7] = v[2], m[11] = v[3];
  } else if (form == kFull) {
    if (!read_doubles(r, m, version)) return false;
  } else {
    return false;
  }
  return std::all_of(m.begin(), m.end(), [](double v) { return std::isfinite(v); });
}

// Codec headers of format version 4: GeometryCodecHeader::serialize() without the 32 bytes of its float64
// origin[3] and step (little-endian, in that order) — varint size of the rest, varint offset where the 32
// bytes were cut, the rest — followed by origin and step as compact doubles. The reader puts the 32 bytes
// back and parses; the origin and step it then reads must be the compact ones. Older versions store
// serialize()'s bytes as they are (varint size + bytes).
// Seam tables of format version 7. GeometryCodecHeader::serialize() lists every seam as patch, other patch
// (varints) and a byte of sides and orientation, and a layout lists each shared side from both of its
// patches: 768 bytes per codec header for a 64-quad layout, twice per model with normal maps, once more per
// model of a consistent set — 3,072 bytes of the 3,456-byte manifest of the four animals with their 64-quad
// layout (geometry only; docs/codec-v3.md, "Seam tables"). From version 7 the codec header's bytes carry
// no seams (its seam count is 0) and the table follows the header's doubles:
//   u8 form
//   form 0 (kSeamsListed): varint count, then per seam as serialize() writes it;
//   form 1 (kSeamsAsBefore): the same list as the codec header read just before in this manifest (a model's
//          normal maps, the next model of a consistent set);
//   form 2 (kSeamsMirrored): the table every quad layout and two-square partition gives — one seam per side,
//          (patch, side) in order, each the mirror of its partner's (p, s, q, t, r) ↔ (q, t, p, s, r) —
//          stored once per pair, bit-packed LSB first: for each side in order whose partner is not known yet,
//          the partner's patch minus this patch in bit_width(num_patches − 1 − patch) bits (the partner
//          comes later, so the difference is ≥ 0), its side in 2 bits and `reversed` in 1; zero bits pad to
//          a byte;
//   form 3 (kSeamsCode, version 9): a closed oriented genus-0 layout in canonical order, as the code of
//          layout_code.h (a few bits per quad; its length follows from its steps).
enum SeamForm : std::uint8_t { kSeamsListed = 0, kSeamsAsBefore = 1, kSeamsMirrored = 2, kSeamsCode = 3 };

bool same_seams(const std::vector<PatchSeam>& a, const std::vector<PatchSeam>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const PatchSeam& x, const PatchSeam& y) {
    return x.patch == y.patch && x.side == y.side && x.other_patch == y.other_patch &&
           x.other_side == y.other_side && x.reversed == y.reversed;
  });
}

bool mirrored_seams(const std::vector<PatchSeam>& seams, int num_patches) {
  if (seams.size() != 4 * static_cast<std::size_t>(num_patches)) return false;
  for (std::size_t i = 0; i < seams.size(); ++i) {
    const PatchSeam& s = seams[i];
    if (s.patch != static_cast<int>(i / 4) || s.side != static_cast<int>(i % 4) || s.other_patch < 0 ||
        s.other_patch >= num_patches || s.other_side < 0 || s.other_side > 3)
      return false;
    const std::size_t j =
        4 * static_cast<std::size_t>(s.other_patch) + static_cast<std::size_t>(s.other_side);
    const PatchSeam& o = seams[j];
    if (j == i || o.other_patch != s.patch || o.other_side != s.side || o.reversed != s.reversed)
      return false;
  }
  return true;
}

void write_seams(ByteWriter& w, const std::vector<PatchSeam>& seams, int num_patches, std::uint16_t version,
                 const std::vector<PatchSeam>* before) {
  if (before != nullptr && same_seams(seams, *before)) {
    w.u8(kSeamsAsBefore);
    return;
  }
  if (const auto order = version >= 9 ? layout_order(seams, num_patches) : std::nullopt;
      order && order->identity()) {
    w.u8(kSeamsCode);
    for (std::uint8_t b : order->code) w.u8(b);
    return;
  }
  if (!mirrored_seams(seams, num_patches)) {
    w.u8(kSeamsListed);
    w.varint(seams.size());
    for (const PatchSeam& s : seams) {
      w.varint(static_cast<std::uint64_t>(s.patch));
      w.varint(static_cast<std::uint64_t>(s.other_patch));
      w.u8(static_cast<std::uint8_t>((s.side & 3) | (s.other_side & 3) << 2 | (s.reversed ? 16 : 0)));
    }
    return;
  }
  w.u8(kSeamsMirrored);
  std::uint64_t acc = 0;
  int filled = 0;
  auto put = [&](std::uint64_t v, int bits) {
    for (int b = 0; b < bits; ++b) {
      acc |= (v >> b & 1) << filled;
      if (++filled == 8) w.u8(static_cast<std::uint8_t>(acc)), acc = 0, filled = 0;
    }
  };
  for (std::size_t i = 0; i < seams.size(); ++i) {
    const PatchSeam& s = seams[i];
    const std::size_t j =
        4 * static_cast<std::size_t>(s.other_patch) + static_cast<std::size_t>(s.other_side);
    if (j < i) continue;  // written with its partner
    put(static_cast<std::uint64_t>(s.other_patch - s.patch),
        std::bit_width(static_cast<unsigned>(num_patches - 1 - s.patch)));
    put(static_cast<std::uint64_t>(s.other_side), 2);
    put(s.reversed ? 1 : 0, 1);
  }
  if (filled > 0) w.u8(static_cast<std::uint8_t>(acc));
}

/// Reads what write_seams() wrote into `seams` (for a header of `num_patches` patches). Bounds: a table
/// never holds more than 4 seams per patch, and a mirrored one is only allocated when the bytes left can
/// hold it (3 bits per pair at least).
bool read_seams(ByteReader& r, std::vector<PatchSeam>& seams, int num_patches, std::uint16_t version,
                const std::vector<PatchSeam>* before) {
  std::uint8_t form;
  if (!r.u8(form)) return false;
  if (form == kSeamsCode) {
    std::size_t used = 0;
    return version >= 9 && read_layout_code(r.rest(), num_patches, seams, used) && r.skip(used);
  }
  if (form == kSeamsAsBefore) {
    if (before == nullptr) return false;
    seams = *before;
    return true;
  }
  if (form == kSeamsListed) {
    std::uint64_t count;
    if (!r.bounded(count, 4 * static_cast<std::uint64_t>(num_patches)) || count > r.remaining() / 3)
      return false;
    seams.resize(static_cast<std::size_t>(count));
    for (PatchSeam& s : seams) {
      std::uint64_t patch, other;
      std::uint8_t packed;
      if (!r.bounded(patch, static_cast<std::uint64_t>(num_patches - 1)) ||
          !r.bounded(other, static_cast<std::uint64_t>(num_patches - 1)) || !r.u8(packed) ||
          (packed & ~0x1F) != 0)
        return false;
      s = {static_cast<int>(patch), packed & 3, static_cast<int>(other), (packed >> 2) & 3,
           (packed & 16) != 0};
    }
    return true;
  }
  if (form != kSeamsMirrored) return false;
  const std::uint64_t pairs = 2 * static_cast<std::uint64_t>(num_patches);
  if (r.remaining() * 8 < pairs * 3) return false;
  seams.assign(4 * static_cast<std::size_t>(num_patches), PatchSeam{-1, 0, -1, 0, true});
  std::uint8_t byte = 0;
  int left = 0;
  auto get = [&](int bits, std::uint64_t& v) {
    v = 0;
    for (int b = 0; b < bits; ++b) {
      if (left == 0) {
        if (!r.u8(byte)) return false;
        left = 8;
      }
      v |= static_cast<std::uint64_t>(byte & 1) << b;
      byte = static_cast<std::uint8_t>(byte >> 1);
      --left;
    }
    return true;
  };
  for (std::size_t i = 0; i < seams.size(); ++i) {
    PatchSeam& s = seams[i];
    if (s.patch >= 0) continue;  // its partner's mirror
    const int patch = static_cast<int>(i / 4);
    std::uint64_t delta, side, reversed;
    if (!get(std::bit_width(static_cast<unsigned>(num_patches - 1 - patch)), delta) || !get(2, side) ||
        !get(1, reversed) || delta > static_cast<std::uint64_t>(num_patches - 1 - patch))
      return false;
    const int other = patch + static_cast<int>(delta);
    const std::size_t j = 4 * static_cast<std::size_t>(other) + static_cast<std::size_t>(side);
    if (j <= i || seams[j].patch >= 0) return false;  // the partner must be a later side with no seam yet
    s = {patch, static_cast<int>(i % 4), other, static_cast<int>(side), reversed == 1};
    seams[j] = {other, static_cast<int>(side), patch, static_cast<int>(i % 4), reversed == 1};
  }
  return byte == 0;  // the padding is zero
}

void write_codec_header(ByteWriter& w, const GeometryCodecHeader& h, std::uint16_t version,
                        const std::vector<PatchSeam>* seams_before = nullptr) {
  if (version >= 7) {
    GeometryCodecHeader without = h;
    without.seams.clear();
    write_codec_header(w, without, 6);
    write_seams(w, h.seams, h.num_patches, version, seams_before);
    return;
  }
  std::vector<std::uint8_t> bytes = h.serialize();
  if (version < 4) {
    w.bytes(bytes);
    return;
  }
  const double values[4] = {h.origin[0], h.origin[1], h.origin[2], h.step};
  ByteWriter f64s;
  for (double v : values) f64s.f64(v);
  const auto at = std::search(bytes.begin(), bytes.end(), f64s.data().begin(), f64s.data().end());
  if (at == bytes.end()) throw std::logic_error("write_pack: codec header without its float64 origin/step");
  const auto offset = static_cast<std::size_t>(at - bytes.begin());
  bytes.erase(at, at + 32);
  w.varint(offset);
  w.bytes(bytes);
  write_doubles(w, values, version);
}

bool read_codec_header(ByteReader& r, GeometryCodecHeader& h, std::uint16_t version,
                       const std::vector<PatchSeam>* seams_before = nullptr) {
  if (version >= 7) {
    // The header as version 6 stores it, with no seams, then the seam table; parse() checks the whole header
    // again (seam bounds included).
    if (!read_codec_header(r, h, 6) || !h.seams.empty() ||
        !read_seams(r, h.seams, h.num_patches, version, seams_before))
      return false;
    GeometryCodecHeader checked;
    return GeometryCodecHeader::parse(h.serialize(), checked) == Status::kOk;
  }
  std::vector<std::uint8_t> bytes;
  if (version < 4) return r.bytes(bytes, 1 << 20) && GeometryCodecHeader::parse(bytes, h) == Status::kOk;
  std::uint64_t offset;
  double values[4];
  if (!r.bounded(offset, 1 << 20) || !r.bytes(bytes, 1 << 20) || offset > bytes.size() ||
      !read_doubles(r, values, version))
    return false;
  ByteWriter f64s;
  for (double v : values) f64s.f64(v);
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(offset), f64s.data().begin(), f64s.data().end());
  if (GeometryCodecHeader::parse(bytes, h) != Status::kOk) return false;
  const double parsed[4] = {h.origin[0], h.origin[1], h.origin[2], h.step};
  return std::equal(parsed, parsed + 4, values, [](double a, double b) {
    return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
  });
}

// Hole mask of one patch, `side` × `side` quads: a flag byte (0 = no masked quad), then the bits in raster
// order through the arithmetic coder, each in a context of its already coded neighbours (left, up, up-left,
// up-right): a hole costs about its perimeter, an empty patch one byte.
// Two-layer normal maps (version 11): one bit per patch, packed little-endian into ⌈patches / 8⌉ bytes.
void write_orientation(ByteWriter& w, const NormalOrientation& orientation, int num_patches) {
  for (int p = 0; p < num_patches; p += 8) {
    std::uint8_t byte = 0;
    for (int k = 0; k < 8 && p + k < num_patches; ++k) {
      const std::size_t i = static_cast<std::size_t>(p + k);
      if (i >= orientation.size() || orientation[i]) byte |= static_cast<std::uint8_t>(1u << k);
    }
    w.u8(byte);
  }
}

bool read_orientation(ByteReader& r, NormalOrientation& orientation, int num_patches) {
  orientation.assign(static_cast<std::size_t>(std::max(num_patches, 0)), true);
  for (int p = 0; p < num_patches; p += 8) {
    std::uint8_t byte;
    if (!r.u8(byte)) return false;
    for (int k = 0; k < 8; ++k) {
      const bool bit = (byte >> k) & 1;
      if (p + k < num_patches) {
        orientation[static_cast<std::size_t>(p + k)] = bit;
      } else if (bit) {
        return false;  // padding bits are 0
      }
    }
  }
  return true;
}

int mask_context(const std::vector<std::uint8_t>& mask, int side, int i, int j) {
  auto at = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < side ? mask[static_cast<std::size_t>(y) * side + x] : std::uint8_t{0};
  };
  return at(i - 1, j) | at(i, j - 1) << 1 | at(i - 1, j - 1) << 2 | at(i + 1, j - 1) << 3;
}

void write_mask(ByteWriter& w, const std::vector<std::uint8_t>& mask, int side) {
  std::vector<std::uint8_t> bits(mask.size());
  for (std::size_t k = 0; k < mask.size(); ++k) bits[k] = mask[k] ? 1 : 0;
  if (std::none_of(bits.begin(), bits.end(), [](std::uint8_t b) { return b; })) {
    w.u8(0);
    return;
  }
  w.u8(1);
  ArithmeticEncoder encoder;
  Context contexts[16];
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
      encoder.encode(bits[static_cast<std::size_t>(j) * side + i], contexts[mask_context(bits, side, i, j)]);
  w.bytes(encoder.finish());
}

bool read_mask(ByteReader& r, int side, std::vector<std::uint8_t>& mask) {
  std::uint8_t coded;
  if (!r.u8(coded) || coded > 1) return false;
  mask.assign(static_cast<std::size_t>(side) * side, 0);
  if (coded == 0) return true;
  std::vector<std::uint8_t> bytes;
  if (!r.bytes(bytes, r.remaining())) return false;
  ArithmeticDecoder decoder(bytes);
  Context contexts[16];
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
      mask[static_cast<std::size_t>(j) * side + i] =
          static_cast<std::uint8_t>(decoder.decode(contexts[mask_context(mask, side, i, j)]));
  return true;
}

// The fine hole masks of one model (all patches, `side` × `side` quads each) in one arithmetic-coded chunk.
// Per coarse quad (a block of 2^shift × 2^shift fine quads, raster order) one bit says whether the whole
// block equals the coarse bit — nearly always, far from a hole's border — in a context of the coarse bit and
// of the neighbouring blocks' flags; the fine bits of the other blocks follow one by one in a context of
// their coded neighbours (not yet coded = 0) and the coarse bit. On the bunny (2 × 256² quads) this decodes
// about 9k decisions instead of 131k.
constexpr int kUniformContexts = 8, kFineContexts = 32;

int uniform_context(const std::vector<std::uint8_t>& uniform, int coarse_side, int ci, int cj,
                    int coarse_bit) {
  const int left = ci > 0 ? uniform[static_cast<std::size_t>(cj) * coarse_side + ci - 1] : 1;
  const int up = cj > 0 ? uniform[static_cast<std::size_t>(cj - 1) * coarse_side + ci] : 1;
  return coarse_bit | left << 1 | up << 2;
}

std::vector<std::uint8_t> encode_fine_masks(const std::vector<std::vector<std::uint8_t>>& masks,
                                            const std::vector<std::vector<std::uint8_t>>& coarse, int side,
                                            int shift) {
  ArithmeticEncoder encoder;
  Context uniform_ctx[kUniformContexts], fine_ctx[kFineContexts];
  const int block = 1 << shift, coarse_side = side >> shift;
  for (std::size_t p = 0; p < masks.size(); ++p) {
    const auto bit = [&](int i, int j) { return masks[p][static_cast<std::size_t>(j) * side + i] ? 1 : 0; };
    std::vector<std::uint8_t> known(static_cast<std::size_t>(side) * side, 0);
    std::vector<std::uint8_t> uniform(static_cast<std::size_t>(coarse_side) * coarse_side, 0);
    for (int cj = 0; cj < coarse_side; ++cj) {
      for (int ci = 0; ci < coarse_side; ++ci) {
        const int c = coarse[p][static_cast<std::size_t>(cj) * coarse_side + ci] ? 1 : 0;
        bool same = true;
        for (int j = cj * block; j < (cj + 1) * block && same; ++j)
          for (int i = ci * block; i < (ci + 1) * block && same; ++i) same = bit(i, j) == c;
        encoder.encode(same, uniform_ctx[uniform_context(uniform, coarse_side, ci, cj, c)]);
        uniform[static_cast<std::size_t>(cj) * coarse_side + ci] = same;
        for (int j = cj * block; j < (cj + 1) * block; ++j) {
          for (int i = ci * block; i < (ci + 1) * block; ++i) {
            const int b = same ? c : bit(i, j);
            if (!same) encoder.encode(b, fine_ctx[mask_context(known, side, i, j) | c << 4]);
            known[static_cast<std::size_t>(j) * side + i] = static_cast<std::uint8_t>(b);
          }
        }
      }
    }
  }
  return encoder.finish();
}

/// Pack format version 1: every fine bit coded, in the context of its neighbours and the coarse bit.
void decode_fine_masks_v1(std::span<const std::uint8_t> bytes,
                          const std::vector<std::vector<std::uint8_t>>& coarse, int side, int shift,
                          std::vector<std::vector<std::uint8_t>>& masks) {
  ArithmeticDecoder decoder(bytes);
  Context contexts[kFineContexts];
  const int coarse_side = side >> shift;
  masks.assign(coarse.size(), std::vector<std::uint8_t>(static_cast<std::size_t>(side) * side, 0));
  for (std::size_t p = 0; p < coarse.size(); ++p)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        const int c = coarse[p][static_cast<std::size_t>(j >> shift) * coarse_side + (i >> shift)];
        masks[p][static_cast<std::size_t>(j) * side + i] =
            static_cast<std::uint8_t>(decoder.decode(contexts[mask_context(masks[p], side, i, j) | c << 4]));
      }
}

/// Mirrors encode_fine_masks(); `coarse` holds 0/1 bytes (read_mask()).
void decode_fine_masks(std::span<const std::uint8_t> bytes,
                       const std::vector<std::vector<std::uint8_t>>& coarse, int side, int shift,
                       std::vector<std::vector<std::uint8_t>>& masks) {
  ArithmeticDecoder decoder(bytes);
  Context uniform_ctx[kUniformContexts], fine_ctx[kFineContexts];
  const int block = 1 << shift, coarse_side = side >> shift;
  masks.assign(coarse.size(), std::vector<std::uint8_t>(static_cast<std::size_t>(side) * side, 0));
  std::vector<std::uint8_t> uniform(static_cast<std::size_t>(coarse_side) * coarse_side);
  for (std::size_t p = 0; p < coarse.size(); ++p) {
    auto& mask = masks[p];
    std::fill(uniform.begin(), uniform.end(), std::uint8_t{0});
    for (int cj = 0; cj < coarse_side; ++cj) {
      for (int ci = 0; ci < coarse_side; ++ci) {
        const int c = coarse[p][static_cast<std::size_t>(cj) * coarse_side + ci] ? 1 : 0;
        const int same = decoder.decode(uniform_ctx[uniform_context(uniform, coarse_side, ci, cj, c)]);
        uniform[static_cast<std::size_t>(cj) * coarse_side + ci] = static_cast<std::uint8_t>(same);
        for (int j = cj * block; j < (cj + 1) * block; ++j) {
          std::uint8_t* const row = mask.data() + static_cast<std::size_t>(j) * side;
          if (same) {  // the block is its coarse quad's value (most blocks): whole rows at a time
            std::fill_n(row + ci * block, block, static_cast<std::uint8_t>(c));
            continue;
          }
          for (int i = ci * block; i < (ci + 1) * block; ++i)
            row[i] =
                static_cast<std::uint8_t>(decoder.decode(fine_ctx[mask_context(mask, side, i, j) | c << 4]));
        }
      }
    }
  }
}

/// The coarse mask `shift` levels above `mask`: a coarse quad is masked when at least half of its quads are.
std::vector<std::uint8_t> coarsen_mask(const std::vector<std::uint8_t>& mask, int side, int shift) {
  const int coarse_side = side >> shift, block = 1 << shift;
  std::vector<std::uint8_t> coarse(static_cast<std::size_t>(coarse_side) * coarse_side, 0);
  for (int cj = 0; cj < coarse_side; ++cj)
    for (int ci = 0; ci < coarse_side; ++ci) {
      int count = 0;
      for (int j = cj * block; j < (cj + 1) * block; ++j)
        for (int i = ci * block; i < (ci + 1) * block; ++i)
          count += mask[static_cast<std::size_t>(j) * side + i] != 0;
      coarse[static_cast<std::size_t>(cj) * coarse_side + ci] = 2 * count >= block * block;
    }
  return coarse;
}

// The canonical chunk order: by stage (geometry pass p → p, normal pass p → p + delay, a fine hole mask → the
// manifest's mask stage), then geometry, normals, hole mask, then model. Two-layer normal maps (version 11):
// layer 2's pass q (normal pass base + q) → q + its own delay, so its larger passes land beside the
// geometry passes of the same size as the xyz passes they replace would have; each stream's passes stay in
// order, and at one stage layer 1's pass comes before layer 2's.
struct ChunkKey {
  int stage, kind, model, pass;
};
struct NormalLayers {
  int base_passes = 0;     // layer 1's passes; 0: one layer
  int residual_delay = 0;  // layer 2's stage offset
};
std::vector<ChunkKey> chunk_order(const std::vector<int>& geometry_passes,
                                  const std::vector<int>& normal_passes, const std::vector<bool>& fine_mask,
                                  int normals_delay, int mask_stage,
                                  const std::vector<NormalLayers>& layers) {
  std::vector<ChunkKey> keys;
  for (std::size_t m = 0; m < geometry_passes.size(); ++m) {
    for (int p = 0; p < geometry_passes[m]; ++p) keys.push_back({p, 0, static_cast<int>(m), p});
    const NormalLayers& l = layers[m];
    for (int p = 0; p < normal_passes[m]; ++p)
      keys.push_back(
          {l.base_passes > 0 && p >= l.base_passes ? p - l.base_passes + l.residual_delay : p + normals_delay,
           1, static_cast<int>(m), p});
    if (fine_mask[m]) keys.push_back({mask_stage, 2, static_cast<int>(m), 0});
  }
  std::stable_sort(keys.begin(), keys.end(), [](const ChunkKey& a, const ChunkKey& b) {
    return std::tie(a.stage, a.kind, a.model) < std::tie(b.stage, b.kind, b.model);
  });
  return keys;
}

int passes_of(const GeometryCodecHeader& h) {
  return h.top_bitplane - h.bottom_bitplane + 1;
}

std::uint64_t samples_of(const GeometryCodecHeader& h) {
  const std::uint64_t n = (std::uint64_t{1} << h.level) + 1;
  return n * n * static_cast<std::uint64_t>(h.num_patches);
}

// CRC groups of format version 4 (pack.h): a chunk whose payload has at least `group_bytes` bytes is a group
// of its own; smaller consecutive chunks are gathered until their payloads reach group_bytes. closes[c]:
// chunk c ends its group (its CRC32 trailer follows its payload).
std::vector<bool> crc_group_ends(std::span<const std::uint64_t> payload_sizes, std::uint64_t group_bytes) {
  std::vector<bool> closes(payload_sizes.size(), false);
  std::uint64_t gathered = 0;
  bool open = false;
  for (std::size_t c = 0; c < payload_sizes.size(); ++c) {
    if (payload_sizes[c] >= group_bytes) {
      if (open) closes[c - 1] = true;
      closes[c] = true;
      gathered = 0, open = false;
      continue;
    }
    gathered += payload_sizes[c], open = true;
    if (gathered >= group_bytes) {
      closes[c] = true;
      gathered = 0, open = false;
    }
  }
  if (open) closes.back() = true;
  return closes;
}

constexpr std::uint32_t kCrcBytes = 4;
constexpr std::uint64_t kMaxChunkSize = 0x7fffffff;

Status parse_manifest(std::span<const std::uint8_t> bytes, std::size_t manifest_end, PackInfo& out) {
  ByteReader r(bytes);
  std::uint64_t model_count, normals_delay, mask_stage;
  if (!r.bounded(model_count, kMaxModels) || model_count == 0 || !r.bounded(normals_delay, kMaxPasses) ||
      !r.bounded(mask_stage, kMaxPasses))
    return Status::kCorrupt;
  out.models.assign(static_cast<std::size_t>(model_count), {});
  std::vector<int> geometry_passes, normal_passes;
  std::vector<NormalLayers> layers;
  std::vector<bool> fine_mask;
  std::uint64_t samples = 0;
  const std::vector<PatchSeam>* seams_before = nullptr;  // version 7: the seam table read last
  for (PackModelInfo& model : out.models) {
    std::uint8_t has_normals;
    if (!r.string(model.name, kMaxNameSize) || !read_normalization(r, model.normalization, out.version) ||
        !read_codec_header(r, model.geometry, out.version, seams_before) || !r.u8(has_normals) ||
        has_normals > (out.version >= 11 ? 2 : 1))
      return Status::kCorrupt;
    seams_before = &model.geometry.seams;
    // Pack version v ≤ 3 holds codec headers of version v (1: joint streams, 2: per-patch ones, 3: local
    // frames); version 4 (a container change) those of version 3; version 5 those of versions 3 and 4 (4:
    // the lifting update); versions 6 and 7 those of versions 3 to 5 (5: the filter kCubicLong); versions 8
    // and 9 those of versions 3 to 6 (6: cell frames); version 10 those of versions 3 to 7 (7: a bottom
    // bit-plane).
    const auto codec_version_ok = [&](int v) {
      return out.version >= 10  ? v >= 3
             : out.version >= 8 ? v >= 3 && v <= 6
             : out.version >= 6 ? v >= 3 && v <= 5
             : out.version == 5 ? v == 3 || v == 4
             : out.version == 4 ? v == 3
                                : v == out.version;
    };
    if (!codec_version_ok(model.geometry.version)) return Status::kCorrupt;
    if (model.geometry.level > kMaxPackLevel || passes_of(model.geometry) < 1 ||
        passes_of(model.geometry) > static_cast<int>(kMaxPasses))
      return Status::kCorrupt;
    samples += samples_of(model.geometry);
    model.has_normals = has_normals >= 1;
    model.normal_layers = has_normals == 2 ? 2 : 1;
    if (model.has_normals) {
      if (!read_codec_header(r, model.normals, out.version, seams_before) ||
          !codec_version_ok(model.normals.version) || model.normals.level > kMaxPackLevel ||
          model.normals.num_patches != model.geometry.num_patches || passes_of(model.normals) < 1 ||
          passes_of(model.normals) > static_cast<int>(kMaxPasses))
        return Status::kCorrupt;
      samples += samples_of(model.normals);
      seams_before = &model.normals.seams;
    }
    if (model.normal_layers == 2) {
      // Version 11: layer 1's pass count, the orientation bits, layer 2's header (same level and patches,
      // no seams).
      std::uint64_t base_passes;
      if (!r.bounded(base_passes, static_cast<std::uint64_t>(passes_of(model.normals))) || base_passes == 0 ||
          !read_orientation(r, model.normal_orientation, model.normals.num_patches) ||
          !read_codec_header(r, model.normal_residual, out.version, nullptr) ||
          !codec_version_ok(model.normal_residual.version) ||
          model.normal_residual.level != model.normals.level ||
          model.normal_residual.num_patches != model.normals.num_patches ||
          !model.normal_residual.seams.empty() || passes_of(model.normal_residual) < 1 ||
          passes_of(model.normal_residual) > static_cast<int>(kMaxPasses))
        return Status::kCorrupt;
      model.normal_base_passes = static_cast<int>(base_passes);
      samples += samples_of(model.normal_residual);
    }
    if (model.normal_layers == 2) {
      std::uint64_t delay;
      if (!r.bounded(delay, 2 * kMaxPasses)) return Status::kCorrupt;
      model.normal_residual_delay = static_cast<int>(delay);
    }
    layers.push_back({model.normal_layers == 2 ? model.normal_base_passes : 0, model.normal_residual_delay});
    if (samples > kMaxSamplesPerPack) return Status::kCorrupt;
    std::uint64_t mask_patches;
    if (!r.bounded(mask_patches, static_cast<std::uint64_t>(model.geometry.num_patches)))
      return Status::kCorrupt;
    if (mask_patches != 0 && mask_patches != static_cast<std::uint64_t>(model.geometry.num_patches))
      return Status::kCorrupt;
    model.hole_mask.resize(static_cast<std::size_t>(mask_patches));
    if (mask_patches > 0) {
      std::uint8_t mask_level, coarse_level;
      if (!r.u8(mask_level) || mask_level > model.geometry.level || !r.u8(coarse_level) ||
          coarse_level > mask_level)
        return Status::kCorrupt;
      model.hole_mask_level = coarse_level;
      model.fine_hole_mask_level = mask_level;
    }
    for (auto& mask : model.hole_mask)
      if (!read_mask(r, 1 << model.hole_mask_level, mask)) return Status::kCorrupt;
    fine_mask.push_back(mask_patches > 0 && model.fine_hole_mask_level > model.hole_mask_level);
    geometry_passes.push_back(passes_of(model.geometry));
    normal_passes.push_back(model.normal_passes());
  }
  const std::vector<ChunkKey> order =
      chunk_order(geometry_passes, normal_passes, fine_mask, static_cast<int>(normals_delay),
                  static_cast<int>(mask_stage), layers);
  std::uint64_t group_bytes = 0, chunk_count;
  if (out.version >= 4 && (!r.bounded(group_bytes, kMaxChunkSize) || group_bytes == 0))
    return Status::kCorrupt;
  if (!r.varint(chunk_count) || chunk_count != order.size()) return Status::kCorrupt;
  std::vector<std::uint64_t> sizes(order.size());
  out.chunks.resize(order.size());
  for (std::size_t c = 0; c < order.size(); ++c) {
    // Version 4: the payload, the chunk with its trailer < 2^31 too.
    if (!r.bounded(sizes[c], out.version >= 4 ? kMaxChunkSize - kCrcBytes : kMaxChunkSize))
      return Status::kCorrupt;
    if (out.version < 4 && !r.u32(out.chunks[c].crc32)) return Status::kCorrupt;
  }
  const std::vector<bool> closes =
      out.version >= 4 ? crc_group_ends(sizes, group_bytes) : std::vector<bool>(order.size(), true);
  std::uint64_t offset = manifest_end;
  std::size_t group_first = 0;
  for (std::size_t c = 0; c < order.size(); ++c) {
    ChunkInfo& chunk = out.chunks[c];
    chunk.model = order[c].model;
    chunk.kind = static_cast<ChunkKind>(order[c].kind);
    chunk.pass = order[c].pass;
    chunk.offset = offset;
    chunk.crc_bytes = out.version >= 4 && closes[c] ? kCrcBytes : 0;
    chunk.size = static_cast<std::uint32_t>(sizes[c] + chunk.crc_bytes);
    chunk.group_first = group_first;
    if (closes[c]) group_first = c + 1;
    offset += chunk.size;
  }
  if (r.remaining() != 0) return Status::kCorrupt;
  return Status::kOk;
}

}  // namespace

int PackModelInfo::normal_passes() const {
  if (!has_normals) return 0;
  return normal_layers == 2 ? normal_base_passes + passes_of(normal_residual) : passes_of(normals);
}

namespace {

/// zlib's running CRC-32 over `bytes` (in pieces of at most 1 GiB: zlib takes a uInt length).
uLong crc32_update(uLong crc, std::span<const std::uint8_t> bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - at, 1u << 30);
    crc = ::crc32(crc, bytes.data() + at, static_cast<uInt>(n));
    at += n;
  }
  return crc;
}

}  // namespace

std::uint32_t manifest_crc(std::uint16_t version, std::span<const std::uint8_t> manifest) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  if (version >= 11) {  // from format 11 the version bytes (little-endian) come first
    const std::uint8_t v[2] = {static_cast<std::uint8_t>(version & 0xff),
                               static_cast<std::uint8_t>(version >> 8)};
    crc = crc32_update(crc, v);
  }
  return static_cast<std::uint32_t>(crc32_update(crc, manifest));
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint32_t>(crc32_update(::crc32(0L, Z_NULL, 0), bytes));
}

namespace {

struct FixedHeader {
  std::uint16_t version = 0;
  std::size_t size = 0;  // bytes of the fixed header: the manifest starts here
  std::uint32_t manifest_size = 0, manifest_crc = 0;
};

Status read_fixed_header(std::span<const std::uint8_t> bytes, FixedHeader& out) {
  const std::size_t n = std::min(bytes.size(), sizeof kMagic);
  if (!std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n), kMagic))
    return Status::kCorrupt;
  if (bytes.size() < sizeof kMagic + 2) return Status::kTruncated;
  ByteReader r(bytes.subspan(sizeof kMagic));
  r.u16(out.version);
  if (out.version < kOldestPackVersion || out.version > kPackVersion) return Status::kUnsupportedVersion;
  if (out.version >= 4) {
    std::size_t pos = sizeof kMagic + 2;
    std::uint64_t size = 0;
    switch (detail::read_varint(bytes, pos, size, 4, true)) {
      case detail::VarintRead::kTruncated:
        return Status::kTruncated;
      case detail::VarintRead::kCorrupt:
        return Status::kCorrupt;
      case detail::VarintRead::kOk:
        break;
    }
    if (size > kMaxManifestSize) return Status::kCorrupt;
    if (bytes.size() < pos + 4) return Status::kTruncated;
    ByteReader crc(bytes.subspan(pos));
    crc.u32(out.manifest_crc);
    out.size = pos + 4;
    out.manifest_size = static_cast<std::uint32_t>(size);
    return Status::kOk;
  }
  if (bytes.size() < kPackHeaderSize) return Status::kTruncated;
  std::uint16_t flags = 0;
  r.u16(flags), r.u32(out.manifest_size), r.u32(out.manifest_crc);
  if (flags != 0 || out.manifest_size > kMaxManifestSize) return Status::kCorrupt;
  out.size = kPackHeaderSize;
  return Status::kOk;
}

}  // namespace

Status read_pack_header(std::span<const std::uint8_t> bytes, std::size_t& manifest_end) {
  FixedHeader h;
  if (Status s = read_fixed_header(bytes, h); s != Status::kOk) return s;
  manifest_end = h.size + h.manifest_size;
  return Status::kOk;
}

Status read_pack_info(std::span<const std::uint8_t> bytes, PackInfo& out) {
  out = {};
  FixedHeader h;
  if (Status s = read_fixed_header(bytes, h); s != Status::kOk) return s;
  const std::size_t manifest_end = h.size + h.manifest_size;
  if (bytes.size() < manifest_end) return Status::kTruncated;
  const auto manifest = bytes.subspan(h.size, h.manifest_size);
  if (kCheckCrc && manifest_crc(h.version, manifest) != h.manifest_crc) return Status::kCorrupt;
  out.manifest_end = manifest_end;
  out.version = h.version;
  const Status s = parse_manifest(manifest, manifest_end, out);
  if (s != Status::kOk) out = {};
  return s;
}

namespace {

/// The models with their patches in the canonical order of their (shared) layout, or nullopt when they are
/// in it already, have no such layout, or differ in it (PackWriteOptions::canonical_layout).
std::optional<std::vector<PackModelInput>> canonical_models(const std::vector<PackModelInput>& models) {
  if (models.empty()) return std::nullopt;
  const std::vector<PatchSeam>& seams = models.front().seams;
  const std::size_t patches = models.front().geometry.size();
  for (const PackModelInput& m : models) {
    if (m.geometry.size() != patches || !same_seams(m.seams, seams) ||
        (!m.normals.empty() && m.normals.size() != patches) ||
        (!m.hole_mask.empty() && m.hole_mask.size() != patches))
      return std::nullopt;
  }
  if (patches > static_cast<std::size_t>(std::numeric_limits<int>::max() / 4)) return std::nullopt;
  const auto order = layout_order(seams, static_cast<int>(patches));
  if (!order || order->identity()) return std::nullopt;
  std::vector<PatchSeam> canonical;
  std::size_t used = 0;
  if (!read_layout_code(order->code, static_cast<int>(patches), canonical, used))
    throw std::logic_error("write_pack: a layout code that does not read back");
  std::vector<PackModelInput> out = models;
  for (std::size_t m = 0; m < models.size(); ++m) {
    out[m].seams = canonical;
    for (std::size_t c = 0; c < patches; ++c) {
      const auto p = static_cast<std::size_t>(order->patch[c]);
      const int turn = order->rotation[c];
      out[m].geometry[c] = rotate_grid(models[m].geometry[p], turn);
      if (!models[m].normals.empty()) out[m].normals[c] = rotate_grid(models[m].normals[p], turn);
      if (!models[m].hole_mask.empty()) out[m].hole_mask[c] = rotate_quad_mask(models[m].hole_mask[p], turn);
    }
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> write_pack(const std::vector<PackModelInput>& models,
                                     const PackWriteOptions& options) {
  if (options.canonical_layout) {
    if (auto canonical = canonical_models(models)) {
      PackWriteOptions plain = options;
      plain.canonical_layout = false;
      return write_pack(*canonical, plain);
    }
  }
  if (models.empty()) throw std::invalid_argument("write_pack: no models");
  if (models.size() > kMaxModels) throw std::invalid_argument("write_pack: more than 64 models");
  if (options.normals_delay < 0 || options.normals_delay > static_cast<int>(kMaxPasses))
    throw std::invalid_argument("write_pack: normals_delay outside [0, 64]");
  if (options.crc_group_bytes < 1 || options.crc_group_bytes > kMaxChunkSize)
    throw std::invalid_argument("write_pack: crc_group_bytes outside [1, 2^31)");
  {
    // The readers' bound (read_pack_info: kMaxSamplesPerPack): a pack they would refuse is not written.
    std::uint64_t samples = 0;
    for (const PackModelInput& model : models) {
      for (const Grid3& g : model.geometry) samples += static_cast<std::uint64_t>(g.size()) * g.size();
      if (options.normals)  // two layers: the residual grids count as well
        for (const Grid3& g : model.normals)
          samples += static_cast<std::uint64_t>(options.normal_layers) * g.size() * g.size();
    }
    if (samples > kMaxSamplesPerPack)
      throw std::invalid_argument("write_pack: " + std::to_string(samples) +
                                  " samples (geometry and normal maps), more than a pack holds (2^25)");
  }
  if (options.normal_layers != 1 && options.normal_layers != 2)
    throw std::invalid_argument("write_pack: normal_layers must be 1 or 2");
  if (!(options.normal_base_bytes_per_texel > 0) || !std::isfinite(options.normal_base_bytes_per_texel) ||
      !(options.normal_residual_step > 0) || !std::isfinite(options.normal_residual_step))
    throw std::invalid_argument(
        "write_pack: normal_base_bytes_per_texel and normal_residual_step must be positive");
  std::vector<EncodedGeometry> geometry(models.size()), normals(models.size()), residual(models.size());
  std::vector<int> base_passes(models.size(), 0);  // layer 1's passes; 0 = one layer
  std::vector<NormalOrientation> orientation(models.size());
  std::vector<int> geometry_passes, normal_passes, mask_level;
  for (std::size_t m = 0; m < models.size(); ++m) {
    const PackModelInput& model = models[m];
    if (model.name.size() > kMaxNameSize) throw std::invalid_argument("write_pack: model name too long");
    if (model.geometry.empty())
      throw std::invalid_argument("write_pack: model '" + model.name + "' has no patches");
    if (model.geometry.front().level > kMaxPackLevel)
      throw std::invalid_argument("write_pack: level above " + std::to_string(kMaxPackLevel));
    geometry[m] = encode_geometry(model.geometry, model.seams, options.geometry);
    geometry_passes.push_back(static_cast<int>(geometry[m].segments.size()));
    const bool with_normals = options.normals && !model.normals.empty();
    if (with_normals) {
      if (model.normals.size() != model.geometry.size())
        throw std::invalid_argument("write_pack: model '" + model.name + "': normal maps and patches differ");
      normals[m] = encode_geometry(model.normals, model.seams, options.normal_codec);
      if (options.normal_layers == 2) {
        // Layer 1: the xyz stream's first passes that hold the base bytes; layer 2 only when passes remain.
        std::uint64_t texels = 0;
        for (const Grid3& g : model.normals) texels += static_cast<std::uint64_t>(g.size()) * g.size();
        const double base = options.normal_base_bytes_per_texel * static_cast<double>(texels);
        std::size_t bytes = 0, passes = 0;
        while (passes < normals[m].segments.size() && static_cast<double>(bytes) < base)
          bytes += normals[m].segments[passes++].size();
        if (passes >= 1 && passes < normals[m].segments.size()) {
          base_passes[m] = static_cast<int>(passes);
          std::vector<std::span<const std::uint8_t>> first;
          for (std::size_t k = 0; k < passes; ++k) first.emplace_back(normals[m].segments[k]);
          DecodedGeometry axes, decoded;
          if (decode_geometry(normals[m].header, first, {}, axes) != Status::kOk)
            throw std::logic_error("write_pack: layer 1 of the normal maps does not decode");
          normalize_normal_maps(axes.patches);
          std::vector<std::span<const std::uint8_t>> all;
          for (const auto& seg : geometry[m].segments) all.emplace_back(seg);
          if (decode_geometry(geometry[m].header, all, {}, decoded) != Status::kOk)
            throw std::logic_error("write_pack: the geometry does not decode");
          orientation[m] = normal_orientation(axes.patches, decoded.patches);
          const std::vector<Grid3> grids =
              normal_residual(model.normals, decoded.patches, orientation[m], &axes.patches);
          // The residual's step: normal_residual_step times the xyz stream's nominal one (its extent 2 over
          // 2^bits), so layer 2 ends at about the angular precision of the xyz stream it replaces.
          float lo = 0, hi = 0;
          for (const Grid3& g : grids)
            for (std::size_t k = 0; k + 2 < g.values.size(); k += 3)
              for (int c = 0; c < 2; ++c)
                lo = std::min(lo, g.values[k + c]), hi = std::max(hi, g.values[k + c]);
          const double target =
              options.normal_residual_step * 2.0 / std::ldexp(1.0, options.normal_codec.quantization_bits);
          GeometryCodecOptions codec = options.normal_codec;
          codec.quantization_bits =
              std::clamp(static_cast<int>(std::ceil(std::log2(std::max(double(hi - lo), target) / target))),
                         1, options.normal_codec.quantization_bits);
          residual[m] = encode_geometry(grids, {}, codec);
        }
      }
    }
    normal_passes.push_back(!with_normals ? 0
                            : base_passes[m] > 0
                                ? base_passes[m] + static_cast<int>(residual[m].segments.size())
                                : static_cast<int>(normals[m].segments.size()));
    const int level = model.geometry.front().level;
    mask_level.push_back(model.hole_mask_level < 0 ? level : model.hole_mask_level);
    if (mask_level.back() > level)
      throw std::invalid_argument("write_pack: model '" + model.name + "': hole mask level above the grid's");
    if (!model.hole_mask.empty()) {
      const std::size_t quads = std::size_t{1} << (2 * mask_level.back());
      if (model.hole_mask.size() != model.geometry.size() ||
          std::any_of(model.hole_mask.begin(), model.hole_mask.end(),
                      [&](const auto& mask) { return mask.size() != quads; }))
        throw std::invalid_argument("write_pack: model '" + model.name +
                                    "': hole mask does not match the grid");
    }
  }

  // Hole masks: the coarse one (2 levels up) in the manifest, the fine one in a chunk after the geometry pass
  // where the pack passes options.hole_mask_after_bytes.
  std::vector<std::vector<std::vector<std::uint8_t>>> coarse_masks(models.size());
  std::vector<int> coarse_level(models.size(), 0);
  std::vector<bool> fine_mask(models.size(), false);
  std::vector<std::vector<std::uint8_t>> fine_mask_bytes(models.size());
  for (std::size_t m = 0; m < models.size(); ++m) {
    if (models[m].hole_mask.empty()) continue;
    coarse_level[m] = std::max(0, mask_level[m] - std::max(0, options.coarse_hole_mask_levels));
    const int shift = mask_level[m] - coarse_level[m];
    for (const auto& mask : models[m].hole_mask)
      coarse_masks[m].push_back(coarsen_mask(mask, 1 << mask_level[m], shift));
    fine_mask[m] = shift > 0;
    if (fine_mask[m])
      fine_mask_bytes[m] = encode_fine_masks(models[m].hole_mask, coarse_masks[m], 1 << mask_level[m], shift);
  }
  int mask_stage = 0;
  {
    std::size_t total = 0;
    const int max_passes = *std::max_element(geometry_passes.begin(), geometry_passes.end());
    for (mask_stage = 0; mask_stage + 1 < max_passes; ++mask_stage) {
      for (std::size_t m = 0; m < models.size(); ++m)
        if (mask_stage < geometry_passes[m])
          total += geometry[m].segments[static_cast<std::size_t>(mask_stage)].size();
      if (total >= options.hole_mask_after_bytes) break;
    }
  }

  // Layer 2's stage offset: its first passes that hold fewer bytes than layer 1's last (the residual's top
  // planes, nearly empty) go before that pass's stage, the next one right after it.
  std::vector<NormalLayers> layers(models.size());
  for (std::size_t m = 0; m < models.size(); ++m) {
    if (base_passes[m] == 0) continue;
    const std::size_t last = normals[m].segments[static_cast<std::size_t>(base_passes[m] - 1)].size();
    std::size_t bytes = 0;
    int lead = 0;
    while (lead < static_cast<int>(residual[m].segments.size()) &&
           bytes + residual[m].segments[static_cast<std::size_t>(lead)].size() < last)
      bytes += residual[m].segments[static_cast<std::size_t>(lead++)].size();
    layers[m] = {base_passes[m], std::max(0, base_passes[m] + options.normals_delay - lead)};
  }

  ByteWriter manifest;
  const std::vector<PatchSeam>* seams_before = nullptr;  // the seam table written last
  manifest.varint(models.size());
  manifest.varint(static_cast<std::uint64_t>(options.normals_delay));
  manifest.varint(static_cast<std::uint64_t>(mask_stage));
  for (std::size_t m = 0; m < models.size(); ++m) {
    manifest.string(models[m].name);
    write_normalization(manifest, models[m].normalization, kPackVersion);
    write_codec_header(manifest, geometry[m].header, kPackVersion, seams_before);
    seams_before = &geometry[m].header.seams;
    manifest.u8(normal_passes[m] == 0 ? 0 : base_passes[m] > 0 ? 2 : 1);
    if (normal_passes[m] > 0) {
      write_codec_header(manifest, normals[m].header, kPackVersion, seams_before);
      seams_before = &normals[m].header.seams;
    }
    if (base_passes[m] > 0) {
      manifest.varint(static_cast<std::uint64_t>(base_passes[m]));
      write_orientation(manifest, orientation[m], normals[m].header.num_patches);
      write_codec_header(manifest, residual[m].header, kPackVersion, nullptr);
      manifest.varint(static_cast<std::uint64_t>(layers[m].residual_delay));
    }
    manifest.varint(models[m].hole_mask.size());
    if (!models[m].hole_mask.empty()) {
      manifest.u8(static_cast<std::uint8_t>(mask_level[m]));
      manifest.u8(static_cast<std::uint8_t>(coarse_level[m]));
    }
    for (const auto& mask : coarse_masks[m]) write_mask(manifest, mask, 1 << coarse_level[m]);
  }
  const std::vector<ChunkKey> order =
      chunk_order(geometry_passes, normal_passes, fine_mask, options.normals_delay, mask_stage, layers);
  auto segment = [&](const ChunkKey& key) -> const std::vector<std::uint8_t>& {
    if (key.kind == 2) return fine_mask_bytes[static_cast<std::size_t>(key.model)];
    const std::size_t m = static_cast<std::size_t>(key.model);
    if (key.kind == 1 && base_passes[m] > 0 && key.pass >= base_passes[m])
      return residual[m].segments[static_cast<std::size_t>(key.pass - base_passes[m])];
    const auto& encoded = key.kind == 0 ? geometry[m] : normals[m];
    return encoded.segments[static_cast<std::size_t>(key.pass)];
  };
  std::vector<std::uint64_t> sizes;
  for (const ChunkKey& key : order) {
    sizes.push_back(segment(key).size());
    if (sizes.back() > kMaxChunkSize - kCrcBytes)
      throw std::invalid_argument("write_pack: a chunk over 2 GiB");
  }
  manifest.varint(options.crc_group_bytes);
  manifest.varint(order.size());
  for (std::uint64_t size : sizes) manifest.varint(size);
  const std::vector<bool> closes = crc_group_ends(sizes, options.crc_group_bytes);

  ByteWriter file;
  for (std::uint8_t b : kMagic) file.u8(b);
  file.u16(kPackVersion);
  file.varint(manifest.data().size());
  file.u32(manifest_crc(kPackVersion, manifest.data()));
  std::vector<std::uint8_t>& out = file.data();
  out.insert(out.end(), manifest.data().begin(), manifest.data().end());
  std::size_t group_begin = out.size();
  for (std::size_t c = 0; c < order.size(); ++c) {
    out.insert(out.end(), segment(order[c]).begin(), segment(order[c]).end());
    if (!closes[c]) continue;
    const std::uint32_t crc =
        crc32(std::span<const std::uint8_t>(out).subspan(group_begin, out.size() - group_begin));
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
    group_begin = out.size();
  }
  return std::move(out);
}

struct PackDecoder::State {
  PackDecodeOptions options;
  bool have_info = false;
  bool failed = false;      // an allocation failed on a hostile manifest: no models
  bool crc_failed = false;  // decoding stopped at a chunk that failed its CRC
  Status status = Status::kOk;
  PackInfo info;
  std::size_t next_chunk = 0;  // first chunk not yet complete and verified
  std::size_t chunks_decoded = 0, bytes_used = 0;
  struct Model {
    // Streams: 0 geometry, 1 normal maps (layer 1 of two), 2 layer 2 of two-layer normal maps.
    std::array<GeometryDecoder, 3> decoder;
    std::array<std::vector<std::size_t>, 3> chunks;  // verified chunks of each stream
    std::array<Status, 3> status{Status::kOk, Status::kOk, Status::kOk};
    // The last update fed the stream bytes not yet verified (the open CRC group, see update()).
    std::array<bool, 3> tentative{false, false, false};
    bool with_normals = false, two_layers = false;
    bool has_fine_mask = false;
    std::vector<std::vector<std::uint8_t>> fine_mask;
    std::size_t tentative_geometry_passes = 0;  // complete geometry chunks among them
  };
  std::vector<Model> models;

  std::span<const std::uint8_t> payload(std::span<const std::uint8_t> data, std::size_t c) const {
    return data.subspan(static_cast<std::size_t>(info.chunks[c].offset), info.chunks[c].payload_size());
  }
  /// The stream a geometry or normal chunk belongs to.
  std::size_t stream_of(const ChunkInfo& chunk) const {
    if (chunk.kind == ChunkKind::kGeometry) return 0;
    const PackModelInfo& mi = info.models[static_cast<std::size_t>(chunk.model)];
    return mi.normal_layers == 2 && chunk.pass >= mi.normal_base_passes ? 2 : 1;
  }
  /// Feeds one model's stream its verified chunks, then the complete chunks `extra` and `tail` (a byte
  /// prefix of the chunk after them).
  void feed(std::span<const std::uint8_t> data, Model& m, std::size_t stream,
            std::span<const std::size_t> extra, std::span<const std::uint8_t> tail) {
    const auto& list = m.chunks[stream];
    std::vector<std::span<const std::uint8_t>> segments;
    segments.reserve(list.size() + extra.size());
    for (std::size_t c : list) segments.push_back(payload(data, c));
    for (std::size_t c : extra) segments.push_back(payload(data, c));
    m.status[stream] = m.decoder[stream].update(segments, tail);
  }
  void reset_stream(Model& m, std::size_t index, std::size_t stream) {
    const PackModelInfo& mi = info.models[index];
    if (stream == 0)
      m.decoder[0].reset(
          mi.geometry, {.drop_finest_steps = options.drop_finest_steps, .max_threads = options.max_threads});
    else
      m.decoder[stream].reset(stream == 1 ? mi.normals : mi.normal_residual,
                              {.max_threads = options.max_threads});
  }
};

PackDecoder::PackDecoder(const PackDecodeOptions& options) : s_(std::make_unique<State>()) {
  s_->options = options;
}
PackDecoder::~PackDecoder() = default;
PackDecoder::PackDecoder(PackDecoder&&) noexcept = default;
PackDecoder& PackDecoder::operator=(PackDecoder&&) noexcept = default;

void PackDecoder::update(std::span<const std::uint8_t> bytes) {
  State& st = *s_;
  if (st.failed) return;
  const PackDecodeOptions& options = st.options;
  const std::span<const std::uint8_t> data = bytes.first(std::min(bytes.size(), options.max_bytes));
  try {
    if (!st.have_info) {
      st.status = read_pack_info(data, st.info);
      if (st.status != Status::kOk) return;
      st.have_info = true;
      st.models.resize(st.info.models.size());
      for (std::size_t m = 0; m < st.models.size(); ++m) {
        State::Model& model = st.models[m];
        model.with_normals = options.normals && st.info.models[m].has_normals;
        model.two_layers = model.with_normals && st.info.models[m].normal_layers == 2;
        st.reset_stream(model, m, 0);
        if (model.with_normals) st.reset_stream(model, m, 1);
        if (model.two_layers) st.reset_stream(model, m, 2);
      }
    }
    const PackInfo& info = st.info;
    // Complete CRC groups (versions 1–3: single chunks), CRC-checked, in order; decoding stops for good at
    // the first that fails.
    while (!st.crc_failed && st.next_chunk < info.chunks.size()) {
      const std::size_t first = st.next_chunk;
      std::size_t last = first;
      if (info.version >= 4)
        while (last + 1 < info.chunks.size() && info.chunks[last].crc_bytes == 0) ++last;
      const ChunkInfo& end = info.chunks[last];
      if (end.offset + end.size > data.size()) break;
      bool crc_ok = true;
      if (info.version >= 4) {
        const auto group = data.subspan(
            static_cast<std::size_t>(info.chunks[first].offset),
            static_cast<std::size_t>(end.offset + end.payload_size() - info.chunks[first].offset));
        ByteReader trailer(data.subspan(static_cast<std::size_t>(end.offset + end.payload_size()), 4));
        std::uint32_t crc = 0;
        crc_ok = end.crc_bytes == kCrcBytes && trailer.u32(crc) && (!kCheckCrc || crc32(group) == crc);
      } else {
        crc_ok = !kCheckCrc || crc32(st.payload(data, first)) == end.crc32;
      }
      if (!crc_ok) {
        st.crc_failed = true;  // streams fed bytes of this group tentatively start over below
        break;
      }
      for (std::size_t c = first; c <= last; ++c) {
        const ChunkInfo& chunk = info.chunks[c];
        State::Model& m = st.models[static_cast<std::size_t>(chunk.model)];
        if (chunk.kind == ChunkKind::kHoleMask) {
          const PackModelInfo& mi = info.models[static_cast<std::size_t>(chunk.model)];
          const int shift = mi.fine_hole_mask_level - mi.hole_mask_level;
          (info.version == 1 ? decode_fine_masks_v1 : decode_fine_masks)(
              st.payload(data, c), mi.hole_mask, 1 << mi.fine_hole_mask_level, shift, m.fine_mask);
          m.has_fine_mask = true;
        } else {
          m.chunks[st.stream_of(chunk)].push_back(c);
        }
        ++st.chunks_decoded;
      }
      st.next_chunk = last + 1;
    }
    // The open group (the first one not verified: incomplete, or its trailer missing), with
    // options.partial_chunks: its complete chunks and a byte prefix of the first incomplete one, unverified,
    // as embedded streams (versions 1–3: the first incomplete chunk only). Hole masks wait for their CRC.
    // Should the group's CRC fail once complete, the streams fed from it decode again without it.
    st.bytes_used = st.next_chunk == 0 ? info.manifest_end
                                       : static_cast<std::size_t>(info.chunks[st.next_chunk - 1].offset +
                                                                  info.chunks[st.next_chunk - 1].size);
    st.status = st.crc_failed ? Status::kCorrupt : Status::kOk;
    struct Open {
      std::vector<std::size_t> complete;
      std::span<const std::uint8_t> tail;
    };
    std::vector<std::array<Open, 3>> open(st.models.size());
    if (!st.crc_failed && st.next_chunk < info.chunks.size()) {
      st.status = Status::kTruncated;
      for (std::size_t c = st.next_chunk; options.partial_chunks && c < info.chunks.size(); ++c) {
        const ChunkInfo& chunk = info.chunks[c];
        if (chunk.offset >= data.size()) break;
        const bool complete = chunk.offset + chunk.payload_size() <= data.size();
        if (chunk.kind != ChunkKind::kHoleMask && (chunk.kind == ChunkKind::kGeometry || options.normals)) {
          Open& o = open[static_cast<std::size_t>(chunk.model)][st.stream_of(chunk)];
          if (complete)
            o.complete.push_back(c);
          else
            o.tail = data.subspan(static_cast<std::size_t>(chunk.offset));
          st.bytes_used = static_cast<std::size_t>(
              std::min<std::uint64_t>(data.size(), chunk.offset + chunk.payload_size()));
        }
        if (!complete || chunk.crc_bytes > 0 || info.version < 4) break;  // the group (v1–3: chunk) ends
      }
    }
    for (std::size_t m = 0; m < st.models.size(); ++m) {
      State::Model& model = st.models[m];
      const auto stream = [&](std::size_t k) {
        const Open& o = open[m][k];
        if (st.crc_failed && model.tentative[k]) st.reset_stream(model, m, k);
        st.feed(data, model, k, o.complete, o.tail);
        model.tentative[k] = !o.complete.empty() || !o.tail.empty();
      };
      stream(0);
      model.tentative_geometry_passes = open[m][0].complete.size();
      if (model.with_normals) stream(1);
      if (model.two_layers) stream(2);
    }
  } catch (const std::exception&) {
    // The decoders do not throw on bytes; a failed allocation on a hostile manifest lands here.
    st.failed = true;
    st.status = Status::kCorrupt;
    st.models.clear();
  }
}

PackDecodeResult PackDecoder::result(int drop_finest_steps, bool normals) {
  return make_result(drop_finest_steps, normals, false);
}

PackDecodeResult PackDecoder::take_result(int drop_finest_steps, bool normals) {
  return make_result(drop_finest_steps, normals, true);
}

PackDecodeResult PackDecoder::make_result(int drop_finest_steps, bool normals, bool take) {
  State& st = *s_;
  PackDecodeResult result;
  result.status = st.status;
  if (!st.have_info) return result;
  result.info = st.info;
  result.chunks_decoded = st.chunks_decoded;
  result.bytes_used = st.bytes_used;
  if (st.failed) return result;
  try {
    for (std::size_t m = 0; m < st.models.size(); ++m) {
      const PackModelInfo& model_info = st.info.models[m];
      State::Model& sm = st.models[m];
      DecodedModel model;
      model.name = model_info.name;
      model.normalization = model_info.normalization;
      model.seams = model_info.geometry.seams;
      model.hole_mask = model_info.hole_mask;
      model.hole_mask_level = model_info.hole_mask_level;
      if (sm.has_fine_mask) {
        model.hole_mask = sm.fine_mask;
        model.hole_mask_level = model_info.fine_hole_mask_level;
      }
      model.geometry_passes = sm.chunks[0].size() + sm.tentative_geometry_passes;
      const auto decode = [&](std::size_t k, int drop) {
        DecodedGeometry decoded;
        if (take) {
          sm.decoder[k].take_result(decoded, drop);
        } else {
          sm.decoder[k].result(decoded, drop);
        }
        return decoded;
      };
      DecodedGeometry decoded = decode(0, drop_finest_steps);
      if (sm.status[0] != Status::kOk) result.status = Status::kCorrupt;
      model.geometry = std::move(decoded.patches);
      model.detail_level = decoded.detail_level;
      const auto any = [&](std::size_t k) { return !sm.chunks[k].empty() || sm.tentative[k]; };
      if (sm.with_normals && any(1)) {
        if (sm.status[1] != Status::kOk || (sm.two_layers && sm.status[2] != Status::kOk))
          result.status = Status::kCorrupt;
        if (normals) {
          model.normals = decode(1, -1).patches;
          normalize_normal_maps(model.normals);
          if (sm.two_layers && any(2)) {
            // Layer 2: the residual in frames around layer 1's normals and the geometry decoded so far;
            // the seams glue the result as layer 1's stream glued its samples.
            std::vector<Grid3> maps = decode(2, -1).patches;
            apply_normal_residual(maps, model.geometry, model_info.normal_orientation, &model.normals,
                                  st.options.max_threads);
            copy_seam_samples(maps, model_info.normals.seams);
            model.normals = std::move(maps);
          }
        }
      }
      result.models.push_back(std::move(model));
    }
  } catch (const std::exception&) {
    result.status = Status::kCorrupt;
    result.models.clear();
  }
  return result;
}

PackDecodeResult decode_pack(std::span<const std::uint8_t> bytes, const PackDecodeOptions& options) {
  PackDecoder decoder(options);
  decoder.update(bytes);
  return decoder.take_result();
}

}  // namespace geomip::codec
