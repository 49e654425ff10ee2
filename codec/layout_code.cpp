#include "codec/layout_code.h"

#include <bit>
#include <tuple>
#include <utility>

namespace geomip::codec {
namespace {

enum class Step { kF, kR, kL, kS };

// The traversal's state, shared by the encoder and the decoder: sides are 4·patch + side in canonical
// numbering; next/prev link the open sides of the current cycle (and of the stacked ones).
class Traversal {
 public:
  explicit Traversal(int num_patches)
      : patches_(num_patches),
        next_(4 * static_cast<std::size_t>(num_patches)),
        prev_(next_.size()),
        partner_(next_.size(), -1) {
    for (int s = 0; s < 4; ++s) next_[s] = (s + 1) % 4, prev_[s] = (s + 3) % 4;
  }

  int gate() const { return gate_; }
  int length() const { return length_; }
  bool done() const { return done_; }
  int visited() const { return visited_; }
  int next(int side) const { return next_[static_cast<std::size_t>(side)]; }
  int prev(int side) const { return prev_[static_cast<std::size_t>(side)]; }
  const std::vector<int>& partners() const { return partner_; }

  /// The side `k` places ahead of the gate, or -1 when the walks would exceed kMaxLayoutWalk.
  int ahead(int k) {
    walked_ += static_cast<std::size_t>(k);
    if (walked_ > kMaxLayoutWalk) return -1;
    int side = gate_;
    for (int i = 0; i < k; ++i) side = next(side);
    return side;
  }

  /// Applies one step (for S: the side it glues to, k places ahead, k odd in [3, length − 3]); false when
  /// the step is not possible in this state.
  bool apply(Step step, int k = 0) {
    if (done_) return false;
    const int g = gate_;
    switch (step) {
      case Step::kF: {
        if (visited_ >= patches_) return false;
        const int f = 4 * visited_++;
        const int a = prev(g), b = next(g);
        link(g, f);
        chain(a, f + 1), chain(f + 1, f + 2), chain(f + 2, f + 3), chain(f + 3, b);
        length_ += 2;
        gate_ = f + 3;
        return true;
      }
      case Step::kR:
      case Step::kL: {
        if (length_ == 2) {
          if (step == Step::kL) return false;  // a closing pair is always R
          link(g, next(g));
          return pop();
        }
        const int q = step == Step::kR ? next(g) : prev(g);
        const int a = step == Step::kR ? prev(g) : prev(q), b = step == Step::kR ? next(q) : next(g);
        link(g, q);
        chain(a, b);
        length_ -= 2;
        gate_ = step == Step::kR ? a : b;  // the other end of the closed corner
        return true;
      }
      case Step::kS: {
        if (k < 3 || k % 2 == 0 || k > length_ - 3) return false;
        const int q = ahead(k);
        if (q < 0) return false;
        const int n1 = next(g), p1 = prev(q), n2 = next(q), p2 = prev(g);
        link(g, q);
        chain(p1, n1), chain(p2, n2);
        stack_.emplace_back(n2, length_ - k - 1);
        gate_ = n1;
        length_ = k - 1;
        return true;
      }
    }
    return false;
  }

 private:
  void link(int a, int b) {
    partner_[static_cast<std::size_t>(a)] = b;
    partner_[static_cast<std::size_t>(b)] = a;
  }
  void chain(int a, int b) {
    next_[static_cast<std::size_t>(a)] = b;
    prev_[static_cast<std::size_t>(b)] = a;
  }
  bool pop() {
    if (stack_.empty()) {
      done_ = true;
      return true;
    }
    std::tie(gate_, length_) = stack_.back();
    stack_.pop_back();
    return true;
  }

