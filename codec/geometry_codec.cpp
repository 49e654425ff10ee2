#include "codec/geometry_codec.h"

#include "codec/parallel.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <utility>
#include <numeric>
#include <stdexcept>
#include <string>

#include "codec/bitplane_coder.h"
#include "codec/byte_io.h"

namespace geomip::codec {
namespace {

// Version 1: one joint bit-plane stream for all patches; version 2: a stream per patch (parallel decoding);
// version 3: version 2 plus local frames and orientation weights; version 4: version 3 plus the lifting
// update flag (bit 1 of the flags byte); version 5: version 4 plus the filter kCubicLong; version 6: version
// 5 with cell frames (see "Local frames" below); version 7: version 6 with a bottom bit-plane (a varint after
// the top one; GeometryCodecOptions::headroom_bits), written only when it is above 0.
constexpr std::uint8_t kHeaderVersion = 7;
constexpr int kMaxTangentialShift = 8;
constexpr int kMaxLevel = 12;
constexpr int kMaxTopBitplane = 48;
constexpr std::uint64_t kMaxTotalSamples = std::uint64_t{1} << 26;  // patches · (2^level+1)²

/// An array of n default-initialized (for these trivial types: not zero-filled) elements; what
/// std::make_unique_for_overwrite does, which Emscripten's libc++ lacks.
template <class T>
std::unique_ptr<T[]> uninitialized_array(std::size_t n) {
  return std::unique_ptr<T[]>(new T[n]);
}

int grid_size(int level) {
  return (1 << level) + 1;
}

/// Grid index of parameter k of side s (see PatchSeam).
int side_index(int level, int side, int k) {
  const int m = 1 << level, size = m + 1;
  int i, j;
  switch (side) {
    case 0:
      i = k, j = 0;
      break;
    case 1:
      i = m, j = k;
      break;
    case 2:
      i = m - k, j = m;
      break;
    default:
      i = 0, j = m - k;
      break;
  }
  return j * size + i;
}

/// Which samples are coded (the owner of each seam class: its lowest patch·size² + index sample), and the
/// (copy, owner) pairs of global indices (patch·size² + grid index) the decoder must fill.
struct Ownership {
  std::vector<std::vector<std::uint8_t>> coded;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> copies;
};

Ownership seam_ownership(int level, int num_patches, const std::vector<PatchSeam>& seams) {
  const int m = 1 << level;
  const std::size_t per_patch = static_cast<std::size_t>(grid_size(level)) * grid_size(level);
  Ownership own;
  own.coded.assign(static_cast<std::size_t>(num_patches), std::vector<std::uint8_t>(per_patch, 1));
  if (seams.empty()) return own;
  // Union-find over boundary samples only: id = (patch·4 + side)·m + k, k < m (each boundary sample once).
  const std::size_t ids = static_cast<std::size_t>(num_patches) * 4 * m;
  std::vector<std::uint32_t> parent(ids);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  auto id = [&](int p, int s, int k) {
    if (k == m) s = (s + 1) % 4, k = 0;
    return static_cast<std::uint32_t>((static_cast<std::size_t>(p) * 4 + s) * m + k);
  };
  for (const PatchSeam& seam : seams) {
    for (int k = 0; k <= m; ++k) {
      const std::uint32_t a = find(id(seam.patch, seam.side, k));
      const std::uint32_t b = find(id(seam.other_patch, seam.other_side, seam.reversed ? m - k : k));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  auto global = [&](std::uint32_t a) {
    const std::size_t p = a / (4 * static_cast<std::size_t>(m));
    const int s = static_cast<int>(a / m % 4), k = static_cast<int>(a % m);
    return p * per_patch + static_cast<std::size_t>(side_index(level, s, k));
  };
  std::vector<std::uint64_t> owner(ids, std::numeric_limits<std::uint64_t>::max());
  for (std::uint32_t a = 0; a < ids; ++a) {
    const std::uint32_t r = find(a);
    owner[r] = std::min<std::uint64_t>(owner[r], global(a));
  }
  for (std::uint32_t a = 0; a < ids; ++a) {
    const std::uint64_t g = global(a), o = owner[find(a)];
    if (g != o) {
      own.coded[g / per_patch][g % per_patch] = 0;
      own.copies.emplace_back(g, o);
    }
  }
  return own;
}

/// double → float without undefined behaviour for values beyond float's range (a header from bytes may hold
/// any finite origin and step): those become ±infinity.
float to_float(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);
}

bool seam_ok(const PatchSeam& s, int num_patches) {
  return s.patch >= 0 && s.patch < num_patches && s.other_patch >= 0 && s.other_patch < num_patches &&
         s.side >= 0 && s.side < 4 && s.other_side >= 0 && s.other_side < 4;
}

/// The checks parse() applies, shared with decode_geometry() for headers built by hand.
bool header_ok(const GeometryCodecHeader& h) {
  if (h.version < 1 || h.version > kHeaderVersion || h.level < 0 || h.level > kMaxLevel ||
      h.num_patches < 1 || h.steps < 0 || h.steps > h.level)
    return false;
  const std::uint64_t size = static_cast<std::uint64_t>(grid_size(h.level));
  if (static_cast<std::uint64_t>(h.num_patches) * size * size > kMaxTotalSamples) return false;
  if (h.filter != WaveletFilter::kLinear && h.filter != WaveletFilter::kCubic &&
      !(h.filter == WaveletFilter::kCubicLong && h.version >= 5))
    return false;
  for (double o : h.origin) {
    if (!std::isfinite(o)) return false;
  }
  if (!std::isfinite(h.step) || !(h.step > 0)) return false;
  if (h.top_bitplane < 0 || h.top_bitplane > kMaxTopBitplane) return false;
  if (h.bottom_bitplane < 0 || h.bottom_bitplane > h.top_bitplane ||
      (h.version < 7 && h.bottom_bitplane != 0))
    return false;
  if (h.joint_segments < 0 || h.joint_segments > h.top_bitplane - h.bottom_bitplane + 1 ||
      (h.version < 2 && h.joint_segments != 0))
    return false;
  if (h.version < 3 && (h.orientation_weights || h.frame_steps != 0 || h.tangential_shift != 0)) return false;
  if (h.version < 4 && h.lifting_update) return false;
  if (h.frame_steps < 0 || h.frame_steps > h.steps || h.tangential_shift < 0 ||
      h.tangential_shift > kMaxTangentialShift ||
      h.frame_start.size() != static_cast<std::size_t>(h.frame_steps))
    return false;
  for (int v : h.frame_start) {
    if (v < 0 || v > h.top_bitplane) return false;
  }
  if (h.seams.size() > 4 * static_cast<std::size_t>(h.num_patches)) return false;
  for (const auto& s : h.seams) {
    if (!seam_ok(s, h.num_patches)) return false;
  }
  return true;
}

using detail::put_varint;

void put_double(std::vector<std::uint8_t>& out, double d) {
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
}

/// Bounds-checked reader: every get fails (returns false) instead of reading past the end.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool byte(std::uint8_t& b) {
    if (pos_ >= bytes_.size()) return false;
    b = bytes_[pos_++];
    return true;
  }
  /// Varint of at most 5 bytes (values < 2^35), canonical (no trailing zero byte).
  bool varint(std::uint64_t& v) {
    return detail::read_varint(bytes_, pos_, v, 5, true) == detail::VarintRead::kOk;
  }
  bool small_int(int& out, std::uint64_t max) {
    std::uint64_t v;
    if (!varint(v) || v > max) return false;
    out = static_cast<int>(v);
    return true;
  }
  bool f64(double& d) {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) {
      std::uint8_t b;
      if (!byte(b)) return false;
      bits |= static_cast<std::uint64_t>(b) << (8 * i);
    }
    std::memcpy(&d, &bits, sizeof d);
    return true;
  }
  bool at_end() const { return pos_ == bytes_.size(); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

// ---- Local frames (version 3) ----------------------------------------------------------------------------
// A frame is three integer rows (normal, tangent, bitangent), each about 2^kFrameBits times a unit vector,
// built with integer arithmetic only from the decoder's reconstruction, so encoder and decoder (native or
// WASM) get bit-identical frames.
constexpr int kFrameBits = 14;
using Frame = std::array<std::int32_t, 9>;

/// floor(√v) for v < 2^62, exact: the double square root (correctly rounded everywhere, WASM included) only
/// seeds it, the integer fix-up decides.
std::uint64_t isqrt(std::uint64_t v) {
  std::uint64_t s = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(v)));
  while (s * s > v) --s;
  while ((s + 1) * (s + 1) <= v) ++s;
  return s;
}

