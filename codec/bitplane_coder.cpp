#include "codec/bitplane_coder.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

#include "codec/arithmetic_coder.h"
#include "codec/byte_io.h"
#include "codec/parallel.h"

namespace geomip::codec {
namespace {

constexpr std::uint8_t kSig = 1;     // node state: known significant
constexpr std::uint8_t kActive = 2;  // node state: covers at least one coded sample
constexpr int kMaxQuadLevels = 16;

/// A sample of the significant-sample list. flags: bit c = channel c significant, bit 3 + c = its sign.
struct Sample {
  std::uint32_t index;   ///< grid index j·size + i
  std::uint32_t mag[3];  ///< decoder: known magnitude bits; encoder: unused
  std::uint8_t q[3];     ///< lowest plain plane known (decoder)
  std::uint8_t flags;
};

struct Band {
  int patch = 0, k = 0, orient = 0;  // orient 0: coarse, 1: row details, 2: column details, 3: diagonal
  int cls = 0, kcls = 0, offset = 0;
  int x0 = 0, y0 = 0, dx = 1, dy = 1, w = 0, h = 0;
  int start = -1;  // deferred band: first weighted plane coded (−1: from the top)
  int levels = 0;
  int lw[kMaxQuadLevels] = {}, lh[kMaxQuadLevels] = {};
  std::size_t lbase[kMaxQuadLevels] = {};
  std::vector<std::uint8_t> state;
  std::vector<std::int8_t> msb;  // encoder: highest set bit of the node's max magnitude, −1 if zero
  int parent = -1;
  std::vector<std::uint32_t> lis, lis_next;
  std::vector<Sample> lsp;
  std::size_t refine_count = 0;

  std::size_t node(int l, int x, int y) const { return lbase[l] + static_cast<std::size_t>(y) * lw[l] + x; }
  std::uint32_t grid_index(int x, int y, int size) const {
    return static_cast<std::uint32_t>((y0 + dy * y) * size + x0 + dx * x);
  }
};

inline std::uint32_t pack(int l, int x, int y) {
  return static_cast<std::uint32_t>(l) << 28 | static_cast<std::uint32_t>(x) << 14 |
         static_cast<std::uint32_t>(y);
}

/// The order in which the bytes of P streams are interleaved in a segment, a function of their sizes only:
/// byte k of stream p sits at "time" (k + ½)/size_p, and the bytes are merged by time (ties: lower p
/// first). A byte prefix of the segment therefore holds about the same fraction of every patch's stream, as
/// the joint coder of version 1 would have sent them, and a decoder that knows the sizes takes its streams
/// apart without decoding anything.
constexpr std::uint64_t kMaxStreamBytes = std::uint64_t{1} << 30;

class Interleaver {
 public:
  explicit Interleaver(std::span<const std::uint64_t> sizes) : sizes_(sizes), taken_(sizes.size(), 0) {}
  /// The stream the next byte belongs to, or −1 when all are exhausted.
  int next() {
    int best = -1;
    for (std::size_t p = 0; p < sizes_.size(); ++p) {
      if (taken_[p] >= sizes_[p]) continue;
      // (2·taken_p + 1) / size_p < (2·taken_b + 1) / size_b, cross-multiplied (sizes ≤ kMaxStreamBytes:
      // the products stay below 2^63).
      const auto b = static_cast<std::size_t>(best);
      if (best < 0 || (2 * taken_[p] + 1) * sizes_[b] < (2 * taken_[b] + 1) * sizes_[p]) {
        best = static_cast<int>(p);
      }
    }
    if (best >= 0) ++taken_[static_cast<std::size_t>(best)];
    return best;
  }