  int patches_;
  std::vector<int> next_, prev_, partner_;
  std::vector<std::pair<int, int>> stack_;
  int gate_ = 3;  // patch 0's side 3: a two-square layout glues it to side 0 of patch 1 (no turn)
  int length_ = 4;
  int visited_ = 1;
  std::size_t walked_ = 0;
  bool done_ = false;
};

class BitWriter {
 public:
  void put(bool bit) {
    if (filled_ == 0) bytes_.push_back(0);
    if (bit) bytes_.back() = static_cast<std::uint8_t>(bytes_.back() | 1u << filled_);
    filled_ = (filled_ + 1) % 8;
  }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
  int filled_ = 0;
};

class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool get(bool& bit) {
    if (pos_ / 8 >= bytes_.size()) return false;
    bit = (bytes_[pos_ / 8] >> (pos_ % 8) & 1) != 0;
    ++pos_;
    return true;
  }
  std::size_t bytes_used() const { return (pos_ + 7) / 8; }
  bool padding_zero() const { return pos_ % 8 == 0 || (bytes_[pos_ / 8] >> (pos_ % 8)) == 0; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

void put_step(BitWriter& w, Step step, int k) {
  switch (step) {
    case Step::kF:
      w.put(false);
      return;
    case Step::kR:
      w.put(true), w.put(false);
      return;
    case Step::kL:
      w.put(true), w.put(true), w.put(false);
      return;
    case Step::kS: {
      w.put(true), w.put(true), w.put(true);
      const unsigned v = static_cast<unsigned>(k - 1) / 2;  // k odd ≥ 3: v ≥ 1
      const int width = std::bit_width(v);
      for (int i = 1; i < width; ++i) w.put(false);
      for (int i = width - 1; i >= 0; --i) w.put((v >> i & 1) != 0);
      return;
    }
  }
}

bool get_step(BitReader& r, Step& step, int& k) {
  bool bit;
  int ones = 0;
  while (ones < 3) {
    if (!r.get(bit)) return false;
    if (!bit) break;
    ++ones;
  }
  step = ones == 0 ? Step::kF : ones == 1 ? Step::kR : ones == 2 ? Step::kL : Step::kS;
  if (step != Step::kS) return true;
  int zeros = 0;
  for (;;) {
    if (!r.get(bit)) return false;
    if (bit) break;
    if (++zeros > 30) return false;
  }
  unsigned v = 1;
  for (int i = 0; i < zeros; ++i) {
    if (!r.get(bit)) return false;
    v = v << 1 | (bit ? 1u : 0u);
  }
  k = static_cast<int>(2 * v + 1);
  return true;
}

bool is_closed_oriented_table(const std::vector<PatchSeam>& seams, int num_patches) {
  if (num_patches < 1 || seams.size() != 4 * static_cast<std::size_t>(num_patches)) return false;
  for (std::size_t i = 0; i < seams.size(); ++i) {
    const PatchSeam& s = seams[i];
    if (s.patch != static_cast<int>(i / 4) || s.side != static_cast<int>(i % 4) || s.other_patch < 0 ||
        s.other_patch >= num_patches || s.other_side < 0 || s.other_side > 3 || !s.reversed)
      return false;
    const std::size_t j =
        4 * static_cast<std::size_t>(s.other_patch) + static_cast<std::size_t>(s.other_side);
    const PatchSeam& o = seams[j];
    if (j == i || o.other_patch != s.patch || o.other_side != s.side || !o.reversed) return false;
  }
  return true;
}

}  // namespace

bool LayoutOrder::identity() const {
  for (std::size_t c = 0; c < patch.size(); ++c)
    if (patch[c] != static_cast<int>(c) || rotation[c] != 0) return false;
  return true;
}

std::optional<LayoutOrder> layout_order(const std::vector<PatchSeam>& seams, int num_patches) {
  if (!is_closed_oriented_table(seams, num_patches)) return std::nullopt;
  LayoutOrder order;
  order.patch.push_back(0);
  order.rotation.push_back(0);
  std::vector<int> canonical(static_cast<std::size_t>(num_patches), -1);
  canonical[0] = 0;
  Traversal t(num_patches);
  BitWriter w;
  // The gate's partner in canonical numbering, or -1 when it lies on a patch not visited yet (its input
  // patch and side in `patch`, `side`).
  const auto partner = [&](int side, int& patch, int& other_side) {
    const int c = side / 4;
    const int input_side = (side % 4 + order.rotation[static_cast<std::size_t>(c)]) % 4;
    const PatchSeam& s = seams[4 * static_cast<std::size_t>(order.patch[static_cast<std::size_t>(c)]) +
                               static_cast<std::size_t>(input_side)];
    patch = s.other_patch, other_side = s.other_side;
    const int q = canonical[static_cast<std::size_t>(patch)];
    if (q < 0) return -1;
    return 4 * q + (other_side - order.rotation[static_cast<std::size_t>(q)] + 4) % 4;
  };
  std::size_t steps = 0;
  while (!t.done()) {
    if (++steps > 2 * static_cast<std::size_t>(num_patches) + 1) return std::nullopt;
    const int g = t.gate();
    int patch = 0, other_side = 0;
    const int y = partner(g, patch, other_side);
    Step step = Step::kF;
    int k = 0;
    if (y < 0) {
      canonical[static_cast<std::size_t>(patch)] = static_cast<int>(order.patch.size());
      order.patch.push_back(patch);
      order.rotation.push_back(other_side);
    } else if (y == t.next(g)) {
      step = Step::kR;
    } else if (y == t.prev(g)) {
      step = Step::kL;
    } else {
      step = Step::kS;
      int side = t.next(g);
      for (k = 1; k < t.length() && side != y; ++k) side = t.next(side);
      if (side != y) return std::nullopt;  // on another cycle: a handle (genus > 0)
    }
    if (!t.apply(step, k)) return std::nullopt;
    put_step(w, step, k);
  }
  if (t.visited() != num_patches) return std::nullopt;  // more than one connected layout
  order.code = w.take();
  return order;
}

bool read_layout_code(std::span<const std::uint8_t> bytes, int num_patches, std::vector<PatchSeam>& seams,
                      std::size_t& used) {
  if (num_patches < 1 || static_cast<std::uint64_t>(num_patches - 1) > 8 * std::uint64_t{bytes.size()})
    return false;
  Traversal t(num_patches);
  BitReader r(bytes);
  std::size_t steps = 0;
  while (!t.done()) {
    if (++steps > 2 * static_cast<std::size_t>(num_patches) + 1) return false;
    Step step;
    int k = 0;
    if (!get_step(r, step, k) || !t.apply(step, k)) return false;
  }
  if (t.visited() != num_patches || !r.padding_zero()) return false;
  seams.resize(4 * static_cast<std::size_t>(num_patches));
  const std::vector<int>& partner = t.partners();
  for (std::size_t i = 0; i < seams.size(); ++i) {
    const int o = partner[i];
    if (o < 0) return false;
    seams[i] = {static_cast<int>(i / 4), static_cast<int>(i % 4), o / 4, o % 4, true};
  }
  used = r.bytes_used();
  return true;
}

namespace {

/// An n × n row-major array of `channels`-value cells turned as rotate_grid() says, in one pass: a turn maps
/// cell (i, j) to (n − 1 − j, i), which carries side s of a grid to side s + 1; side s + rotation must become
/// side s, so a cell takes (4 − rotation) mod 4 turns.
template <typename T>
void turn_cells(const std::vector<T>& in, std::vector<T>& out, int n, int channels, int rotation) {
  const int turns = (4 - rotation % 4) % 4;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      int ti = i, tj = j;
      for (int t = 0; t < turns; ++t) std::tie(ti, tj) = std::pair(n - 1 - tj, ti);
      const auto from = static_cast<std::size_t>(channels) * (static_cast<std::size_t>(j) * n + i);
      const auto to = static_cast<std::size_t>(channels) * (static_cast<std::size_t>(tj) * n + ti);
      for (int c = 0; c < channels; ++c) out[to + c] = in[from + c];
    }
  }
}

}  // namespace

Grid3 rotate_grid(const Grid3& grid, int rotation) {
  Grid3 out = grid;
  turn_cells(grid.values, out.values, grid.size(), 3, rotation);
  return out;
}

std::vector<std::uint8_t> rotate_quad_mask(const std::vector<std::uint8_t>& mask, int rotation) {
  std::vector<std::uint8_t> out = mask;
  int m = 0;
  while (static_cast<std::size_t>(m) * static_cast<std::size_t>(m) < mask.size()) ++m;
  if (static_cast<std::size_t>(m) * static_cast<std::size_t>(m) == mask.size())
    turn_cells(mask, out, m, 1, rotation);
  return out;
}

}  // namespace geomip::codec
