#include "codec/bitplane_coder.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>

#include "codec/arithmetic_coder.h"
#include "codec/byte_io.h"
#include "codec/parallel.h"

namespace geomip::codec {
namespace {

constexpr std::uint8_t kSig = 1;     // node state: known significant
constexpr std::uint8_t kActive = 2;  // node state: covers at least one coded sample
// Decoder: bits 2–4 of a node's state count its significant neighbours at its level (left, right, up,
// down), kept by mark_significant(); the encoder's nodes leave them 0 (it counts in node_context()).
constexpr int kNbrShift = 2;
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
  std::vector<std::uint8_t> kids;  // per node of level ≥ 1: bit q set when child q (2x + (q & 1), 2y + (q >> 1)) is active
  std::vector<std::int8_t> msb;  // encoder: highest set bit of the node's max magnitude, −1 if zero
  int parent = -1;
  std::vector<std::uint32_t> lis, lis_next;
  std::vector<Sample> lsp;
  std::size_t refine_count = 0;

  std::size_t node(int l, int x, int y) const { return lbase[l] + static_cast<std::size_t>(y) * lw[l] + x; }
  /// Decoder: sets kSig at node (l, x, y) (not significant before) and counts it at its neighbours.
  void mark_significant(int l, int x, int y) {
    mark_significant_at(state.data() + node(l, x, y), x, y, lw[l], lh[l]);
  }
  /// The same for the node at `at`, (x, y) of a w × h level.
  static void mark_significant_at(std::uint8_t* at, int x, int y, int w, int h) {
    *at |= kSig;
    constexpr std::uint8_t one = 1u << kNbrShift;
    if (x > 0) at[-1] = static_cast<std::uint8_t>(at[-1] + one);
    if (x + 1 < w) at[1] = static_cast<std::uint8_t>(at[1] + one);
    if (y > 0) *(at - w) = static_cast<std::uint8_t>(*(at - w) + one);
    if (y + 1 < h) at[w] = static_cast<std::uint8_t>(at[w] + one);
  }
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
  explicit Interleaver(std::span<const std::uint64_t> sizes)
      : sizes_(sizes.begin(), sizes.end()), taken_(sizes.size(), 0) {}
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
  std::vector<std::uint64_t> sizes_;
  std::vector<std::uint64_t> taken_;
};

struct Corrupt {};  // bytes that no encoder writes

bool layout_ok(const BitplaneLayout& layout) {
  for (int v : layout.start_plane) {
    if (v < -1 || v > 64) return false;
  }
  return layout.level >= 0 && layout.level <= 12 && layout.steps >= 0 && layout.steps <= layout.level &&
         layout.num_patches >= 1 && layout.joint_segments >= 0 && layout.bottom_bitplane >= 0 &&
         layout.bottom_bitplane <= 64;
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
      const std::uint8_t* const row = mask.data() + b.grid_index(0, y, size);
      std::uint8_t* const out = b.state.data() + b.node(0, 0, y);
      for (int x = 0; x < b.w; ++x) out[x] = row[static_cast<std::size_t>(b.dx) * x] ? kActive : 0;
    }
    b.kids.assign(total, 0);
    for (int l = 1; l < b.levels; ++l) {
      for (int y = 0; y < b.lh[l - 1]; ++y) {
        const std::uint8_t* const child = b.state.data() + b.node(l - 1, 0, y);
        std::uint8_t* const parent = b.state.data() + b.node(l, 0, y >> 1);
        std::uint8_t* const kids = b.kids.data() + b.node(l, 0, y >> 1);
        for (int x = 0; x < b.lw[l - 1]; ++x) {
          // child & kActive is 0 or 2: shifted to bit (x & 1) + 2·(y & 1) of its parent's kids.
          parent[x >> 1] |= child[x];
          kids[x >> 1] |= static_cast<std::uint8_t>((child[x] & kActive) << ((x & 1) + 2 * (y & 1)) >> 1);
        }
      }
    }
    // The significant list holds distinct samples: room for all of them up front, so the sorting passes never
    // grow (copy) it (about as much memory as its growth by doubling would take at the end; where the
    // allocator maps fresh pages, those never written are never touched).
    b.lsp.reserve(static_cast<std::size_t>(b.w) * static_cast<std::size_t>(b.h));
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

  /// Encoder: one weighted bit-plane, sorting pass over every band, then refinement pass over every band.
  /// (The decoder walks the same decisions in resume().)
  void code_plane(int b) {
    static_assert(!kDecode, "the decoder uses start_plane() and resume()");
    for (Band* band : mine_) band->refine_count = band->lsp.size();
    for (Band* bp : mine_) {
      Band& band = *bp;
      const int p = b - band.offset;
      if (p < 0 || band.lis.empty() || (band.start >= 0 && b > band.start)) continue;
      band.lis_next.clear();
      // lis is swapped only after the loop; process() appends to lis_next only.
      for (std::size_t n = 0; n < band.lis.size(); ++n) {
        const std::uint32_t packed = band.lis[n];
        process(band, static_cast<int>(packed >> 28), static_cast<int>((packed >> 14) & 0x3FFF),
                static_cast<int>(packed & 0x3FFF), p, false);
      }
      std::swap(band.lis, band.lis_next);
    }
    for (Band* bp : mine_) {
      const int p = b - bp->offset;
      if (p < 0) continue;
      refine(*bp, p);
    }
  }