 private:
  std::span<const std::uint64_t> sizes_;
  std::vector<std::uint64_t> taken_;
};

struct Stop {};     // the partial tail is exhausted
struct Corrupt {};  // bytes that no encoder writes

bool layout_ok(const BitplaneLayout& layout) {
  for (int v : layout.start_plane) {
    if (v < -1 || v > 64) return false;
  }
  return layout.level >= 0 && layout.level <= 12 && layout.steps >= 0 && layout.steps <= layout.level &&
         layout.num_patches >= 1 && layout.joint_segments >= 0;
}

/// The bands of every patch (only_patch < 0) or of one patch, in coding order; Band::parent indexes the
/// returned list. The bands' quadtrees are set up on up to `max_threads` threads (by patch).
std::vector<Band> make_bands(const BitplaneLayout& layout,
                             const std::vector<std::vector<std::uint8_t>>& coded, int only_patch = -1,
                             int max_threads = 1) {
  const int size = (1 << layout.level) + 1;
  const int steps = layout.steps;
  const int first = only_patch < 0 ? 0 : only_patch;
  const int np = only_patch < 0 ? layout.num_patches : 1;  // patches in the list
  std::vector<Band> bands;
  bands.reserve(static_cast<std::size_t>(np) * (1 + 3 * steps));
  for (int p = first; p < first + np; ++p) {
    Band b;
    b.patch = p;
    b.k = steps + 1;
    b.orient = 0;
    b.cls = 0;
    b.kcls = 2;
    b.offset = band_offset(layout, b.k, 0);
    b.dx = b.dy = 1 << steps;
    b.w = b.h = (size - 1) / b.dx + 1;
    bands.push_back(std::move(b));
  }
  for (int k = steps; k >= 1; --k) {
    const int s = 1 << (k - 1), intervals = (size - 1) / s;
    for (int orient = 1; orient <= 3; ++orient) {
      for (int p = first; p < first + np; ++p) {
        Band b;
        b.patch = p;
        b.k = k;
        b.orient = orient;
        b.cls = orient == 3 ? 2 : 1;
        b.kcls = std::min(k - 1, 2);
        b.offset = band_offset(layout, k, orient);
        b.start = layout.start_plane[static_cast<std::size_t>(k)];
        // Deferred (framed) bands hold (normal, tangent, bitangent) components: contexts of their own.
        if (b.start >= 0 && layout.own_deferred_contexts) b.cls += 2;
        b.dx = b.dy = 2 * s;
        const bool odd_x = orient != 2, odd_y = orient != 1;
        b.x0 = odd_x ? s : 0;
        b.y0 = odd_y ? s : 0;
        b.w = odd_x ? intervals / 2 : intervals / 2 + 1;
        b.h = odd_y ? intervals / 2 : intervals / 2 + 1;
        if (k < steps) b.parent = np + ((steps - (k + 1)) * 3 + (orient - 1)) * np + (p - first);
        bands.push_back(std::move(b));
      }
    }
  }
  const auto set_up = [&](Band& b) {
    int w = b.w, h = b.h;
    std::size_t total = 0;
    b.levels = 0;
    while (true) {
      b.lw[b.levels] = w;
      b.lh[b.levels] = h;
      b.lbase[b.levels] = total;
      total += static_cast<std::size_t>(w) * h;
      ++b.levels;
      if (w == 1 && h == 1) break;
      w = (w + 1) / 2;
      h = (h + 1) / 2;
    }
    b.state.assign(total, 0);
    const auto& mask = coded[b.patch];
    for (int y = 0; y < b.h; ++y) {
      for (int x = 0; x < b.w; ++x) {
        if (mask[b.grid_index(x, y, size)]) b.state[b.node(0, x, y)] = kActive;
      }
    }
    for (int l = 1; l < b.levels; ++l) {
      for (int y = 0; y < b.lh[l - 1]; ++y) {
        for (int x = 0; x < b.lw[l - 1]; ++x)
          b.state[b.node(l, x >> 1, y >> 1)] |= b.state[b.node(l - 1, x, y)];
      }
    }
    const int top = b.levels - 1;
    if (b.state[b.node(top, 0, 0)] & kActive) b.lis.push_back(pack(top, 0, 0));
  };
  parallel_for(np, max_threads, [&](int i) {
    for (auto& b : bands) {
      if (b.patch == first + i) set_up(b);
    }
  });
  return bands;
}

constexpr int kClasses = 5;  // coarse, row/column, diagonal; deferred row/column, deferred diagonal
constexpr int kNodeContexts = kClasses * 3 * 4 * 3 * 2;

/// The shared traversal of encoder and decoder: every decision goes through sym(), so both walk the same
/// path.
template <bool kDecode>
class PlaneCoder {
 public:
  /// Codes the bands of `bands` whose patch is `patch` (−1: all of them) with its own contexts.
  PlaneCoder(const BitplaneLayout& layout, std::vector<Band>& bands, int patch,
             const std::vector<PatchCoefficients>* coefs)
      : size_((1 << layout.level) + 1), bands_(bands), coefs_(coefs) {
    for (auto& b : bands) {
      if (patch < 0 || b.patch == patch) mine_.push_back(&b);
    }
  }

  void set_encoder(ArithmeticEncoder* enc) { enc_ = enc; }
  /// Continues from another coder's adaptive state (the joint coder's, at the fork to per-patch coders).
  void copy_contexts(const PlaneCoder& other) {
    std::copy(std::begin(other.node_ctx_), std::end(other.node_ctx_), std::begin(node_ctx_));
    std::copy(std::begin(other.chan_ctx_), std::end(other.chan_ctx_), std::begin(chan_ctx_));
    std::copy(std::begin(other.late_ctx_), std::end(other.late_ctx_), std::begin(late_ctx_));
    std::copy(std::begin(other.ref_ctx_), std::end(other.ref_ctx_), std::begin(ref_ctx_));
  }
  /// Decodes the next plane from `bytes` (held by value: a decoder behind a pointer costs a dependent load
  /// per symbol).
  void set_decoder(std::span<const std::uint8_t> bytes) { dec_ = ArithmeticDecoder(bytes); }