/// round(num / den) for den > 0, halves up (floor((2·num + den) / (2·den))).
std::int64_t round_div(std::int64_t num, std::int64_t den) {
  const std::int64_t a = 2 * num + den, b = 2 * den;
  // Floor division without a branch on the sign (random for frame components): the truncated quotient,
  // one less when the remainder is negative (a < 0, inexact).
  const std::int64_t q = a / b, r = a % b;
  return q - (r < 0);
}

/// round(v / 2^s), halves up (s ≥ 0).
std::int64_t round_shift(std::int64_t v, int s) {
  return s == 0 ? v : (v + (std::int64_t{1} << (s - 1))) >> s;
}

/// Floor halvings of v until every component fits in 30 bits (a cross product of two such stays below 2^63).
void bound_to_30_bits(std::int64_t* v) {
  const auto largest = static_cast<std::uint64_t>(std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])}));
  if (largest >> 30) {  // more than 30 bits
    const int bits = static_cast<int>(std::bit_width(largest));
    v[0] >>= bits - 30, v[1] >>= bits - 30, v[2] >>= bits - 30;
  }
}

/// The frame whose normal is N (any length; identity rows for N = 0).
Frame make_frame(std::int64_t n0, std::int64_t n1, std::int64_t n2) {
  constexpr std::int32_t one = 1 << kFrameBits;
  const auto largest = static_cast<std::uint64_t>(std::max({std::abs(n0), std::abs(n1), std::abs(n2)}));
  if (largest >> 20) {  // more than 20 bits: floor halvings to < 2^20
    const int bits = static_cast<int>(std::bit_width(largest));
    n0 >>= bits - 20, n1 >>= bits - 20, n2 >>= bits - 20;
  }
  const std::uint64_t len = isqrt(static_cast<std::uint64_t>(n0 * n0 + n1 * n1 + n2 * n2));
  if (len == 0) return {one, 0, 0, 0, one, 0, 0, 0, one};
  const std::int64_t n[3] = {round_div(n0 * one, static_cast<std::int64_t>(len)),
                             round_div(n1 * one, static_cast<std::int64_t>(len)),
                             round_div(n2 * one, static_cast<std::int64_t>(len))};
  // Tangent: n × e_a, a the axis of n's smallest component (first on ties): never shorter than |n|·√(2/3).
  int a = 0;
  for (int c = 1; c < 3; ++c) {
    if (std::abs(n[c]) < std::abs(n[a])) a = c;
  }
  std::int64_t t[3] = {0, 0, 0};
  t[(a + 1) % 3] = n[(a + 2) % 3];
  t[(a + 2) % 3] = -n[(a + 1) % 3];
  const std::int64_t b[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
  const auto unit = [](const std::int64_t* v, std::int32_t* out) {
    const std::uint64_t l = isqrt(static_cast<std::uint64_t>(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    for (int c = 0; c < 3; ++c)
      out[c] = l == 0 ? 0 : static_cast<std::int32_t>(round_div(v[c] * one, static_cast<std::int64_t>(l)));
  };
  Frame f;
  for (int c = 0; c < 3; ++c) f[static_cast<std::size_t>(c)] = static_cast<std::int32_t>(n[c]);
  unit(t, f.data() + 3);
  unit(b, f.data() + 6);
  return f;
}

// Cell frames (version 6). A version-3 to -5 frame is built per framed sample from its own normal (three
// integer square roots and nine divisions, 29 M of the bunny's 197 M decoder instructions) and that normal
// from the finest reconstruction (a whole extra inverse transform per framed step). Version 6 takes the
// normal from the step's coarse grid instead (no inverse at the step's own spacing) and the frame from a
// table: the frame of the centre of the normal's cell in a 2^kFrameCellBits × 2^kFrameCellBits octahedral map
// of directions (a cell spans at most ~2.8°, far below the noise of a normal estimated from coarse samples).
// Measured as bit-rate neutral (docs/codec-v3.md, "Cell frames").
constexpr int kFrameCellBits = 6;
constexpr int kFrameCells = 1 << (2 * kFrameCellBits);
constexpr std::uint16_t kZeroNormalCell = kFrameCells;  // a zero normal: the identity frame
constexpr std::uint16_t kUnsetCell = 0xFFFF;            // FrameField::cell: not computed yet

/// The octahedral cell of direction (x, y, z) (any length; kZeroNormalCell for zero): the upper hemisphere
/// maps to the diamond |u| + |v| ≤ 1 by (x, y) / L1, the lower one folded outside it; cell (U, V) holds
/// u ∈ [2U/N − 1, 2(U+1)/N − 1). Integer arithmetic only.
std::uint16_t octahedral_cell(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto largest = static_cast<std::uint64_t>(std::max({std::abs(x), std::abs(y), std::abs(z)}));
  if (largest >> 40) {  // more than 40 bits (garbage): floor halvings to < 2^40
    const int bits = static_cast<int>(std::bit_width(largest)) - 40;
    x >>= bits, y >>= bits, z >>= bits;
  }
  const std::int64_t l1 = std::abs(x) + std::abs(y) + std::abs(z);
  if (l1 == 0) return kZeroNormalCell;
  std::int64_t a = x, b = y;
  if (z < 0) {
    a = x >= 0 ? l1 - std::abs(y) : std::abs(y) - l1;
    b = y >= 0 ? l1 - std::abs(x) : std::abs(x) - l1;
  }
  constexpr std::int64_t n = std::int64_t{1} << kFrameCellBits;
  const std::int64_t u = std::min(((a + l1) * n) / (2 * l1), n - 1),
                     v = std::min(((b + l1) * n) / (2 * l1), n - 1);
  return static_cast<std::uint16_t>(v * n + u);
}

/// The frames of the octahedral cells' centres (and the identity at kZeroNormalCell), built once.
const std::vector<Frame>& cell_frames() {
  static const std::vector<Frame> table = [] {
    constexpr std::int64_t n = std::int64_t{1} << kFrameCellBits;
    std::vector<Frame> t(static_cast<std::size_t>(kFrameCells) + 1);
    for (std::int64_t v = 0; v < n; ++v) {
      for (std::int64_t u = 0; u < n; ++u) {
        std::int64_t x = 2 * u + 1 - n, y = 2 * v + 1 - n;  // the centre, in units of 1/n
        const std::int64_t z = n - std::abs(x) - std::abs(y);
        if (z < 0) {  // the lower hemisphere, unfolded
          const std::int64_t fx = n - std::abs(y), fy = n - std::abs(x);
          x = x >= 0 ? fx : -fx;
          y = y >= 0 ? fy : -fy;
        }
        t[static_cast<std::size_t>(v * n + u)] = make_frame(x << 12, y << 12, z * 4096);
      }
    }
    t[kZeroNormalCell] = make_frame(0, 0, 0);
    return t;
  }();
  return table;
}

/// The local frames of one model: per patch and grid index (filled at the framed positions of the steps
/// whose frames were computed).
struct FrameField {
  int level = 0, steps = 0, frame_steps = 0, tangential_shift = 0;
  WaveletFilter filter = WaveletFilter::kCubic;
  bool update = false;  // the wavelet's update step (header version 4)
  bool cells = false;   // cell frames (header version 6)
  const Frame* cell_table = nullptr;  // cell_frames() when cells
  const Ownership* own = nullptr;
  std::vector<int> start;                                         // start plane of step k at [k − 1]
  std::size_t samples = 0;  // grid positions per patch
  int max_threads = 1;      // compute() and to_xyz() run their patches on up to this many threads
  // [patch][grid index]; left uninitialized (no zero-fill of 24 B per position): only the coded framed
  // positions of computed steps are written (compute()), and only those are read (frame()).
  std::vector<std::unique_ptr<std::array<std::int64_t, 3>[]>> normals;
  // Version 6 instead of normals and frames: the coarse grid each framed step's normals come from (kept from
  // the step's hook; steps starting at one plane share one), and the octahedral cell of a position's normal,
  // computed when its frame is first needed (kUnsetCell before: most positions of a short prefix need none).
  struct CellGrid {
    int sh = 0;                     // grid position (i, j) is (i >> sh, j >> sh) here
    std::size_t sub = 0;            // samples per row
    bool bounded = false;           // every sample below 2^27 in magnitude: the differences' bound never acts
    std::unique_ptr<std::int32_t[]> xyz;  // the samples, three values each (sub² of them)
  };
  std::vector<std::vector<std::shared_ptr<const CellGrid>>> step_grid;  // [patch][k − 1]
  mutable std::vector<std::unique_ptr<std::uint16_t[]>> cell;           // [patch][grid index]
  std::vector<std::uint8_t> ready;  // [k − 1]: normals of step k computed
  // Frames built so far (an incremental decoder reconstructs many times from the same normals); an entry is
  // valid where built[p][i] is set (the rest stays uninitialized).
  mutable std::vector<std::unique_ptr<Frame[]>> frames;  // [patch][grid index]
  mutable std::vector<std::vector<std::uint8_t>> built;  // [patch][grid index]: frames[...] is valid

  /// The frame at a framed position (built when first needed: only non-zero coefficients need one; the
  /// normal of a position never changes once its step is ready).
  const Frame& frame(std::size_t p, int idx, int gi, int gj) const {
    const auto i = static_cast<std::size_t>(idx);
    if (cells) {
      if (cell[p][i] == kUnsetCell) fill_cells(p, std::countr_zero(static_cast<unsigned>(gi | gj)) + 1);
      return cell_table[cell[p][i]];
    }
    if (built[p].empty()) {  // first frame of this patch
      frames[p] = uninitialized_array<Frame>(samples);
      built[p].assign(samples, 0);
    }
    if (!built[p][i]) {
      const auto& n = normals[p][i];
      frames[p][i] = make_frame(n[0], n[1], n[2]);
      built[p][i] = 1;
    }
    return frames[p][i];
  }

  /// Calls f(i, j, index) for every detail position of step k.
  template <typename F>
  void for_step(int k, F&& f) const {
    const int m = 1 << level, s = 1 << (k - 1), size = m + 1;
    for (int j = 0; j <= m; j += s) {
      const bool odd_row = (j / s) & 1;
      for (int i = odd_row ? 0 : s; i <= m; i += odd_row ? s : 2 * s) f(i, j, j * size + i);
    }
  }

  /// Framed coefficients (n, t1, t2) of the ready steps, at coded positions, back to xyz (steps ≥ min_k).
  void to_xyz(std::vector<PatchCoefficients>& coefs, int min_k = 1) const {
    const int m = 1 << level;
    const std::size_t size = static_cast<std::size_t>(m) + 1;
    parallel_for(static_cast<int>(coefs.size()), max_threads, [&](int pi) {
      const auto p = static_cast<std::size_t>(pi);
      const std::uint8_t* coded = own->coded[p].data();
      std::int32_t* const ch[3] = {coefs[p][0].data(), coefs[p][1].data(), coefs[p][2].data()};
      for (int k = std::max(min_k, 1); k <= frame_steps; ++k) {
        if (!ready[static_cast<std::size_t>(k - 1)]) continue;
        const int d = 1 << (k - 1);  // the detail positions of step k, row by row (as for_step())
        for (int j = 0; j <= m; j += d) {
          const bool odd_row = (j / d) & 1;
          const std::size_t line = static_cast<std::size_t>(j) * size;
          for (int i = odd_row ? 0 : d; i <= m; i += odd_row ? d : 2 * d) {
            const std::size_t idx = line + static_cast<std::size_t>(i);
            if (!coded[idx] || (ch[0][idx] | ch[1][idx] | ch[2][idx]) == 0) continue;
            const Frame& f = frame(p, static_cast<int>(idx), i, j);
            const std::int64_t w0 = ch[0][idx],
                               w1 = std::int64_t{ch[1][idx]} * (std::int64_t{1} << tangential_shift),
                               w2 = std::int64_t{ch[2][idx]} * (std::int64_t{1} << tangential_shift);
            for (int c = 0; c < 3; ++c) {
              const std::int64_t v = std::int64_t{f[static_cast<std::size_t>(c)]} * w0 +
                                     std::int64_t{f[static_cast<std::size_t>(3 + c)]} * w1 +
                                     std::int64_t{f[static_cast<std::size_t>(6 + c)]} * w2;
              ch[c][idx] = static_cast<std::int32_t>(static_cast<std::uint32_t>(round_shift(v, kFrameBits)));
            }
          }
        }
      }
    });
  }

  /// The finest framed step that starts at `plane` (0: none).
  int finest_step_starting_at(int plane) const {
    for (int k = 1; k <= frame_steps; ++k) {
      if (start[static_cast<std::size_t>(k - 1)] == plane) return k;
    }
    return 0;
  }

  /// The grid positions compute(plane, view) reads: multiples of 2^view_shift(plane) (HookViewShift).
  int view_shift(int plane) const {
    const int min_k = finest_step_starting_at(plane);
    // Cell frames read the coarse grid of step min_k (spacing 2^min_k; the framed steps above min_k lie on
    // it, and the seam copies map it to itself), the normals of versions 3–5 the grid at spacing 2^(min_k−1).
    if (min_k == 0) return 0;
    return cells ? min_k : min_k - 1;
  }

  /// The frames of the steps that start at `plane`, from `view` (the decoder's coefficients before that
  /// plane): framed steps already started go back to xyz, seam copies are filled, and the grid at the
  /// spacing of the finest such step is reconstructed; the normal at a detail of step k (spacing s) is the
  /// cross product of the central differences (i ± s, j) and (i, j ± s) of that reconstruction (one-sided on
  /// the border).
  void compute(int plane, std::vector<PatchCoefficients>& view) {
    const int min_k = finest_step_starting_at(plane);
    if (min_k == 0) return;
    std::vector<PatchCoefficients>& w = view;  // scratch: changed in place
    to_xyz(w, min_k);
    const std::size_t size = (std::size_t{1} << level) + 1;  // samples: the member (size²)
    for (const auto& [copy, owner] : own->copies) {
      for (int c = 0; c < 3; ++c)
        w[copy / samples][c][copy % samples] = w[owner / samples][c][owner % samples];
    }
    if (cells) {
      compute_cells(plane, min_k, w);
      return;
    }
    const int s = 1 << (min_k - 1), sub_level = level - (min_k - 1), sub_steps = steps - (min_k - 1);
    const std::size_t sub = (std::size_t{1} << sub_level) + 1;
    const int m = 1 << level;
    parallel_for(static_cast<int>(w.size()), max_threads, [&](int pi) {
      const auto p = static_cast<std::size_t>(pi);
      // The grid at spacing s: w's own channels at s = 1 (w is scratch), else a gathered sub-grid.
      std::array<std::vector<std::int32_t>, 3> gathered;
      std::array<std::span<std::int32_t>, 3> g;
      for (int c = 0; c < 3; ++c) {
        if (s == 1) {
          g[c] = w[p][c];
        } else {
          gathered[c].resize(sub * sub);
          for (std::size_t y = 0; y < sub; ++y) {
            for (std::size_t x = 0; x < sub; ++x) gathered[c][y * sub + x] = w[p][c][(y * s) * size + x * s];
          }
          g[c] = gathered[c];
        }
        wavelet_inverse(g[c], sub_level, sub_steps, filter, update, min_k);
      }
      // Sub-grid coordinates: position (i, j) of the grid is (i >> sh, j >> sh) of g, whose last index is ms.
      const int sh = min_k - 1, ms = m >> sh;
      const std::uint8_t* coded = own->coded[p].data();
      auto& out = normals[p];
      for (int k = min_k; k <= frame_steps; ++k) {
        if (start[static_cast<std::size_t>(k - 1)] != plane) continue;
        const int d = 1 << (k - 1), dd = d >> sh;  // the step's spacing in the grid and in g
        for (int j = 0; j <= m; j += d) {
          const bool odd_row = (j / d) & 1;
          const int y = j >> sh, y0 = std::max(y - dd, 0), y1 = std::min(y + dd, ms);
          const std::int32_t *row[3], *below[3], *above[3];
          for (int c = 0; c < 3; ++c) {
            row[c] = g[c].data() + static_cast<std::size_t>(y) * sub;
            below[c] = g[c].data() + static_cast<std::size_t>(y0) * sub;
            above[c] = g[c].data() + static_cast<std::size_t>(y1) * sub;
          }
          const std::size_t line = static_cast<std::size_t>(j) * size;
          for (int i = odd_row ? 0 : d; i <= m; i += odd_row ? d : 2 * d) {
            if (!coded[line + static_cast<std::size_t>(i)]) continue;
            const int x = i >> sh, x0 = std::max(x - dd, 0), x1 = std::min(x + dd, ms);
            std::int64_t a[3], b[3];
            for (int c = 0; c < 3; ++c) {
              a[c] = std::int64_t{row[c][x1]} - row[c][x0];
              b[c] = std::int64_t{above[c][x]} - below[c][x];
            }
            // Differences of garbage (a corrupt stream) can reach 2^33: keep the cross product below 2^63.
            // Never active for streams of this encoder (quantized values < 2^25).
            bound_to_30_bits(a), bound_to_30_bits(b);
            out[line + static_cast<std::size_t>(i)] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                                       a[0] * b[1] - a[1] * b[0]};
          }
        }
      }
    });
    for (int k = min_k; k <= frame_steps; ++k) {
      if (start[static_cast<std::size_t>(k - 1)] == plane) ready[static_cast<std::size_t>(k - 1)] = 1;
    }
  }

  /// Version 6: the grid at spacing 2^min_k (the coarse grid of step min_k, whose details are all still zero)
  /// is reconstructed from `w` (xyz, seam copies filled) and kept for the steps starting at `plane`
  /// (fill_cells()).
  void compute_cells(int plane, int min_k, std::vector<PatchCoefficients>& w) {
    const std::size_t size = (std::size_t{1} << level) + 1;
    const int s2 = 1 << min_k, sub_level = level - min_k, sub_steps = steps - min_k;
    const std::size_t sub = (std::size_t{1} << sub_level) + 1;
    parallel_for(static_cast<int>(w.size()), max_threads, [&](int pi) {
      const auto p = static_cast<std::size_t>(pi);
      auto grid = std::make_shared<CellGrid>();
      grid->sh = min_k;
      grid->sub = sub;
      std::int32_t low = 0, high = 0;
      // Both written in full before they are read: no zero-fill.
      grid->xyz = uninitialized_array<std::int32_t>(3 * sub * sub);
      const std::size_t count = sub * sub;
      const std::unique_ptr<std::int32_t[]> gathered = uninitialized_array<std::int32_t>(count);
      const std::span<std::int32_t> g(gathered.get(), count);
      for (int c = 0; c < 3; ++c) {
        for (std::size_t y = 0; y < sub; ++y) {
          const std::int32_t* src = w[p][c].data() + y * static_cast<std::size_t>(s2) * size;
          std::int32_t* dst = g.data() + y * sub;
          for (std::size_t x = 0; x < sub; ++x) dst[x] = src[x * static_cast<std::size_t>(s2)];
        }
        if (sub_steps > 0) wavelet_inverse(g, sub_level, sub_steps, filter, update, min_k + 1);
        for (std::size_t q = 0; q < g.size(); ++q) {
          low = std::min(low, g[q]), high = std::max(high, g[q]);
          grid->xyz[3 * q + static_cast<std::size_t>(c)] = g[q];
        }
      }
      // Samples below 2^27 in magnitude (every stream of this encoder) keep the differences below 2^30.
      grid->bounded = low > -(std::int32_t{1} << 27) && high < (std::int32_t{1} << 27);
      for (int k = min_k; k <= frame_steps; ++k) {
        if (start[static_cast<std::size_t>(k - 1)] == plane)
          step_grid[p][static_cast<std::size_t>(k - 1)] = grid;
      }
    });
    for (int k = min_k; k <= frame_steps; ++k) {
      if (start[static_cast<std::size_t>(k - 1)] == plane) ready[static_cast<std::size_t>(k - 1)] = 1;
    }
  }

  /// Version 6: the octahedral cells of the normals at the coded details of patch p's ready step k, all at
  /// once when the first is needed (a short prefix needs none of most steps). The normal at detail (i, j)
  /// (spacing d = 2^(k−1)) is the cross product of differences of the step's coarse grid around it — across
  /// the coarse cell's sides for a row detail (odd i / d: (i ± d, j), and the sums of (i − d, ·) and
  /// (i + d, ·) at rows j ± 2d), mirrored for a column detail, along the cell's sides for a centre detail
  /// ((i ± d, j ± d)), clamped to the patch on the border.
  void fill_cells(std::size_t p, int k) const {
    const CellGrid& grid = *step_grid[p][static_cast<std::size_t>(k - 1)];
    const int sh = grid.sh, d = 1 << (k - 1), m = 1 << level;
    const auto sub = static_cast<std::ptrdiff_t>(grid.sub);
    const std::size_t size = static_cast<std::size_t>(m) + 1;
    const std::int32_t* const g = grid.xyz.get();
    // The samples of the grid's row y (a multiple of 2^sh) and the offset of its column x in such a row.
    const auto row_at = [&](int y) { return g + 3 * static_cast<std::ptrdiff_t>(y >> sh) * sub; };
    const auto col = [&](int x) { return 3 * static_cast<std::ptrdiff_t>(x >> sh); };
    const std::uint8_t* coded = own->coded[p].data();
    std::uint16_t* out = cell[p].get();
    for (int j = 0; j <= m; j += d) {
      const bool odd_row = (j / d) & 1;
      const std::size_t line = static_cast<std::size_t>(j) * size;
      // Rows j, j ± 2d (clamped) for a row detail; j ± d for the others.
      const std::int32_t *const mid = odd_row ? nullptr : row_at(j),
                                *const lo = row_at(odd_row ? j - d : std::max(j - 2 * d, 0)),
                                *const hi = row_at(odd_row ? j + d : std::min(j + 2 * d, m));
      for (int i = odd_row ? 0 : d; i <= m; i += odd_row ? d : 2 * d) {
        if (!coded[line + static_cast<std::size_t>(i)]) continue;
        std::int64_t a[3], b[3];
        if (!odd_row) {  // a row detail: (i ± d, j) are coarse samples
          const std::ptrdiff_t xl = col(i - d), xr = col(i + d);
          const std::int32_t *l = mid + xl, *r = mid + xr, *ll = lo + xl, *lr = lo + xr, *ul = hi + xl,
                             *ur = hi + xr;
          for (int c = 0; c < 3; ++c) {
            a[c] = std::int64_t{r[c]} - l[c];
            b[c] = std::int64_t{ul[c]} + ur[c] - ll[c] - lr[c];
          }
        } else if (!((i / d) & 1)) {  // a column detail: (i, j ± d) are coarse samples
          const std::ptrdiff_t x = col(i), x0 = col(std::max(i - 2 * d, 0)), x1 = col(std::min(i + 2 * d, m));
          const std::int32_t *l = lo + x, *h = hi + x, *ll = lo + x0, *lr = lo + x1, *ul = hi + x0,
                             *ur = hi + x1;
          for (int c = 0; c < 3; ++c) {
            a[c] = std::int64_t{lr[c]} + ur[c] - ll[c] - ul[c];
            b[c] = std::int64_t{h[c]} - l[c];
          }
        } else {  // a centre detail: the cell's corners (i ± d, j ± d)
          const std::ptrdiff_t xl = col(i - d), xr = col(i + d);
          const std::int32_t *ll = lo + xl, *lr = lo + xr, *ul = hi + xl, *ur = hi + xr;
          for (int c = 0; c < 3; ++c) {
            a[c] = std::int64_t{lr[c]} + ur[c] - ll[c] - ul[c];
            b[c] = std::int64_t{ul[c]} + ur[c] - ll[c] - lr[c];
          }
        }
        // Sums of garbage (a corrupt stream) reach 2^35: keep the cross product below 2^63.
        if (!grid.bounded) bound_to_30_bits(a), bound_to_30_bits(b);
        out[line + static_cast<std::size_t>(i)] =
            octahedral_cell(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
      }
    }
  }

  /// Encoder: the xyz coefficients of the steps starting at `plane` into their frames (n, t1, t2), the
  /// tangential ones shifted.
  void to_frames(int plane, std::vector<PatchCoefficients>& coefs) const {
    for (std::size_t p = 0; p < coefs.size(); ++p) {
      for (int k = 1; k <= frame_steps; ++k) {
        if (start[static_cast<std::size_t>(k - 1)] != plane) continue;
        for_step(k, [&](int gi, int gj, int idx) {
          if (!own->coded[p][static_cast<std::size_t>(idx)]) return;
          std::int64_t d[3];
          for (int c = 0; c < 3; ++c)
            d[c] = coefs[p][static_cast<std::size_t>(c)][static_cast<std::size_t>(idx)];
          if (d[0] == 0 && d[1] == 0 && d[2] == 0) return;
          const Frame& f = frame(p, idx, gi, gj);
          for (int r = 0; r < 3; ++r) {
            const std::int64_t v = static_cast<std::int64_t>(f[static_cast<std::size_t>(3 * r)]) * d[0] +
                                   static_cast<std::int64_t>(f[static_cast<std::size_t>(3 * r + 1)]) * d[1] +
                                   static_cast<std::int64_t>(f[static_cast<std::size_t>(3 * r + 2)]) * d[2];
            coefs[p][static_cast<std::size_t>(r)][static_cast<std::size_t>(idx)] = static_cast<std::int32_t>(
                round_shift(round_shift(v, kFrameBits), r == 0 ? 0 : tangential_shift));
          }
        });
      }
    }
  }
};

FrameField make_frame_field(const GeometryCodecHeader& h, const Ownership& own) {
  FrameField ff;
  ff.level = h.level;
  ff.steps = h.steps;
  ff.frame_steps = h.frame_steps;
  ff.tangential_shift = h.tangential_shift;
  ff.filter = h.filter;
  ff.update = h.lifting_update;
  ff.cells = h.version >= 6;
  if (ff.cells) ff.cell_table = cell_frames().data();
  ff.own = &own;
  ff.start = h.frame_start;
  ff.ready.assign(static_cast<std::size_t>(h.frame_steps), 0);
  if (h.frame_steps > 0) {
    const std::size_t size = static_cast<std::size_t>(grid_size(h.level));
    ff.samples = size * size;
    if (ff.cells) {
      ff.cell.resize(static_cast<std::size_t>(h.num_patches));
      for (auto& c : ff.cell) {
        c = uninitialized_array<std::uint16_t>(ff.samples);
        std::fill_n(c.get(), ff.samples, kUnsetCell);
      }
      ff.step_grid.assign(
          static_cast<std::size_t>(h.num_patches),
          std::vector<std::shared_ptr<const FrameField::CellGrid>>(static_cast<std::size_t>(h.frame_steps)));
    } else {
      ff.normals.resize(static_cast<std::size_t>(h.num_patches));
      for (auto& n : ff.normals) n = uninitialized_array<std::array<std::int64_t, 3>>(ff.samples);
    }
    ff.frames.resize(static_cast<std::size_t>(h.num_patches));
    ff.built.resize(static_cast<std::size_t>(h.num_patches));
  }
  return ff;
}

BitplaneLayout make_layout(const GeometryCodecHeader& h) {
  BitplaneLayout layout{h.level, h.steps, h.num_patches, h.version >= 2, h.joint_segments};
  layout.orientation_weights = h.orientation_weights;
  layout.own_deferred_contexts = h.version >= 3;
  layout.bottom_bitplane = h.bottom_bitplane;
  for (int k = 1; k <= h.frame_steps && k <= static_cast<int>(h.frame_start.size()); ++k)
    layout.start_plane[static_cast<std::size_t>(k)] = h.frame_start[static_cast<std::size_t>(k - 1)];
  return layout;
}

}  // namespace

std::vector<std::uint8_t> GeometryCodecHeader::serialize() const {
  std::vector<std::uint8_t> out;
  out.push_back(static_cast<std::uint8_t>(version));
  put_varint(out, static_cast<std::uint64_t>(level));
  put_varint(out, static_cast<std::uint64_t>(num_patches));
  put_varint(out, static_cast<std::uint64_t>(steps));
  out.push_back(static_cast<std::uint8_t>(filter));
  for (double o : origin) put_double(out, o);
  put_double(out, step);
  put_varint(out, static_cast<std::uint64_t>(top_bitplane));
  if (version >= 7) put_varint(out, static_cast<std::uint64_t>(bottom_bitplane));
  if (version >= 2) put_varint(out, static_cast<std::uint64_t>(joint_segments));
  if (version >= 3) {
    out.push_back(static_cast<std::uint8_t>((orientation_weights ? 1 : 0) | (lifting_update ? 2 : 0)));
    put_varint(out, static_cast<std::uint64_t>(frame_steps));
    put_varint(out, static_cast<std::uint64_t>(tangential_shift));
    for (int v : frame_start) put_varint(out, static_cast<std::uint64_t>(v));
  }
  put_varint(out, seams.size());
  for (const auto& s : seams) {
    put_varint(out, static_cast<std::uint64_t>(s.patch));
    put_varint(out, static_cast<std::uint64_t>(s.other_patch));
    out.push_back(static_cast<std::uint8_t>((s.side & 3) | (s.other_side & 3) << 2 | (s.reversed ? 16 : 0)));
  }
  return out;
}

Status GeometryCodecHeader::parse(std::span<const std::uint8_t> bytes, GeometryCodecHeader& out) {
  Reader r(bytes);
  GeometryCodecHeader h;
  std::uint8_t version, filter;
  if (!r.byte(version) || version < 1 || version > kHeaderVersion) return Status::kCorrupt;
  h.version = version;
  if (!r.small_int(h.level, kMaxLevel) || !r.small_int(h.num_patches, 1 << 20) ||
      !r.small_int(h.steps, kMaxLevel) || !r.byte(filter) || filter > (h.version >= 5 ? 2 : 1)) {
    return Status::kCorrupt;
  }
  h.filter = static_cast<WaveletFilter>(filter);
  for (double& o : h.origin) {
    if (!r.f64(o)) return Status::kCorrupt;
  }
  int num_seams = 0;
  if (!r.f64(h.step) || !r.small_int(h.top_bitplane, kMaxTopBitplane) ||
      (h.version >= 7 && !r.small_int(h.bottom_bitplane, kMaxTopBitplane)) ||
      (h.version >= 2 && !r.small_int(h.joint_segments, kMaxTopBitplane + 1))) {
    return Status::kCorrupt;
  }
  if (h.version >= 3) {
    std::uint8_t flags;
    if (!r.byte(flags) || flags > (h.version >= 4 ? 3 : 1) || !r.small_int(h.frame_steps, kMaxLevel) ||
        !r.small_int(h.tangential_shift, kMaxTangentialShift)) {
      return Status::kCorrupt;
    }
    h.orientation_weights = (flags & 1) != 0;
    h.lifting_update = (flags & 2) != 0;
    h.frame_start.resize(static_cast<std::size_t>(h.frame_steps));
    for (int& v : h.frame_start) {
      if (!r.small_int(v, kMaxTopBitplane)) return Status::kCorrupt;
    }
  }
  if (!r.small_int(num_seams, 1 << 22)) return Status::kCorrupt;
  if (num_seams > 4 * h.num_patches) return Status::kCorrupt;
  h.seams.resize(static_cast<std::size_t>(num_seams));
  for (auto& s : h.seams) {
    std::uint8_t packed;
    if (!r.small_int(s.patch, 1 << 20) || !r.small_int(s.other_patch, 1 << 20) || !r.byte(packed) ||
        (packed & ~0x1F) != 0) {
      return Status::kCorrupt;
    }
    s.side = packed & 3;
    s.other_side = (packed >> 2) & 3;
    s.reversed = (packed & 16) != 0;
  }
  if (!r.at_end() || !header_ok(h)) return Status::kCorrupt;
  out = std::move(h);
  return Status::kOk;
}

EncodedGeometry encode_geometry(const std::vector<Grid3>& patches, const std::vector<PatchSeam>& seams,
                                const GeometryCodecOptions& options) {
  if (patches.empty()) throw std::invalid_argument("encode_geometry: no patches");
  const int level = patches[0].level;
  if (level < 0 || level > kMaxLevel) {
    throw std::invalid_argument("encode_geometry: level " + std::to_string(level) + " outside [0, 12]");
  }
  const std::size_t size = static_cast<std::size_t>(grid_size(level)), samples = size * size;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    if (patches[p].level != level || patches[p].values.size() != 3 * samples) {
      throw std::invalid_argument("encode_geometry: patch " + std::to_string(p) +
                                  " has another level or size");
    }
  }
  if (options.quantization_bits < 1 || options.quantization_bits > 24) {
    throw std::invalid_argument("encode_geometry: quantization_bits must be in [1, 24]");
  }
  if (options.headroom_bits < 0) throw std::invalid_argument("encode_geometry: headroom_bits must be ≥ 0");
  const int headroom = std::min(options.headroom_bits, 24 - options.quantization_bits);
  if (headroom > 0 && !options.cell_frames)
    throw std::invalid_argument("encode_geometry: headroom_bits needs cell_frames (codec header version 7)");
  if (options.steps < -1 || options.steps > level) {
    throw std::invalid_argument("encode_geometry: steps must be -1 or in [0, level]");
  }
  if (options.frame_steps < 0 || options.frame_steps > kMaxLevel || options.tangential_shift < 0 ||
      options.tangential_shift > kMaxTangentialShift) {
    throw std::invalid_argument("encode_geometry: frame_steps or tangential_shift out of range");
  }
  const int np = static_cast<int>(patches.size());
  if (seams.size() > 4 * patches.size())
    throw std::invalid_argument("encode_geometry: more than 4 seams per patch");
  for (const auto& s : seams) {
    if (!seam_ok(s, np)) throw std::invalid_argument("encode_geometry: seam references a bad patch or side");
  }
  if (static_cast<std::uint64_t>(np) * samples > kMaxTotalSamples) {
    throw std::invalid_argument("encode_geometry: too many samples");
  }

  double lo[3], hi[3];
  for (int c = 0; c < 3; ++c) lo[c] = INFINITY, hi[c] = -INFINITY;
  for (const auto& g : patches) {
    for (std::size_t i = 0; i < samples; ++i) {
      for (int c = 0; c < 3; ++c) {
        const double v = g.values[3 * i + c];
        if (!std::isfinite(v)) throw std::invalid_argument("encode_geometry: NaN or infinite sample");
        lo[c] = std::min(lo[c], v);
        hi[c] = std::max(hi[c], v);
      }
    }
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  EncodedGeometry result;
  GeometryCodecHeader& h = result.header;
  h.level = level;
  h.num_patches = np;
  h.steps = options.steps < 0 ? level : options.steps;
  h.filter = options.filter;
  for (int c = 0; c < 3; ++c) h.origin[c] = lo[c];
  h.step = extent > 0 ? extent / std::ldexp(1.0, options.quantization_bits + headroom) : 1.0;
  h.bottom_bitplane = headroom;
  h.seams = seams;

  const Ownership own = seam_ownership(level, np, seams);
  std::vector<PatchCoefficients> coefs(static_cast<std::size_t>(np));
  for (int p = 0; p < np; ++p) {
    for (int c = 0; c < 3; ++c) {
      auto& ch = coefs[p][c];
      ch.resize(samples);
      for (std::size_t i = 0; i < samples; ++i) {
        ch[i] = static_cast<std::int32_t>(std::lround((patches[p].values[3 * i + c] - h.origin[c]) / h.step));
      }
    }
  }
  // Seam copies take their owner's integers (equal anyway for bit-identical seams), so the per-patch
  // transforms give every copy its owner's coefficient.
  for (const auto& [copy, owner] : own.copies) {
    for (int c = 0; c < 3; ++c)
      coefs[copy / samples][c][copy % samples] = coefs[owner / samples][c][owner % samples];
  }
  for (auto& pc : coefs) {
    for (auto& ch : pc) wavelet_forward(ch, level, h.steps, h.filter, options.lifting_update);
  }
  // Version 6 differs from 5 only in how frames are built: without cell frames the stream is version 5's (and
  // a stream without frames, such as a normal map's, is version 5's but for this byte).
  h.version = !options.cell_frames ? 5 : headroom > 0 ? kHeaderVersion : 6;
  h.orientation_weights = options.orientation_weights;
  h.lifting_update = options.lifting_update;
  h.frame_steps = std::min(options.frame_steps, h.steps);
  h.tangential_shift = h.frame_steps > 0 ? options.tangential_shift : 0;
  // Start plane of the framed details of step k: one plane above the top of their xyz magnitudes (a frame
  // rotation lengthens no component by more than √3, rounding included, so the framed magnitudes fit).
  FrameField ff = make_frame_field(h, own);
  {
    BitplaneLayout probe = make_layout(h);
    for (int k = 1; k <= h.frame_steps; ++k) {
      int start = 0;
      const int s = 1 << (k - 1);
      for (int p = 0; p < np; ++p) {
        ff.for_step(k, [&](int i, int j, int idx) {
          if (!own.coded[static_cast<std::size_t>(p)][static_cast<std::size_t>(idx)]) return;
          std::int64_t mx = 0;
          for (int c = 0; c < 3; ++c)
            mx = std::max<std::int64_t>(mx, std::abs(static_cast<std::int64_t>(coefs[p][c][idx])));
          if (mx == 0) return;
          const bool odd_x = (i / s) & 1, odd_y = (j / s) & 1;
          const int orient = odd_x && odd_y ? 3 : (odd_x ? 1 : 2);
          start = std::max(start, static_cast<int>(std::bit_width(static_cast<std::uint64_t>(mx))) +
                                      band_offset(probe, k, orient));
        });
      }
      h.frame_start.push_back(start);
    }
  }
  ff.start = h.frame_start;
  // joint_bytes 0 means per patch from the first plane: a joint_segments of 0 (encode_bitplanes reads 0 as
  // "no automatic choice").
  BitplaneLayout layout = make_layout(h);
  layout.joint_segments = 0;
  const EncodeHook hook = [&](int plane, std::vector<PatchCoefficients>& view,
                              std::vector<PatchCoefficients>& cf) {
    ff.compute(plane, view);
    ff.to_frames(plane, cf);
  };
  BitplaneEncoding enc = encode_bitplanes(layout, coefs, own.coded, options.joint_bytes, hook);
  h.top_bitplane = enc.top_bitplane;
  h.joint_segments = enc.joint_segments;
  result.segments = std::move(enc.segments);
  return result;
}

struct GeometryDecoder::State {
  GeometryCodecHeader header;
  GeometryDecodeOptions options;
  Ownership own;
  FrameField ff;
  BitplaneDecoder bits;
  BitplaneDecodeResult last;
  // result() cache: the grids of the last call, valid while the coefficients and the drop are the same.
  std::vector<std::uint64_t> versions;
  int cached_drop = -1;
  DecodedGeometry cached;
  std::vector<PatchCoefficients> scratch;  // coefficients of the last result()
};

GeometryDecoder::GeometryDecoder() = default;
GeometryDecoder::~GeometryDecoder() = default;
GeometryDecoder::GeometryDecoder(GeometryDecoder&&) noexcept = default;
GeometryDecoder& GeometryDecoder::operator=(GeometryDecoder&&) noexcept = default;

Status GeometryDecoder::reset(const GeometryCodecHeader& header, const GeometryDecodeOptions& options) {
  s_.reset();
  if (!header_ok(header) || options.drop_finest_steps < 0) return Status::kInvalidArgument;
  auto st = std::make_unique<State>();
  st->header = header;
  st->options = options;
  st->own = seam_ownership(header.level, header.num_patches, header.seams);
  st->ff = make_frame_field(header, st->own);
  st->ff.max_threads = options.max_threads;
  State* raw = st.get();
  const DecodeHook hook = [raw](int plane, std::vector<PatchCoefficients>& view) {
    raw->ff.compute(plane, view);
  };
  const HookViewShift shift = [raw](int plane) { return raw->ff.view_shift(plane); };
  const Status s = st->bits.reset(make_layout(header), header.top_bitplane, st->own.coded,
                                  options.max_threads, hook, shift);
  if (s != Status::kOk) return s;
  s_ = std::move(st);
  return Status::kOk;
}

Status GeometryDecoder::update(std::span<const std::span<const std::uint8_t>> segments,
                               std::span<const std::uint8_t> partial_tail) {
  if (!s_) return Status::kInvalidArgument;
  return s_->bits.update(segments, partial_tail, s_->last);
}

void GeometryDecoder::result(DecodedGeometry& out, int drop_finest_steps) {
  out = DecodedGeometry{};
  if (!s_) return;
  build_result(drop_finest_steps);
  out = s_->cached;
}

void GeometryDecoder::take_result(DecodedGeometry& out, int drop_finest_steps) {
  out = DecodedGeometry{};
  if (!s_) return;
  build_result(drop_finest_steps);
  out = std::move(s_->cached);
  s_->cached = DecodedGeometry{};
  s_->cached_drop = -1;  // the cache is gone: the next result() reconstructs
}

void GeometryDecoder::build_result(int drop_finest_steps) {
  State& st = *s_;
  const GeometryCodecHeader& header = st.header;
  const int level = header.level, np = header.num_patches, steps = header.steps;
  const std::size_t size = static_cast<std::size_t>(grid_size(level)), samples = size * size;
  const int drop = std::min(drop_finest_steps < 0 ? st.options.drop_finest_steps : drop_finest_steps, steps);
  std::vector<std::uint64_t> versions = st.bits.patch_versions();
  if (versions == st.versions && drop == st.cached_drop) return;
  std::vector<PatchCoefficients>& coefs = st.scratch;  // reused: no allocation per call
  st.bits.reconstruct(coefs);
  const Ownership& own = st.own;
  // The grids are built in the cache (its buffers are reused from call to call), then copied out.
  DecodedGeometry& res = st.cached;
  st.cached_drop = -1;  // invalid until complete
  res.segments_complete = st.last.segments_complete;
  res.partial = st.last.partial;
  st.ff.to_xyz(coefs);
  for (const auto& [copy, owner] : own.copies) {
    for (int c = 0; c < 3; ++c)
      coefs[copy / samples][c][copy % samples] = coefs[owner / samples][c][owner % samples];
  }
  // Per patch (in parallel): drop the finest details, find the finest step with a non-zero detail, inverse
  // transform, dequantize.
  std::vector<int> finest(static_cast<std::size_t>(np), steps + 1);  // steps + 1: none
  res.patches.resize(static_cast<std::size_t>(np));
  parallel_for(np, st.options.max_threads, [&](int p) {
    Grid3& g = res.patches[static_cast<std::size_t>(p)];
    g.level = level;
    g.values.resize(3 * samples);
    for (int c = 0; c < 3; ++c) {
      auto& ch = coefs[static_cast<std::size_t>(p)][static_cast<std::size_t>(c)];
      int& f = finest[static_cast<std::size_t>(p)];
      if (drop == 0) {
        // Only the finest non-zero step is needed: scan the steps from the finest, stop at the first hit.
        for (int k = 1; k < f; ++k) {
          const std::size_t sk = std::size_t{1} << (k - 1);
          bool hit = false;
          for (std::size_t j = 0; j < size && !hit; j += sk) {
            const bool odd_row = (j / sk) & 1;
            for (std::size_t i = odd_row ? 0 : sk; i < size; i += odd_row ? sk : 2 * sk) {
              if (ch[j * size + i] != 0) {
                hit = true;
                break;
              }
            }
          }
          if (hit) f = k;
        }
      } else {
        for (std::size_t j = 0; j < size; ++j) {
          for (std::size_t i = 0; i < size; ++i) {
            std::int32_t& v = ch[j * size + i];
            if (v == 0) continue;
            // The step that introduced (i, j): 1 + trailing zeros of i | j; beyond `steps`: the coarse band.
            const unsigned both = static_cast<unsigned>(i | j);
            const int k = both == 0 ? steps + 1 : std::min(std::countr_zero(both) + 1, steps + 1);
            if (k > steps) continue;
            if (k <= drop) {
              v = 0;
            } else {
              f = std::min(f, k);
            }
          }
        }
      }
      wavelet_inverse(ch, level, steps, header.filter, header.lifting_update);
    }
    // Dequantize, the three channels of a sample together (contiguous stores).
    const auto& pc = coefs[static_cast<std::size_t>(p)];
    const std::int32_t *x = pc[0].data(), *y = pc[1].data(), *z = pc[2].data();
    const double ox = header.origin[0], oy = header.origin[1], oz = header.origin[2], step = header.step;
    float* v = g.values.data();
    constexpr double kMaxFloat = std::numeric_limits<float>::max();
    if (std::max({std::abs(ox), std::abs(oy), std::abs(oz)}) + step * 0x1p31 < 0.5 * kMaxFloat) {
      // Every int32 lands well inside the float range (any real pack), where to_float() is the plain
      // conversion: without its branches the loop vectorizes.
      for (std::size_t i = 0; i < samples; ++i) {
        v[3 * i] = static_cast<float>(ox + step * static_cast<double>(x[i]));
        v[3 * i + 1] = static_cast<float>(oy + step * static_cast<double>(y[i]));
        v[3 * i + 2] = static_cast<float>(oz + step * static_cast<double>(z[i]));
      }
    } else {
      for (std::size_t i = 0; i < samples; ++i) {
        v[3 * i] = to_float(ox + step * static_cast<double>(x[i]));
        v[3 * i + 1] = to_float(oy + step * static_cast<double>(y[i]));
        v[3 * i + 2] = to_float(oz + step * static_cast<double>(z[i]));
      }
    }
  });
  const int finest_step = *std::min_element(finest.begin(), finest.end());
  res.detail_level = finest_step > steps ? level - steps : level - finest_step + 1;
  st.versions = std::move(versions);
  st.cached_drop = drop;
}

void copy_seam_samples(std::vector<Grid3>& patches, const std::vector<PatchSeam>& seams) {
  if (patches.empty() || seams.empty()) return;
  const int level = patches[0].level;
  const std::size_t samples = static_cast<std::size_t>(grid_size(level)) * grid_size(level);
  for (const Grid3& g : patches) {
    if (g.level != level || g.values.size() != 3 * samples) return;
  }
  for (const PatchSeam& seam : seams) {
    const int np = static_cast<int>(patches.size());
    if (seam.patch < 0 || seam.patch >= np || seam.other_patch < 0 || seam.other_patch >= np ||
        seam.side < 0 || seam.side > 3 || seam.other_side < 0 || seam.other_side > 3)
      return;
  }
  const Ownership own = seam_ownership(level, static_cast<int>(patches.size()), seams);
  for (const auto& [copy, owner] : own.copies) {
    const float* from = patches[owner / samples].values.data() + 3 * (owner % samples);
    float* to = patches[copy / samples].values.data() + 3 * (copy % samples);
    to[0] = from[0], to[1] = from[1], to[2] = from[2];
  }
}

Status decode_geometry(const GeometryCodecHeader& header,
                       std::span<const std::span<const std::uint8_t>> segments,
                       std::span<const std::uint8_t> partial_tail, DecodedGeometry& out,
                       const GeometryDecodeOptions& options) {
  out = DecodedGeometry{};
  GeometryDecoder decoder;
  if (decoder.reset(header, options) != Status::kOk) return Status::kInvalidArgument;
  const Status status = decoder.update(segments, partial_tail);
  decoder.take_result(out);
  return status;
}

}  // namespace geomip::codec