 private:
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

  std::uint32_t magnitude(const Band& band, std::uint32_t index, int c) const {
    const std::int32_t v = (*coefs_)[band.patch][c][index];
    return static_cast<std::uint32_t>(v < 0 ? -static_cast<std::int64_t>(v) : v);
  }

  /// Encoder: tests node (l, x, y) of `band` at plain plane p (known significant when `inferred`); splits it
  /// if significant.
  void process(Band& band, int l, int x, int y, int p, bool inferred) {
    const std::size_t idx = band.node(l, x, y);
    if (!inferred) {
      const int bit = band.msb[idx] >= p;
      enc_->encode(bit, node_ctx_[node_context(band, l, x, y)]);
      if (!bit) {
        band.lis_next.push_back(pack(l, x, y));
        return;
      }
    }
    band.state[idx] |= kSig;
    if (l == 0) {
      new_sample(band, x, y, p);
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
      process(band, cl, cx, cy, p, infer);
      any = any || (band.state[band.node(cl, cx, cy)] & kSig);
    }
  }

  void new_sample(Band& band, int x, int y, int p) {
    const std::uint32_t index = band.grid_index(x, y, size_);
    band.lsp.push_back(Sample{index, {0, 0, 0}, {0, 0, 0}, 0});
    bool any = false;
    for (int c = 0; c < 3; ++c) {
      const int bit = (magnitude(band, index, c) >> p) & 1;
      if (c < 2 || any) enc_->encode(bit, chan_ctx_[(band.cls * 3 + c) * 2 + any]);
      if (bit) {
        enc_->encode_bypass((*coefs_)[band.patch][c][index] < 0);
        band.lsp.back().flags |= static_cast<std::uint8_t>(1 << c);
        any = true;
      }
    }
  }