  /// One weighted bit-plane: sorting pass over every band, then refinement pass over every band.
  /// kCheck: the stream may be a byte prefix; stop (throw Stop) before the first symbol that needs a byte
  /// past it.
  template <bool kCheck>
  void code_plane(int b) {
    for (Band* band : mine_) band->refine_count = band->lsp.size();
    for (Band* bp : mine_) {
      Band& band = *bp;
      const int p = b - band.offset;
      if (p < 0 || band.lis.empty() || (band.start >= 0 && b > band.start)) continue;
      band.lis_next.clear();
      // lis is swapped only after the loop; process() appends to lis_next only.
      for (std::size_t n = 0; n < band.lis.size(); ++n) {
        const std::uint32_t packed = band.lis[n];
        process<kCheck>(band, static_cast<int>(packed >> 28), static_cast<int>((packed >> 14) & 0x3FFF),
                        static_cast<int>(packed & 0x3FFF), p, false);
      }
      std::swap(band.lis, band.lis_next);
    }
    for (Band* bp : mine_) {
      const int p = b - bp->offset;
      if (p < 0) continue;
      refine<kCheck>(*bp, p);
    }
  }

 private:
  template <bool kCheck>
  int sym(int bit, Context& ctx) {
    if constexpr (kDecode) {
      if (kCheck && dec_.exhausted()) throw Stop{};
      return dec_.decode(ctx);
    } else {
      enc_->encode(bit, ctx);
      return bit;
    }
  }
  template <bool kCheck>
  int raw(int bit) {
    if constexpr (kDecode) {
      if (kCheck && dec_.exhausted()) throw Stop{};
      return dec_.decode_bypass();
    } else {
      enc_->encode_bypass(bit);
      return bit;
    }
  }

  int node_context(const Band& band, int l, int x, int y) const {
    const std::uint8_t* st = band.state.data() + band.lbase[l];
    const int w = band.lw[l], h = band.lh[l];
    const std::size_t at = static_cast<std::size_t>(y) * w + x;
    int nbr = 0;
    if (x > 0) nbr += st[at - 1] & kSig;
    if (x + 1 < w) nbr += st[at + 1] & kSig;
    if (y > 0) nbr += st[at - w] & kSig;
    if (y + 1 < h) nbr += st[at + w] & kSig;
    nbr = std::min(nbr, 2);
    int par = 0;
    if (band.parent >= 0) {
      const Band& pb = bands_[band.parent];
      const int pl = l > 0 ? l - 1 : 0, px = l > 0 ? x : x >> 1, py = l > 0 ? y : y >> 1;
      if (pl < pb.levels && px < pb.lw[pl] && py < pb.lh[pl]) par = pb.state[pb.node(pl, px, py)] & kSig;
    }
    return ((((band.cls * 3 + band.kcls) * 4 + std::min(l, 3)) * 3 + nbr) * 2) + par;
  }

  std::int32_t coef(const Band& band, std::uint32_t index, int c) const {
    return (*coefs_)[band.patch][c][index];
  }

  /// Tests node (l, x, y) of `band` at plain plane p (known significant when `inferred`); splits it if
  /// significant.
  template <bool kCheck>
  void process(Band& band, int l, int x, int y, int p, bool inferred) {
    const std::size_t idx = band.node(l, x, y);
    int bit = 1;
    if (!inferred) {
      if constexpr (!kDecode) bit = band.msb[idx] >= p;
      bit = sym<kCheck>(bit, node_ctx_[node_context(band, l, x, y)]);
      if (!bit) {
        band.lis_next.push_back(pack(l, x, y));
        return;
      }
      if constexpr (kDecode) {
        if (p > kMaxCoefficientPlane) throw Corrupt{};
      }
    }
    band.state[idx] |= kSig;
    if (l == 0) {
      new_sample<kCheck>(band, x, y, p);
      return;
    }
    // Children at level l − 1; the last active one is significant for sure when no sibling was.
    const int cl = l - 1;
    int children[4][2];
    int count = 0;
    for (int cy = 2 * y; cy <= 2 * y + 1 && cy < band.lh[cl]; ++cy) {
      for (int cx = 2 * x; cx <= 2 * x + 1 && cx < band.lw[cl]; ++cx) {
        if (band.state[band.node(cl, cx, cy)] & kActive) {
          children[count][0] = cx;
          children[count][1] = cy;
          ++count;
        }
      }
    }
    bool any = false;
    for (int i = 0; i < count; ++i) {
      const int cx = children[i][0], cy = children[i][1];
      const bool infer = (i == count - 1) && !any;
      process<kCheck>(band, cl, cx, cy, p, infer);
      any = any || (band.state[band.node(cl, cx, cy)] & kSig);
    }
  }

  template <bool kCheck>
  void new_sample(Band& band, int x, int y, int p) {
    const std::uint32_t index = band.grid_index(x, y, size_);
    band.lsp.push_back(Sample{index, {0, 0, 0}, {0, 0, 0}, 0});
    const std::size_t at = band.lsp.size() - 1;  // band.lsp is not resized below: a reference is safe
    Sample& s = band.lsp[at];
    bool any = false;
    for (int c = 0; c < 3; ++c) {
      int bit = 1, negative = 0;
      if constexpr (!kDecode) {
        const std::int32_t v = coef(band, index, c);
        const std::uint32_t m = static_cast<std::uint32_t>(v < 0 ? -static_cast<std::int64_t>(v) : v);
        bit = (m >> p) & 1;
        negative = v < 0;
      }
      if (c < 2 || any) bit = sym<kCheck>(bit, chan_ctx_[(band.cls * 3 + c) * 2 + any]);
      if (bit) {
        negative = raw<kCheck>(negative);
        s.mag[c] = 1u << p;
        s.q[c] = static_cast<std::uint8_t>(p);
        s.flags |= static_cast<std::uint8_t>((1 << c) | (negative << (3 + c)));
        any = true;
      }
    }
  }

  template <bool kCheck>
  void refine(Band& band, int p) {
    if constexpr (kDecode && !kCheck) {
      refine_fast(band, p);
      return;
    }
    for (std::size_t n = 0; n < band.refine_count; ++n) {
      Sample& s = band.lsp[n];
      for (int c = 0; c < 3; ++c) {
        int bit = 0, negative = 0;
        if constexpr (!kDecode) {
          const std::int32_t v = coef(band, s.index, c);
          const std::uint32_t m = static_cast<std::uint32_t>(v < 0 ? -static_cast<std::int64_t>(v) : v);
          bit = (m >> p) & 1;
          negative = v < 0;
        }
        if (s.flags & (1 << c)) {
          // Only the first refinement bit (just the leading one known) is context coded; see the header.
          std::uint32_t known;
          if constexpr (kDecode) {
            known = s.mag[c] >> (p + 1);
          } else {
            const std::int32_t v = coef(band, s.index, c);
            known = static_cast<std::uint32_t>(v < 0 ? -static_cast<std::int64_t>(v) : v) >> (p + 1);
          }
          bit = known == 1 ? sym<kCheck>(bit, ref_ctx_[band.cls]) : raw<kCheck>(bit);
          if constexpr (kDecode) {
            s.mag[c] |= static_cast<std::uint32_t>(bit) << p;
            s.q[c] = static_cast<std::uint8_t>(p);
          }
        } else {
          bit = sym<kCheck>(bit, late_ctx_[band.cls * 3 + c]);
          if (bit) {
            negative = raw<kCheck>(negative);
            s.mag[c] = 1u << p;
            s.q[c] = static_cast<std::uint8_t>(p);
            s.flags |= static_cast<std::uint8_t>((1 << c) | (negative << (3 + c)));
          }
        }
      }
    }
  }

  /// The decoder's refinement pass over complete segments: the same decisions as refine(), with the range
  /// decoder's state in locals (stores through Sample would otherwise force it back to memory per symbol).
  void refine_fast(Band& band, int p) {
    ArithmeticDecoder d = dec_;
    Sample* lsp = band.lsp.data();
    const std::size_t count = band.refine_count;
    Context* ref = &ref_ctx_[band.cls];
    Context* late = &late_ctx_[band.cls * 3];
    for (std::size_t n = 0; n < count; ++n) {
      Sample& s = lsp[n];
      std::uint32_t flags = s.flags;
      for (int c = 0; c < 3; ++c) {
        if (flags & (1u << c)) {
          const std::uint32_t known = s.mag[c] >> (p + 1);
          const int bit = known == 1 ? d.decode(*ref) : d.decode_bypass();
          s.mag[c] |= static_cast<std::uint32_t>(bit) << p;
          s.q[c] = static_cast<std::uint8_t>(p);
        } else if (d.decode(late[c])) {
          const std::uint32_t negative = static_cast<std::uint32_t>(d.decode_bypass());
          s.mag[c] = 1u << p;
          s.q[c] = static_cast<std::uint8_t>(p);
          flags |= (1u << c) | (negative << (3 + c));
        }
      }
      s.flags = static_cast<std::uint8_t>(flags);
    }
    dec_ = d;
  }