  void refine(Band& band, int p) {
    for (std::size_t n = 0; n < band.refine_count; ++n) {
      Sample& s = band.lsp[n];
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t m = magnitude(band, s.index, c);
        const int bit = (m >> p) & 1;
        if (s.flags & (1 << c)) {
          // Only the first refinement bit (just the leading one known) is context coded; see the header.
          if ((m >> (p + 1)) == 1) {
            enc_->encode(bit, ref_ctx_[band.cls]);
          } else {
            enc_->encode_bypass(bit);
          }
        } else {
          enc_->encode(bit, late_ctx_[band.cls * 3 + c]);
          if (bit) {
            enc_->encode_bypass((*coefs_)[band.patch][c][s.index] < 0);
            s.flags |= static_cast<std::uint8_t>(1 << c);
          }
        }
      }
    }
  }

  /// The decoder's refinement pass over complete segments: the same decisions as refine(), with the range
  /// decoder's state in locals (stores through Sample would otherwise force it back to memory per symbol).
  /// Starts at sample `first`.
  void refine_fast(Band& band, int p, std::size_t first = 0) {
    ArithmeticDecoder d = dec_;
    Sample* lsp = band.lsp.data();
    const std::size_t count = band.refine_count;
    Context* ref = &ref_ctx_[band.cls];
    Context* late = &late_ctx_[band.cls * 3];
    for (std::size_t n = first; n < count; ++n) {
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

  // ---- the decoder's resumable traversal (incremental decoding) ----
  //
  // The same decisions as code_plane(), process(), new_sample() and refine(), in the same order, but as a
  // loop over an explicit cursor instead of a recursion: when the bytes of a partial stream run out, the
  // decoder stops before the symbol that needs them and keeps its place (the cursor), and resume() goes on
  // from there once extend() gave it more bytes. So every byte is decoded once however the stream arrives.
 public:
  /// Byte position of the range decoder in the current plane's stream.
  std::size_t position() const { return dec_.position(); }
  /// Starts plane `b` (the next resume() decodes it from its beginning).
  void start_plane(int b) {
    cur_ = Cursor{};
    cur_.plane = b;
  }
  /// Gives the decoder a longer prefix of the current plane's stream (the same bytes first).
  void extend(std::span<const std::uint8_t> bytes) { dec_.extend(bytes); }
  /// Decodes on in the current plane. kCheck: the stream may be a byte prefix; stop before the first symbol
  /// that needs a byte past it. Returns true when the plane is finished. Throws Corrupt.
  template <bool kCheck>
  bool resume() {
    Cursor& k = cur_;
    if (k.pass == 0) {
      for (Band* band : mine_) band->refine_count = band->lsp.size();
      k.pass = 1;
    }
    if (k.pass == 1) {
      if (!sort_pass<kCheck>()) return false;
      k.pass = 2, k.band = 0, k.n = 0, k.c = 0, k.sub = 0;
    }
    if (k.pass == 2) {
      if (!refine_pass<kCheck>()) return false;
      k.pass = 3;
    }
    return true;
  }
  /// The plane being decoded is finished (or none was started).
  bool plane_done() const { return cur_.pass == 3 || cur_.plane < 0; }

 private:
  enum : std::uint8_t { kBandStart, kLisEntry, kTest, kChannel, kSign, kNext };
  struct Frame {
    std::uint16_t x, y;
    std::uint8_t l;
    std::int8_t last;        // quadrant of the child processed last (−1: none yet)
    std::uint8_t remaining;  // active children not yet processed
    bool any;                // a processed child was significant
  };
  struct Cursor {
    int plane = -1;
    int pass = 0;  // 0 not started, 1 sorting, 2 refinement, 3 done
    std::size_t band = 0, n = 0;
    std::uint8_t pc = kBandStart;
    int depth = 0;
    Frame stack[kMaxQuadLevels];
    int l = 0, x = 0, y = 0;
    bool inferred = false, any = false;
    int c = 0, sub = 0;
  };

  template <bool kCheck>
  bool sort_pass() {
    Cursor& k = cur_;
    ArithmeticDecoder d = dec_;
    const int b = k.plane;
    for (; k.band < mine_.size(); ++k.band, k.pc = kBandStart) {
      Band& band = *mine_[k.band];
      const int p = b - band.offset;
      if (k.pc == kBandStart) {
        if (p < 0 || band.lis.empty() || (band.start >= 0 && b > band.start)) continue;
        if (!kCheck) {  // a whole band with the stream complete: the fast loop takes it
          dec_ = d;
          sort_fast(band, p);
          d = dec_;
          continue;
        }
        band.lis_next.clear();
        k.n = 0;
        k.pc = kLisEntry;
      }
      for (bool band_done = false; !band_done;) {
        switch (k.pc) {
          case kLisEntry: {
            if (k.n == band.lis.size()) {
              band_done = true;
              break;
            }
            const std::uint32_t packed = band.lis[k.n];
            k.l = static_cast<int>(packed >> 28);
            k.x = static_cast<int>((packed >> 14) & 0x3FFF);
            k.y = static_cast<int>(packed & 0x3FFF);
            k.inferred = false;
            k.depth = 0;
            k.pc = kTest;
            break;
          }
          case kTest: {
            if (!k.inferred) {
              if (kCheck && d.exhausted()) {
                dec_ = d;
                return false;
              }
              if (!d.decode(node_ctx_[node_context(band, k.l, k.x, k.y)])) {
                band.lis_next.push_back(pack(k.l, k.x, k.y));
                k.pc = kNext;
                break;
              }
              if (p > kMaxCoefficientPlane) throw Corrupt{};
            }
            band.mark_significant(k.l, k.x, k.y);
            if (k.l == 0) {
              band.lsp.push_back(Sample{band.grid_index(k.x, k.y, size_), {0, 0, 0}, {0, 0, 0}, 0});
              k.c = 0;
              k.any = false;
              k.pc = kChannel;
              break;
            }
            Frame& f = k.stack[k.depth++];
            f.x = static_cast<std::uint16_t>(k.x);
            f.y = static_cast<std::uint16_t>(k.y);
            f.l = static_cast<std::uint8_t>(k.l);
            f.last = -1;
            f.any = false;
            f.remaining = 0;
            const int cl = k.l - 1;
            for (int q = 0; q < 4; ++q) {
              const int cx = 2 * k.x + (q & 1), cy = 2 * k.y + (q >> 1);
              if (cx < band.lw[cl] && cy < band.lh[cl] && (band.state[band.node(cl, cx, cy)] & kActive))
                ++f.remaining;
            }
            k.pc = kNext;
            break;
          }
          case kChannel: {
            if (k.c == 3) {
              k.pc = kNext;
              break;
            }
            int bit = 1;
            if (k.c < 2 || k.any) {
              if (kCheck && d.exhausted()) {
                dec_ = d;
                return false;
              }
              bit = d.decode(chan_ctx_[(band.cls * 3 + k.c) * 2 + k.any]);
            }
            if (bit) {
              k.pc = kSign;
            } else {
              ++k.c;
            }
            break;
          }
          case kSign: {
            if (kCheck && d.exhausted()) {
              dec_ = d;
              return false;
            }
            const int negative = d.decode_bypass();
            Sample& sm = band.lsp.back();
            sm.mag[k.c] = 1u << p;
            sm.q[k.c] = static_cast<std::uint8_t>(p);
            sm.flags |= static_cast<std::uint8_t>((1 << k.c) | (negative << (3 + k.c)));
            k.any = true;
            ++k.c;
            k.pc = kChannel;
            break;
          }
          default: {  // kNext: the node or sample in hand is finished; go to the next one
            if (k.depth == 0) {
              ++k.n;
              k.pc = kLisEntry;
              break;
            }
            Frame& f = k.stack[k.depth - 1];
            const int cl = f.l - 1;
            if (f.last >= 0) {
              const int lx = 2 * f.x + (f.last & 1), ly = 2 * f.y + (f.last >> 1);
              f.any = f.any || (band.state[band.node(cl, lx, ly)] & kSig);
            }
            if (f.remaining == 0) {
              --k.depth;
              break;
            }
            int q = f.last + 1;
            for (;; ++q) {
              const int cx = 2 * f.x + (q & 1), cy = 2 * f.y + (q >> 1);
              if (cx < band.lw[cl] && cy < band.lh[cl] && (band.state[band.node(cl, cx, cy)] & kActive))
                break;
            }
            f.last = static_cast<std::int8_t>(q);
            --f.remaining;
            k.l = cl;
            k.x = 2 * f.x + (q & 1);
            k.y = 2 * f.y + (q >> 1);
            k.inferred = f.remaining == 0 && !f.any;
            k.pc = kTest;
            break;
          }
        }
      }
      std::swap(band.lis, band.lis_next);
    }
    dec_ = d;
    return true;
  }

  /// The decoder's sorting pass over one whole band (stream complete): the same decisions as the kTest /
  /// kChannel / kSign / kNext steps of sort_pass(), in the same order, with the traversal state and the range
  /// decoder in locals (byte stores into the quadtree state would otherwise force the cursor back to memory
  /// per symbol).
  void sort_fast(Band& band, int p) {
    ArithmeticDecoder d = dec_;
    band.lis_next.clear();
    std::uint8_t* const st = band.state.data();
    const std::uint32_t* const lis = band.lis.data();
    const std::size_t lis_size = band.lis.size();
    Context* const chan = &chan_ctx_[band.cls * 3 * 2];
    // The band's and its parent's quadtree shapes in locals, and node_context() over them.
    const int levels = band.levels;
    int lw[kMaxQuadLevels], lh[kMaxQuadLevels];
    std::size_t lbase[kMaxQuadLevels];
    for (int i = 0; i < levels; ++i) lw[i] = band.lw[i], lh[i] = band.lh[i], lbase[i] = band.lbase[i];
    // Per level nl of this band: the parent band's node covering (x, y) is (x, y) >> pshift[nl] at level
    // nl − 1 (level 0 for nl = 0), inside pw[nl] × ph[nl] (0 × 0 when the parent has no such level).
    const Band* const pb = band.parent >= 0 ? &bands_[static_cast<std::size_t>(band.parent)] : nullptr;
    const std::uint8_t* pbase[kMaxQuadLevels];
    int pw[kMaxQuadLevels], ph[kMaxQuadLevels], pshift[kMaxQuadLevels], lctx[kMaxQuadLevels];
    for (int i = 0; i < levels; ++i) {
      const int pl = i > 0 ? i - 1 : 0;
      const bool has = pb && pl < pb->levels;
      pbase[i] = has ? pb->state.data() + pb->lbase[pl] : nullptr;
      pw[i] = has ? pb->lw[pl] : 0;
      ph[i] = has ? pb->lh[pl] : 0;
      pshift[i] = i > 0 ? 0 : 1;
      lctx[i] = ((band.cls * 3 + band.kcls) * 4 + std::min(i, 3)) * 6;
    }
    const auto node = [&](int nl, int nx, int ny) {
      return lbase[nl] + static_cast<std::size_t>(ny) * static_cast<std::size_t>(lw[nl]) +
             static_cast<std::size_t>(nx);
    };
    // = node_context(band, nl, nx, ny) for the node at st[at]: its neighbour count is in its state byte.
    const auto context = [&](std::size_t at, int nl, int nx, int ny) {
      const int nbr = std::min(st[at] >> kNbrShift, 2);
      const int px = nx >> pshift[nl], py = ny >> pshift[nl];
      const int par = px < pw[nl] && py < ph[nl]
                          ? pbase[nl][static_cast<std::size_t>(py) * static_cast<std::size_t>(pw[nl]) +
                                      static_cast<std::size_t>(px)] &
                                kSig
                          : 0;
      return lctx[nl] + nbr * 2 + par;
    };
    const std::uint8_t* const kids = band.kids.data();
    // A split node: its active children not processed yet (bit q: child q), and whether one was significant.
    struct Split {
      std::uint16_t x, y;
      std::uint8_t l, left;
      bool any;
    };
    Split stack[kMaxQuadLevels];
    for (std::size_t n = 0; n < lis_size; ++n) {
      const std::uint32_t packed = lis[n];
      int l = static_cast<int>(packed >> 28), x = static_cast<int>((packed >> 14) & 0x3FFF),
          y = static_cast<int>(packed & 0x3FFF);
      bool inferred = false;
      int depth = 0;
      while (true) {
        // Test node (l, x, y); split it (or read its sample) when significant.
        const std::size_t at = node(l, x, y);
        if (!inferred && !d.decode(node_ctx_[context(at, l, x, y)])) {
          band.lis_next.push_back(pack(l, x, y));
        } else {
          if (!inferred && p > kMaxCoefficientPlane) throw Corrupt{};
          // Over the locals: through the band, each byte store would make the compiler reload its members.
          Band::mark_significant_at(st + at, x, y, lw[l], lh[l]);
          if (depth > 0) stack[depth - 1].any = true;  // (l, x, y) is a child of the innermost split node
          if (l == 0) {
            Sample sm{band.grid_index(x, y, size_), {0, 0, 0}, {0, 0, 0}, 0};
            bool any = false;
            for (int c = 0; c < 3; ++c) {
              if ((c < 2 || any) && !d.decode(chan[c * 2 + any])) continue;
              const int negative = d.decode_bypass();
              sm.mag[c] = 1u << p;
              sm.q[c] = static_cast<std::uint8_t>(p);
              sm.flags = static_cast<std::uint8_t>(sm.flags | (1 << c) | (negative << (3 + c)));
              any = true;
            }
            band.lsp.push_back(sm);
          } else {
            Split& f = stack[depth++];
            f.x = static_cast<std::uint16_t>(x);
            f.y = static_cast<std::uint16_t>(y);
            f.l = static_cast<std::uint8_t>(l);
            f.left = kids[at];
            f.any = false;
          }
        }
        // The next node: the next active child of the innermost split node with children left.
        while (depth > 0 && stack[depth - 1].left == 0) --depth;
        if (depth == 0) break;
        Split& f = stack[depth - 1];
        const int q = std::countr_zero(static_cast<unsigned>(f.left));
        f.left = static_cast<std::uint8_t>(f.left & (f.left - 1));
        l = f.l - 1;
        x = 2 * f.x + (q & 1);
        y = 2 * f.y + (q >> 1);
        // The last active child is significant for sure when no sibling was.
        inferred = f.left == 0 && !f.any;
      }
    }
    std::swap(band.lis, band.lis_next);
    dec_ = d;
  }

  template <bool kCheck>
  bool refine_pass() {
    Cursor& k = cur_;
    const int b = k.plane;
    for (; k.band < mine_.size(); ++k.band, k.n = 0) {
      Band& band = *mine_[k.band];
      const int p = b - band.offset;
      if (p < 0) continue;
      ArithmeticDecoder d = dec_;
      Context* ref = &ref_ctx_[band.cls];
      Context* late = &late_ctx_[band.cls * 3];
      for (; k.n < band.refine_count; ++k.n, k.c = 0) {
        if (!kCheck && k.c == 0 && k.sub == 0) break;  // sample boundary: the fast loop takes over
        Sample& sm = band.lsp[k.n];
        for (; k.c < 3; ++k.c) {
          if (k.sub == 0) {
            if (kCheck && d.exhausted()) {
              dec_ = d;
              return false;
            }
            if (sm.flags & (1u << k.c)) {
              const std::uint32_t known = sm.mag[k.c] >> (p + 1);
              const int bit = known == 1 ? d.decode(*ref) : d.decode_bypass();
              sm.mag[k.c] |= static_cast<std::uint32_t>(bit) << p;
              sm.q[k.c] = static_cast<std::uint8_t>(p);
            } else if (d.decode(late[k.c])) {
              k.sub = 1;
            }
          }
          if (k.sub == 1) {
            if (kCheck && d.exhausted()) {
              dec_ = d;
              return false;
            }
            const std::uint32_t negative = static_cast<std::uint32_t>(d.decode_bypass());
            sm.mag[k.c] = 1u << p;
            sm.q[k.c] = static_cast<std::uint8_t>(p);
            sm.flags = static_cast<std::uint8_t>(sm.flags | (1u << k.c) | (negative << (3 + k.c)));
            k.sub = 0;
          }
        }
      }
      dec_ = d;
      if (!kCheck) refine_fast(band, p, k.n);
    }
    return true;
  }

  Cursor cur_;
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

/// The distinct start planes of deferred steps that are ≤ top and coded (≥ the bottom plane), most
/// significant first.
std::vector<int> hook_planes(const BitplaneLayout& layout, int top) {
  std::vector<int> planes;
  for (int k = 1; k <= layout.steps; ++k) {
    const int v = layout.start_plane[static_cast<std::size_t>(k)];
    if (v >= layout.bottom_bitplane && v <= top && std::find(planes.begin(), planes.end(), v) == planes.end())
      planes.push_back(v);
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
  const int bottom = layout.bottom_bitplane;
  top = std::max(top, bottom);  // at least one plane, even for a stream of zeros
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
  for (; plane >= bottom && stay_joint(); --plane) {
    run_hook(plane);
    ArithmeticEncoder enc;
    joint.set_encoder(&enc);
    joint.code_plane(plane);
    result.segments.push_back(enc.finish());
    joint_total += result.segments.back().size();
    if (layout.independent_patches) ++result.joint_segments;
  }
  if (plane < bottom) return result;
  // A segment is the varint sizes of the P streams, then their bytes interleaved in proportion to their
  // sizes (see Interleaver).
  const int np = layout.num_patches;
  std::vector<PlaneCoder<false>> coders;
  coders.reserve(static_cast<std::size_t>(np));
  for (int p = 0; p < np; ++p) {
    coders.emplace_back(layout, bands, p, &coefs);
    coders.back().copy_contexts(joint);
  }
  for (; plane >= bottom; --plane) {
    run_hook(plane);
    std::vector<std::vector<std::uint8_t>> streams;
    for (auto& coder : coders) {
      ArithmeticEncoder enc;
      coder.set_encoder(&enc);
      coder.code_plane(plane);
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

/// Where one coder is: the plane in progress and what happened in the last update.
struct CoderRun {
  std::size_t next = 0;  ///< segment index of the plane in progress (or the next to start)
  bool started = false;  ///< plane `next` was started (the coder's cursor is inside it)
  std::size_t seen = 0;  ///< bytes of plane `next` given to the coder so far
  bool partial = false;  ///< the last update stopped inside a present, incomplete part
  bool corrupt = false;
  std::exception_ptr error;   ///< anything else (allocation failure): rethrown by the caller's thread
  std::uint64_t version = 0;  ///< grows whenever the coder may have decoded something
};

/// Decodes the planes of one coder from run.next on, while < end and bytes are there (part(t): its stream of
/// segment t), resuming inside a plane it stopped in before.
template <typename PartFn>
void advance(PlaneCoder<true>& coder, CoderRun& run, int top_bitplane, std::size_t end, const PartFn& part) {
  run.partial = false;
  try {
    while (run.next < end) {
      const StreamPart sp = part(run.next);
      if (!sp.present) break;
      if (!run.started) {
        coder.set_decoder(sp.bytes);
        coder.start_plane(top_bitplane - static_cast<int>(run.next));
        run.started = true;
        run.seen = sp.bytes.size();
        ++run.version;
      } else {
        coder.extend(sp.bytes);
        if (sp.bytes.size() != run.seen || sp.complete) ++run.version;
        run.seen = sp.bytes.size();
      }
      if (!sp.complete) {
        run.partial = true;
        coder.resume<true>();
        break;
      }
      coder.resume<false>();
      ++run.next;
      run.started = false;
    }
  } catch (const Corrupt&) {
    run.corrupt = true;
  } catch (...) {
    run.error = std::current_exception();
  }
}

/// The per-patch streams of one segment after the joint ones, taken apart as its bytes arrive: the varint
/// byte sizes of the P streams first, then every byte goes to the stream the interleave gives it (the same
/// merge as Interleaver).
class SegmentSplit {
 public:
  /// Takes apart the new bytes of `seg`, a longer prefix of the same segment than before (`complete`: the
  /// whole segment). Returns false when the sizes do not add up to a complete segment's bytes, when a prefix
  /// holds more bytes than they announce, or when a varint is malformed.
  bool feed(std::span<const std::uint8_t> seg, bool complete, int np) {
    if (sizes_.size() < static_cast<std::size_t>(np)) {
      std::size_t pos = 0;
      std::vector<std::uint64_t> sizes;
      for (int p = 0; p < np; ++p) {
        std::uint64_t v = 0;
        const detail::VarintRead read = detail::read_varint(seg, pos, v, 5, false);
        if (read == detail::VarintRead::kTruncated) return !complete;  // nothing of the streams arrived yet
        if (read != detail::VarintRead::kOk || v > kMaxStreamBytes) return false;
        sizes.push_back(v);
      }
      sizes_ = std::move(sizes);
      consumed_ = header_end_ = pos;
      streams_.assign(static_cast<std::size_t>(np), {});
      order_.emplace(sizes_);
      d_ = static_cast<std::int64_t>(np == 2 ? sizes_[1] : 0) - static_cast<std::int64_t>(sizes_[0]);
      for (std::uint64_t v : sizes_) total_ += v;
    }
    const std::uint64_t arrived = seg.size() - header_end_;
    if (complete ? arrived != total_ : arrived > total_) return false;
    const std::uint8_t* in = seg.data();
    if (np == 2) {
      // d = (2·a + 1)·s1 − (2·b + 1)·s0 after a bytes of stream 0 and b of stream 1; stream 0 is next while
      // d ≤ 0 (ties to the lower index) or stream 1 is exhausted.
      const std::uint64_t s0 = sizes_[0], s1 = sizes_[1];
      auto& out0 = streams_[0];
      auto& out1 = streams_[1];
      for (std::size_t j = consumed_; j < seg.size(); ++j) {
        if (out0.size() < s0 && (d_ <= 0 || out1.size() >= s1)) {
          out0.push_back(in[j]);
          d_ += 2 * static_cast<std::int64_t>(s1);
        } else {
          out1.push_back(in[j]);
          d_ -= 2 * static_cast<std::int64_t>(s0);
        }
      }
    } else {
      for (std::size_t j = consumed_; j < seg.size(); ++j) {
        streams_[static_cast<std::size_t>(order_->next())].push_back(in[j]);
      }
    }
    consumed_ = seg.size();
    return true;
  }
  bool has_sizes() const { return !sizes_.empty(); }
  /// Stream p so far.
  StreamPart part(int p) const {
    if (sizes_.empty()) return {};
    const auto& buf = streams_[static_cast<std::size_t>(p)];
    const bool whole = buf.size() == sizes_[static_cast<std::size_t>(p)];
    return {std::span<const std::uint8_t>(buf), whole, whole || !buf.empty()};
  }

 private:
  std::vector<std::uint64_t> sizes_;
  std::optional<Interleaver> order_;  // P > 2
  std::uint64_t total_ = 0;
  std::size_t header_end_ = 0, consumed_ = 0;
  std::int64_t d_ = 0;
  std::vector<std::vector<std::uint8_t>> streams_;
};

}  // namespace

struct BitplaneDecoder::State {
  BitplaneLayout layout;
  int top = 0;
  std::size_t planes = 0, joint_planes = 0;  // joint_planes: segments of the joint coder
  int max_threads = 0;
  DecodeHook before_plane;
  HookViewShift view_shift;
  std::vector<PatchCoefficients> hook_view;  // the hooks' reconstruction: one buffer for all of them
  std::vector<std::vector<std::uint8_t>> coded;
  std::vector<Band> bands;  // never resized after the coders point into it
  std::unique_ptr<PlaneCoder<true>> joint;
  CoderRun joint_run;
  std::vector<PlaneCoder<true>> coders;  // per patch, made at the fork
  std::vector<CoderRun> runs;
  std::vector<SegmentSplit> splits;  // [segment − joint_planes]
  std::vector<std::size_t> cuts;     // segment indices where a range ends: joint_planes, hooks, planes
  std::vector<int> hooks;
  std::size_t range_start = 0;  // the range in progress starts here (its hooks have run)
  bool hooks_run = false;       // the hooks at range_start ran
  bool corrupt = false;
  std::uint64_t hook_version = 0;
  BitplaneDecodeResult last;
};

BitplaneDecoder::BitplaneDecoder() = default;
BitplaneDecoder::~BitplaneDecoder() = default;
BitplaneDecoder::BitplaneDecoder(BitplaneDecoder&&) noexcept = default;
BitplaneDecoder& BitplaneDecoder::operator=(BitplaneDecoder&&) noexcept = default;

Status BitplaneDecoder::reset(const BitplaneLayout& layout, int top_bitplane,
                              std::vector<std::vector<std::uint8_t>> coded, int max_threads,
                              DecodeHook before_plane, HookViewShift view_shift) {
  s_.reset();
  if (!layout_ok(layout) || coded.size() != static_cast<std::size_t>(layout.num_patches) ||
      top_bitplane < layout.bottom_bitplane || top_bitplane > 64) {
    return Status::kInvalidArgument;
  }
  const std::size_t size = (std::size_t{1} << layout.level) + 1, samples = size * size;
  for (const auto& m : coded) {
    if (m.size() != samples) return Status::kInvalidArgument;
  }
  auto st = std::make_unique<State>();
  st->layout = layout;
  st->top = top_bitplane;
  st->planes = static_cast<std::size_t>(top_bitplane - layout.bottom_bitplane) + 1;
  st->joint_planes = layout.independent_patches
                         ? std::min(st->planes, static_cast<std::size_t>(layout.joint_segments))
                         : st->planes;
  st->max_threads = max_threads;
  st->before_plane = std::move(before_plane);
  st->view_shift = std::move(view_shift);
  st->coded = std::move(coded);
  st->bands = make_bands(layout, st->coded, -1, max_threads);
  st->joint = std::make_unique<PlaneCoder<true>>(layout, st->bands, -1, nullptr);
  st->hooks = hook_planes(layout, top_bitplane);
  st->cuts = {st->joint_planes, st->planes};
  for (int h : st->hooks) st->cuts.push_back(static_cast<std::size_t>(top_bitplane - h));
  std::sort(st->cuts.begin(), st->cuts.end());
  st->cuts.erase(std::unique(st->cuts.begin(), st->cuts.end()), st->cuts.end());
  st->runs.resize(static_cast<std::size_t>(layout.num_patches));
  s_ = std::move(st);
  return Status::kOk;
}

Status BitplaneDecoder::update(std::span<const std::span<const std::uint8_t>> segments,
                               std::span<const std::uint8_t> partial_tail, BitplaneDecodeResult& result) {
  result = {};
  if (!s_) return Status::kInvalidArgument;
  State& st = *s_;
  if (st.corrupt) {
    result = st.last;
    return Status::kCorrupt;
  }
  const int np = st.layout.num_patches;
  const std::size_t planes = st.planes;
  Status status = Status::kOk;
  if (segments.size() > planes || (segments.size() == planes && !partial_tail.empty())) {
    status = Status::kCorrupt;  // decode what fits, then report
  }
  const std::size_t arrived =
      std::min(segments.size(), planes) + (segments.size() < planes && !partial_tail.empty());
  const auto segment = [&](std::size_t t) { return t < segments.size() ? segments[t] : partial_tail; };

  // Per-patch segments: take apart what arrived (in order; a segment whose sizes do not fit ends the
  // decodable ones and the stream is corrupt).
  std::size_t decodable = std::min(arrived, st.joint_planes);
  if (arrived > st.joint_planes) {
    decodable = st.joint_planes;
    for (std::size_t t = st.joint_planes; t < arrived; ++t) {
      const std::size_t i = t - st.joint_planes;
      if (st.splits.size() <= i) st.splits.emplace_back();
      if (!st.splits[i].feed(segment(t), t < segments.size(), np)) {
        status = Status::kCorrupt;
        st.corrupt = true;  // later bytes cannot repair a segment whose sizes do not fit
        break;
      }
      decodable = t + 1;
    }
  }

  // Ranges between cuts (hooks, the fork); a range starts only when every plane before it was decoded
  // completely, and its hooks run first.
  for (;;) {
    const std::size_t a = st.range_start;
    const bool in_joint = a < st.joint_planes;
    const std::size_t limit = in_joint ? std::min(arrived, st.joint_planes) : decodable;
    if (a >= limit || a >= planes) break;
    if (!st.hooks_run) {
      st.hooks_run = true;
      for (int h : st.hooks) {
        if (static_cast<std::size_t>(st.top - h) == a && st.before_plane) {
          reconstruct_view(st.hook_view, st.view_shift ? st.view_shift(h) : 0);
          st.before_plane(h, st.hook_view);
          ++st.hook_version;
        }
      }
    }
    const std::size_t cut = *std::upper_bound(st.cuts.begin(), st.cuts.end(), a);
    const std::size_t end = std::min(cut, limit);
    std::size_t done = 0;
    bool stop = false;
    if (in_joint) {
      advance(*st.joint, st.joint_run, st.top, end, [&](std::size_t t) {
        return StreamPart{segment(t), t < segments.size(), true};
      });
      if (st.joint_run.error) std::rethrow_exception(st.joint_run.error);
      if (st.joint_run.corrupt) status = Status::kCorrupt, st.corrupt = stop = true;
      done = st.joint_run.next;
    } else {
      if (st.coders.empty()) {
        st.coders.reserve(static_cast<std::size_t>(np));
        for (int c = 0; c < np; ++c) {
          st.coders.emplace_back(st.layout, st.bands, c, nullptr);
          st.coders.back().copy_contexts(*st.joint);
          st.runs[static_cast<std::size_t>(c)].next = st.joint_planes;
        }
      }
      parallel_for(np, st.max_threads, [&](int c) {
        CoderRun& run = st.runs[static_cast<std::size_t>(c)];
        advance(st.coders[static_cast<std::size_t>(c)], run, st.top, end,
                [&](std::size_t t) { return st.splits[t - st.joint_planes].part(c); });
      });
      done = planes;
      for (const CoderRun& r : st.runs) {
        if (r.error) std::rethrow_exception(r.error);
        if (r.corrupt) status = Status::kCorrupt, st.corrupt = stop = true;
        done = std::min(done, r.next);
      }
    }
    if (stop || done != cut) break;
    st.range_start = cut;
    st.hooks_run = false;
  }

  if (st.coders.empty()) {
    result.segments_complete = st.joint_run.next;
    result.partial = st.joint_run.partial;
  } else {
    std::size_t complete = planes;
    for (const CoderRun& r : st.runs) {
      complete = std::min(complete, r.next);
      result.partial = result.partial || r.partial;
    }
    result.segments_complete = complete;
  }
  st.joint_run.partial = false;
  for (CoderRun& r : st.runs) r.partial = false;
  st.last = result;
  return status;
}

void BitplaneDecoder::reconstruct(std::vector<PatchCoefficients>& out) const {
  if (!s_) {
    out.clear();
    return;
  }
  reconstruct_view(out, 0);
}

void BitplaneDecoder::reconstruct_view(std::vector<PatchCoefficients>& out, int shift) const {
  const State& st = *s_;
  const std::size_t size = (std::size_t{1} << st.layout.level) + 1, samples = size * size;
  const int np = st.layout.num_patches;
  shift = std::clamp(shift, 0, st.layout.steps);
  out.resize(static_cast<std::size_t>(np));
  parallel_for(np, st.max_threads, [&](int c) {
    auto& patch = out[static_cast<std::size_t>(c)];
    if (shift == 0) {
      for (auto& ch : patch) ch.assign(samples, 0);
    } else {  // zero the positions at multiples of 2^shift only
      const std::size_t s = std::size_t{1} << shift;
      for (auto& ch : patch) {
        ch.resize(samples);
        for (std::size_t j = 0; j < size; j += s) {
          for (std::size_t i = 0; i < size; i += s) ch[j * size + i] = 0;
        }
      }
    }
    for (const auto& band : st.bands) {
      // Step k's details lie at odd multiples of 2^(k−1): none at multiples of 2^shift when k ≤ shift.
      if (band.patch == c && (band.orient == 0 || band.k > shift)) reconstruct_band(band, patch);
    }
  });
}

std::vector<std::uint64_t> BitplaneDecoder::patch_versions() const {
  if (!s_) return {};
  const State& st = *s_;
  std::vector<std::uint64_t> v;
  for (const CoderRun& r : st.runs) v.push_back(st.joint_run.version + st.hook_version + r.version);
  return v;
}

Status decode_bitplanes(const BitplaneLayout& layout, int top_bitplane,
                        const std::vector<std::vector<std::uint8_t>>& coded,
                        std::span<const std::span<const std::uint8_t>> segments,
                        std::span<const std::uint8_t> partial_tail, std::vector<PatchCoefficients>& out,
                        BitplaneDecodeResult& result, int max_threads, const DecodeHook& before_plane) {
  result = {};
  BitplaneDecoder decoder;
  const Status s = decoder.reset(layout, top_bitplane, coded, max_threads, before_plane);
  if (s != Status::kOk) return s;
  const Status status = decoder.update(segments, partial_tail, result);
  decoder.reconstruct(out);
  return status;
}

}  // namespace geomip::codec