  int size_;
  std::vector<Band>& bands_;  // all bands (parents are looked up here; they belong to the same patch)
  std::vector<Band*> mine_;   // the bands this coder codes, in coding order
  const std::vector<PatchCoefficients>* coefs_;
  ArithmeticEncoder* enc_ = nullptr;
  ArithmeticDecoder dec_{{}};
  Context node_ctx_[kNodeContexts];
  Context chan_ctx_[kClasses * 3 * 2];
  Context late_ctx_[kClasses * 3];
  Context ref_ctx_[kClasses];
};

/// The encoder's quadtree of highest set bits of band `b` (max over the three channels) from `cf`.
void compute_msb(Band& b, const PatchCoefficients& cf, int size) {
  b.msb.assign(b.state.size(), -1);
  for (int y = 0; y < b.h; ++y) {
    for (int x = 0; x < b.w; ++x) {
      if (!(b.state[b.node(0, x, y)] & kActive)) continue;
      const std::uint32_t index = b.grid_index(x, y, size);
      std::int64_t m = 0;
      for (int c = 0; c < 3; ++c)
        m = std::max<std::int64_t>(m, std::abs(static_cast<std::int64_t>(cf[c][index])));
      if (m >= (std::int64_t{1} << (kMaxCoefficientPlane + 1))) {
        throw std::invalid_argument("encode_bitplanes: coefficient magnitude " + std::to_string(m) +
                                    " too large");
      }
      b.msb[b.node(0, x, y)] = static_cast<std::int8_t>(std::bit_width(static_cast<std::uint64_t>(m)) - 1);
    }
  }
  for (int l = 1; l < b.levels; ++l) {
    for (int y = 0; y < b.lh[l - 1]; ++y) {
      for (int x = 0; x < b.lw[l - 1]; ++x) {
        auto& parent = b.msb[b.node(l, x >> 1, y >> 1)];
        parent = std::max(parent, b.msb[b.node(l - 1, x, y)]);
      }
    }
  }
}

/// The decoder's reconstruction of one coefficient known down to plain plane q (all bits ≥ q): zero when
/// insignificant, else the middle of the remaining interval (see the header).
inline std::int32_t known_value(std::int32_t v, int q) {
  if (q <= 0) return v;
  const std::int64_t m = std::abs(static_cast<std::int64_t>(v));
  if ((m >> q) == 0) return 0;
  const std::int64_t r = ((m >> q) << q) + (std::int64_t{1} << (q - 1));
  return static_cast<std::int32_t>(v < 0 ? -r : r);
}

/// What decode_bitplanes() outputs after every weighted plane above `plane`, computed by the encoder from the
/// exact coefficients.
std::vector<PatchCoefficients> encoder_view(const std::vector<Band>& bands,
                                            const std::vector<PatchCoefficients>& cf, int plane, int size) {
  const std::size_t samples = static_cast<std::size_t>(size) * size;
  std::vector<PatchCoefficients> view(cf.size());
  for (auto& pc : view) {
    for (auto& ch : pc) ch.assign(samples, 0);
  }
  for (const Band& b : bands) {
    if (b.start >= 0 && b.start <= plane) continue;  // no plane of it coded yet
    const int q = plane + 1 - b.offset;
    for (int y = 0; y < b.h; ++y) {
      for (int x = 0; x < b.w; ++x) {
        if (!(b.state[b.node(0, x, y)] & kActive)) continue;
        const std::uint32_t index = b.grid_index(x, y, size);
        for (int c = 0; c < 3; ++c) view[b.patch][c][index] = known_value(cf[b.patch][c][index], q);
      }
    }
  }
  return view;
}

/// The decoder's reconstruction of the significant samples of `band` into `patch` (zero-filled before).
void reconstruct_band(const Band& band, PatchCoefficients& patch) {
  for (const Sample& sm : band.lsp) {
    for (int ch = 0; ch < 3; ++ch) {
      if (!(sm.flags & (1 << ch))) continue;
      // The middle of the interval [mag, mag + 2^q) (see the header).
      const std::int64_t v =
          static_cast<std::int64_t>(sm.mag[ch]) + (sm.q[ch] > 0 ? (std::int64_t{1} << (sm.q[ch] - 1)) : 0);
      patch[ch][sm.index] = static_cast<std::int32_t>((sm.flags >> (3 + ch)) & 1 ? -v : v);
    }
  }
}

/// The distinct start planes of deferred steps that are ≤ top, most significant first.
std::vector<int> hook_planes(const BitplaneLayout& layout, int top) {
  std::vector<int> planes;
  for (int k = 1; k <= layout.steps; ++k) {
    const int v = layout.start_plane[static_cast<std::size_t>(k)];
    if (v >= 0 && v <= top && std::find(planes.begin(), planes.end(), v) == planes.end()) planes.push_back(v);
  }
  std::sort(planes.begin(), planes.end(), std::greater<int>());
  return planes;
}

}  // namespace

int band_offset(const BitplaneLayout& layout, int k, int orient) {
  const int w = layout.orientation_weights ? 1 : 0;
  if (orient == 0) return layout.steps + w;
  return k - 1 + (orient != 3 ? w : 0);
}

BitplaneEncoding encode_bitplanes(const BitplaneLayout& layout,
                                  const std::vector<PatchCoefficients>& coefficients,
                                  const std::vector<std::vector<std::uint8_t>>& coded,
                                  std::size_t joint_bytes, const EncodeHook& before_plane) {
  if (!layout_ok(layout)) throw std::invalid_argument("encode_bitplanes: layout out of range");
  const std::size_t size = (std::size_t{1} << layout.level) + 1, samples = size * size;
  if (coefficients.size() != static_cast<std::size_t>(layout.num_patches) ||
      coded.size() != static_cast<std::size_t>(layout.num_patches)) {
    throw std::invalid_argument("encode_bitplanes: " + std::to_string(coefficients.size()) + " patches / " +
                                std::to_string(coded.size()) + " masks for " +
                                std::to_string(layout.num_patches) + " patches");
  }
  for (std::size_t p = 0; p < coefficients.size(); ++p) {
    if (coded[p].size() != samples) throw std::invalid_argument("encode_bitplanes: mask size");
    for (const auto& ch : coefficients[p]) {
      if (ch.size() != samples) throw std::invalid_argument("encode_bitplanes: coefficient grid size");
    }
  }
  std::vector<Band> bands = make_bands(layout, coded);
  // The coder's own copy: the hook may change the coefficients of the bands that start at its plane.
  std::vector<PatchCoefficients> coefs = coefficients;
  int top = 0;
  for (auto& b : bands) {
    compute_msb(b, coefs[b.patch], static_cast<int>(size));
    top = std::max(top, b.start >= 0 ? b.start : b.msb[b.node(b.levels - 1, 0, 0)] + b.offset);
  }
  const std::vector<int> hooks = hook_planes(layout, top);
  // Before coding `plane`: the hook for the bands that start there, and their new magnitudes.
  const auto run_hook = [&](int plane) {
    if (std::find(hooks.begin(), hooks.end(), plane) == hooks.end()) return;
    if (before_plane) {
      std::vector<PatchCoefficients> view = encoder_view(bands, coefs, plane, static_cast<int>(size));
      before_plane(plane, view, coefs);
    }
    for (auto& b : bands) {
      if (b.start != plane) continue;
      compute_msb(b, coefs[b.patch], static_cast<int>(size));
      const int msb = b.msb[b.node(b.levels - 1, 0, 0)];
      if (msb >= 0 && msb + b.offset > plane)
        throw std::logic_error("encode_bitplanes: a deferred band exceeds its start plane");
    }
  };
  BitplaneEncoding result;
  result.top_bitplane = top;
  // Joint planes first (all of them in version 1), then one coder per patch from the joint contexts.
  PlaneCoder<false> joint(layout, bands, -1, &coefs);
  std::size_t joint_total = 0;
  int plane = top;
  const auto stay_joint = [&] {
    if (!layout.independent_patches) return true;
    return joint_bytes > 0 ? joint_total < joint_bytes : result.joint_segments < layout.joint_segments;
  };
  for (; plane >= 0 && stay_joint(); --plane) {
    run_hook(plane);
    ArithmeticEncoder enc;
    joint.set_encoder(&enc);
    joint.template code_plane<false>(plane);
    result.segments.push_back(enc.finish());
    joint_total += result.segments.back().size();
    if (layout.independent_patches) ++result.joint_segments;
  }
  if (plane < 0) return result;
  // A segment is the varint sizes of the P streams, then their bytes interleaved in proportion to their
  // sizes (see Interleaver).
  const int np = layout.num_patches;
  std::vector<PlaneCoder<false>> coders;
  coders.reserve(static_cast<std::size_t>(np));
  for (int p = 0; p < np; ++p) {
    coders.emplace_back(layout, bands, p, &coefs);
    coders.back().copy_contexts(joint);
  }
  for (; plane >= 0; --plane) {
    run_hook(plane);
    std::vector<std::vector<std::uint8_t>> streams;
    for (auto& coder : coders) {
      ArithmeticEncoder enc;
      coder.set_encoder(&enc);
      coder.template code_plane<false>(plane);
      streams.push_back(enc.finish());
    }
    std::vector<std::uint8_t> segment;
    std::vector<std::uint64_t> sizes;
    for (const auto& st : streams) {
      if (st.size() > kMaxStreamBytes)
        throw std::length_error("encode_bitplanes: a patch stream of one plane over 1 GiB");
      sizes.push_back(st.size());
      detail::put_varint(segment, st.size());
    }
    std::vector<std::size_t> taken(streams.size(), 0);
    Interleaver order(sizes);
    for (int p; (p = order.next()) >= 0;) {
      auto& t = taken[static_cast<std::size_t>(p)];
      segment.push_back(streams[static_cast<std::size_t>(p)][t++]);
    }
    result.segments.push_back(std::move(segment));
  }
  return result;
}

namespace {

/// What one coder decodes of one plane: its stream's bytes, and whether they are the whole stream.
struct StreamPart {
  std::span<const std::uint8_t> bytes;
  bool complete = false;
  bool present = false;  ///< false: nothing of this plane arrived for this coder
};

struct CoderOutcome {
  std::size_t planes_complete = 0;
  bool partial = false;
  bool corrupt = false;
  std::exception_ptr error;  ///< anything else (allocation failure): rethrown by the caller's thread
};

/// Decodes the planes of one coder; parts[i] is its stream of plane `first` + i (planes after the first
/// absent or incomplete one are not decoded).
void decode_planes(PlaneCoder<true>& coder, int top_bitplane, std::size_t first,
                   const std::vector<StreamPart>& parts, CoderOutcome& outcome) {
  try {
    for (std::size_t t = 0; t < parts.size(); ++t) {
      const StreamPart& part = parts[t];
      if (!part.present) break;
      const int b = top_bitplane - static_cast<int>(first + t);
      coder.set_decoder(part.bytes);
      if (part.complete) {
        coder.code_plane<false>(b);
        ++outcome.planes_complete;
      } else {
        outcome.partial = true;
        try {
          coder.code_plane<true>(b);
        } catch (const Stop&) {
        }
        break;
      }
    }
  } catch (const Corrupt&) {
    outcome.corrupt = true;
  } catch (...) {
    outcome.error = std::current_exception();
  }
}

/// Splits a segment (or a byte prefix of one, `complete` = false) into its per-patch streams, copied into
/// `buffers`. Returns false when the sizes do not add up to a complete segment's bytes, when a prefix holds
/// more bytes than they announce, or when a varint is malformed.
bool split_segment(std::span<const std::uint8_t> seg, bool complete, int np,
                   std::vector<std::vector<std::uint8_t>>& buffers, std::vector<StreamPart>& parts) {
  parts.assign(static_cast<std::size_t>(np), StreamPart{});
  buffers.resize(static_cast<std::size_t>(np));
  std::size_t pos = 0;
  std::vector<std::uint64_t> sizes;
  std::uint64_t total = 0;
  for (int p = 0; p < np; ++p) {
    std::uint64_t v = 0;
    const detail::VarintRead read = detail::read_varint(seg, pos, v, 5, false);
    if (read == detail::VarintRead::kTruncated) return !complete;  // a prefix ending inside the sizes: nothing arrived
    if (read != detail::VarintRead::kOk) return false;
    if (v > kMaxStreamBytes) return false;
    sizes.push_back(v);
    total += v;
  }
  const std::uint64_t arrived = seg.size() - pos;
  if (complete ? arrived != total : arrived > total) return false;
  for (int p = 0; p < np; ++p) {
    buffers[static_cast<std::size_t>(p)].clear();
    buffers[static_cast<std::size_t>(p)].reserve(
        static_cast<std::size_t>(sizes[static_cast<std::size_t>(p)]));
  }
  if (np == 2) {
    // The same merge as Interleaver, incrementally: d = (2·a + 1)·s1 − (2·b + 1)·s0 after a bytes of
    // stream 0 and b of stream 1; stream 0 is next while d ≤ 0 (ties to the lower index) or stream 1 is
    // exhausted.
    const std::uint64_t s0 = sizes[0], s1 = sizes[1];
    auto& out0 = buffers[0];
    auto& out1 = buffers[1];
    out0.resize(static_cast<std::size_t>(s0));
    out1.resize(static_cast<std::size_t>(s1));
    std::size_t a = 0, b = 0;
    std::int64_t d = static_cast<std::int64_t>(s1) - static_cast<std::int64_t>(s0);
    const std::uint8_t* in = seg.data() + pos;
    for (std::uint64_t j = 0; j < arrived; ++j) {
      if (a < s0 && (d <= 0 || b >= s1)) {
        out0[a++] = in[j];
        d += 2 * static_cast<std::int64_t>(s1);
      } else {
        out1[b++] = in[j];
        d -= 2 * static_cast<std::int64_t>(s0);
      }
    }
    out0.resize(a);
    out1.resize(b);
  } else {
    Interleaver order(sizes);
    for (std::uint64_t j = 0; j < arrived; ++j) {
      buffers[static_cast<std::size_t>(order.next())].push_back(seg[pos++]);
    }
  }
  for (int p = 0; p < np; ++p) {
    const auto& buf = buffers[static_cast<std::size_t>(p)];
    const bool whole = buf.size() == sizes[static_cast<std::size_t>(p)];
    parts[static_cast<std::size_t>(p)] = {std::span<const std::uint8_t>(buf), whole, whole || !buf.empty()};
  }
  return true;
}

}  // namespace

Status decode_bitplanes(const BitplaneLayout& layout, int top_bitplane,
                        const std::vector<std::vector<std::uint8_t>>& coded,
                        std::span<const std::span<const std::uint8_t>> segments,
                        std::span<const std::uint8_t> partial_tail, std::vector<PatchCoefficients>& out,
                        BitplaneDecodeResult& result, int max_threads, const DecodeHook& before_plane) {
  result = {};
  if (!layout_ok(layout) || coded.size() != static_cast<std::size_t>(layout.num_patches) ||
      top_bitplane < 0 || top_bitplane > 64) {
    return Status::kInvalidArgument;
  }
  const std::size_t size = (std::size_t{1} << layout.level) + 1, samples = size * size;
  for (const auto& m : coded) {
    if (m.size() != samples) return Status::kInvalidArgument;
  }
  out.assign(static_cast<std::size_t>(layout.num_patches), PatchCoefficients{});
  const std::size_t planes = static_cast<std::size_t>(top_bitplane) + 1;
  Status status = Status::kOk;
  if (segments.size() > planes || (segments.size() == planes && !partial_tail.empty())) {
    status = Status::kCorrupt;  // decode what fits, then report
  }
  // Planes [0, joint) are one joint stream; planes [joint, arrived) one stream per patch.
  const int np = layout.num_patches;
  const std::size_t arrived =
      std::min(segments.size(), planes) + (segments.size() < planes && !partial_tail.empty());
  const std::size_t joint = layout.independent_patches
                                ? std::min(arrived, static_cast<std::size_t>(layout.joint_segments))
                                : arrived;
  const auto segment = [&](std::size_t t) { return t < segments.size() ? segments[t] : partial_tail; };
  std::vector<StreamPart> joint_parts(joint);
  for (std::size_t t = 0; t < joint; ++t) joint_parts[t] = {segment(t), t < segments.size(), true};
  std::vector<std::vector<StreamPart>> parts(static_cast<std::size_t>(np));
  std::vector<std::vector<std::vector<std::uint8_t>>> buffers(arrived - joint);  // [plane − joint][patch]
  std::vector<StreamPart> split;
  for (std::size_t t = joint; t < arrived; ++t) {
    if (!split_segment(segment(t), t < segments.size(), np, buffers[t - joint], split)) {
      status = Status::kCorrupt;  // sizes that do not fit: decode the planes before this one
      break;
    }
    for (int p = 0; p < np; ++p)
      parts[static_cast<std::size_t>(p)].push_back(split[static_cast<std::size_t>(p)]);
  }

  std::vector<Band> bands = make_bands(layout, coded, -1, max_threads);
  // Hooks of deferred steps: before segment top − plane. The segments are decoded in ranges between hooks
  // (and the fork to per-patch coders); a hook runs only when every plane above it was decoded completely.
  const std::vector<int> hooks = hook_planes(layout, top_bitplane);
  // Segments that can be decoded: the joint ones and the per-patch ones before a segment that did not split.
  const std::size_t decodable = joint + parts[0].size();
  std::vector<std::size_t> cuts = {0, joint, decodable};
  for (int h : hooks) cuts.push_back(static_cast<std::size_t>(top_bitplane - h));
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  const auto view = [&] {
    std::vector<PatchCoefficients> v(static_cast<std::size_t>(np));
    parallel_for(np, max_threads, [&](int c) {
      auto& patch = v[static_cast<std::size_t>(c)];
      for (auto& ch : patch) ch.assign(samples, 0);
      for (const auto& band : bands) {
        if (band.patch == c) reconstruct_band(band, patch);
      }
    });
    return v;
  };
  CoderOutcome joint_outcome;
  PlaneCoder<true> joint_coder(layout, bands, -1, nullptr);
  std::vector<CoderOutcome> outcomes(static_cast<std::size_t>(np));
  std::vector<PlaneCoder<true>> coders;  // per patch, made at the fork
  bool fork = false;
  for (std::size_t r = 0; r + 1 < cuts.size(); ++r) {
    const std::size_t a = cuts[r], b = cuts[r + 1];
    if (a >= decodable) break;
    for (int h : hooks) {
      if (static_cast<std::size_t>(top_bitplane - h) == a && before_plane) {
        std::vector<PatchCoefficients> v = view();
        before_plane(h, v);
      }
    }
    if (a < joint) {
      std::vector<StreamPart> slice(joint_parts.begin() + static_cast<std::ptrdiff_t>(a),
                                    joint_parts.begin() + static_cast<std::ptrdiff_t>(b));
      decode_planes(joint_coder, top_bitplane, a, slice, joint_outcome);
      if (joint_outcome.error) std::rethrow_exception(joint_outcome.error);
      if (joint_outcome.corrupt) status = Status::kCorrupt;
      result.partial = joint_outcome.partial;
      result.segments_complete = joint_outcome.planes_complete;
      if (joint_outcome.planes_complete != b || joint_outcome.corrupt) break;
      continue;
    }
    // The per-patch planes follow only a complete, clean joint part.
    if (!fork) {
      fork = true;
      coders.reserve(static_cast<std::size_t>(np));
      for (int c = 0; c < np; ++c) {
        coders.emplace_back(layout, bands, c, nullptr);
        coders.back().copy_contexts(joint_coder);
      }
    }
    parallel_for(np, max_threads, [&](int c) {
      CoderOutcome& outcome = outcomes[static_cast<std::size_t>(c)];
      try {
        const auto& mine = parts[static_cast<std::size_t>(c)];
        std::vector<StreamPart> slice(mine.begin() + static_cast<std::ptrdiff_t>(a - joint),
                                      mine.begin() + static_cast<std::ptrdiff_t>(b - joint));
        decode_planes(coders[static_cast<std::size_t>(c)], top_bitplane, a, slice, outcome);
      } catch (...) {
        outcome.error = std::current_exception();  // rethrown below, on the caller's thread
      }
    });
    std::size_t complete = planes;
    bool stop = false;
    for (const CoderOutcome& o : outcomes) {
      if (o.error) std::rethrow_exception(o.error);
      if (o.corrupt) status = Status::kCorrupt, stop = true;
      complete = std::min(complete, o.planes_complete);
      result.partial = result.partial || o.partial;
    }
    result.segments_complete = joint + complete;
    if (stop || joint + complete != b) break;
  }
  // The reconstruction of every patch, in parallel.
  parallel_for(np, max_threads, [&](int c) {
    auto& patch = out[static_cast<std::size_t>(c)];
    for (auto& ch : patch) ch.assign(samples, 0);
    for (const auto& band : bands) {
      if (band.patch == c) reconstruct_band(band, patch);
    }
  });
  return status;
}

}  // namespace geomip::codec
