// Binary adaptive arithmetic coder: an LZMA-style range coder (32-bit low/range, carry propagation through a
// cached byte and a run of 0xFF bytes, byte-wise output; Martin 1979 "Range encoding", Pavlov's LZMA rc) with
// adaptive probability models.
//
// Model: each Context holds two estimates of P(bit = 0) in 16-bit fixed point, one adapting fast (shift 5)
// and one slowly (shift 8); the coder uses their average (two-rate mixing, as in e.g. the AV1/Daala
// multi-speed counters). During the first updates the shifts are smaller (1, 2, 3, ...), so a fresh context
// learns its skew in a handful of symbols (a cheap approximation of a count-based estimate).
//
// Streams: the encoder's finish() flushes minimally: it picks, inside the final interval, the value with the
// most trailing zero bits and drops trailing zero bytes, because the decoder reads zero bytes past the end of
// its span. The decoder never reads outside its span and records in exhausted() that it needed a byte beyond
// it. Prefix property: every symbol decoded while exhausted() is still false is exactly the symbol that was
// encoded, whatever bytes follow in the real stream; so a decoder given a byte prefix of a stream decodes a
// correct prefix of the symbols, as long as it stops at the first symbol where exhausted() is true. A
// complete stream, on the other hand, decodes every symbol the encoder wrote even though the decoder may read
// (zero) bytes beyond its end near the last symbols.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace geomip::codec {

/// An adaptive binary probability model (the "context" of a symbol). Start each context in its default
/// state (P(0) = 1/2) in both the encoder and the decoder.
struct Context {
  std::uint16_t fast = 1u << 15;  ///< P(bit = 0) · 2^16, fast-adapting estimate
  std::uint16_t slow = 1u << 15;  ///< P(bit = 0) · 2^16, slow-adapting estimate
  std::uint8_t count = 0;         ///< updates seen, saturating (drives the warm-up shifts)

  /// P(bit = 0) · 2^16 in [1, 65535].
  std::uint32_t p0() const { return (static_cast<std::uint32_t>(fast) + slow) >> 1; }
  [[gnu::always_inline]] void update(int bit) {
    if (count < 7) [[unlikely]] {
      warm_up(bit);
      return;
    }
    // Warmed up (all but a context's first 7 updates): shifts 5 and 8. Written as selects rather than
    // branches: refinement bits are close to random, and a mispredicted branch per symbol would dominate the
    // decoder's time. The results stay in [1, 65535]: x − (x >> s) ≥ 1 for x ≥ 1 (s ≥ 1), and
    // x + ((65535 − x) >> s) ≤ 65535.
    const int f = fast, s = slow;
    fast = static_cast<std::uint16_t>(bit ? f - (f >> 5) : f + ((65535 - f) >> 5));
    slow = static_cast<std::uint16_t>(bit ? s - (s >> 8) : s + ((65535 - s) >> 8));
  }

 private:
  // Warm-up shifts: fast 1, 2, 3, 4, 5, 5, ...; slow 1, 2, ..., 8, 8, ... (count saturates at 7). Out of
  // line: the hot loops that inline update() keep only the warmed-up path.
  [[gnu::noinline]] void warm_up(int bit) {
    const int ss = count + 1, fs = ss < 5 ? ss : 5;
    ++count;
    const int f = fast, s = slow;
    const int f1 = f - (f >> fs), f0 = f + ((65535 - f) >> fs);
    const int s1 = s - (s >> ss), s0 = s + ((65535 - s) >> ss);
    fast = static_cast<std::uint16_t>(bit ? f1 : f0);
    slow = static_cast<std::uint16_t>(bit ? s1 : s0);
  }
};

/// Encoder: feed symbols, then finish() once to get the bytes.
class ArithmeticEncoder {
 public:
  /// Codes `bit` (0 or 1) with the probability of `context`, then adapts the context.
  void encode(int bit, Context& context) {
    const std::uint32_t bound = (range_ >> 16) * context.p0();
    if (bit == 0) {
      range_ = bound;
    } else {
      low_ += bound;
      range_ -= bound;
    }
    context.update(bit);
    while (range_ < kTop) {
      range_ <<= 8;
      shift_low();
    }
  }
  /// Codes `bit` with probability 1/2 (no context): signs, nearly uniform raw bits.
  void encode_bypass(int bit) {
    range_ >>= 1;
    if (bit) low_ += range_;
    while (range_ < kTop) {
      range_ <<= 8;
      shift_low();
    }
  }
  /// Flushes (minimally, see the file comment) and returns the stream. The encoder is then spent.
  std::vector<std::uint8_t> finish();

  /// Bytes output so far (without the pending flush): for size estimates.
  std::size_t bytes_so_far() const { return out_.size() + pending_; }

 private:
  static constexpr std::uint32_t kTop = 1u << 24;
  void shift_low();

  std::uint64_t low_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
  std::uint8_t cache_ = 0;
  std::size_t pending_ = 1;  ///< bytes held back: the cache byte plus a run of 0xFF awaiting a possible carry
  bool first_ = true;        ///< the very first cache byte is always 0 and is not written
  std::vector<std::uint8_t> out_;
};

/// Decoder over one stream. Reads zero bytes past the end of `bytes` (never outside the span) and then
/// reports exhausted().
class ArithmeticDecoder {
 public:
  explicit ArithmeticDecoder(std::span<const std::uint8_t> bytes) : bytes_(bytes) {
    for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | next_byte();
  }
  // Always inlined: the bit-plane decoder's loops keep the decoder's state in registers only when it is.
  [[gnu::always_inline]] int decode(Context& context) {
    const std::uint32_t bound = (range_ >> 16) * context.p0();
    const int bit = code_ >= bound;
    const std::uint32_t mask = 0u - static_cast<std::uint32_t>(bit);
    code_ -= bound & mask;
    range_ = bit ? range_ - bound : bound;
    context.update(bit);
    if (range_ < kTop) normalize();
    return bit;
  }
  [[gnu::always_inline]] int decode_bypass() {
    range_ >>= 1;
    const int bit = code_ >= range_;
    code_ -= range_ & (0u - static_cast<std::uint32_t>(bit));
    if (range_ < kTop) normalize();
    return bit;
  }
  /// True once the decoder has needed a byte beyond the end of its span. Symbols decoded while this was
  /// false are the encoded ones (prefix property, see the file comment).
  bool exhausted() const { return exhausted_; }
  /// Bytes of the span consumed so far.
  std::size_t position() const { return pos_; }

  /// Continues over `bytes`, a longer (or equal) prefix of the same stream than the span so far (it may live
  /// elsewhere in memory: only its contents must extend the old ones). The zero bytes that stood in for the
  /// missing ones are replaced by the real ones that have now arrived, so a decoder that stopped at the first
  /// symbol after exhausted() became true continues exactly as if it had had all the bytes from the start
  /// (incremental decoding). Call it only while the decoder stopped there (no symbol decoded while
  /// exhausted()).
  void extend(std::span<const std::uint8_t> bytes) {
    bytes_ = bytes;
    // The missing_ zero bytes sit in the low bytes of code_, the first missing one highest.
    while (missing_ > 0 && pos_ < bytes_.size()) {
      --missing_;
      code_ += static_cast<std::uint32_t>(bytes_[pos_++]) << (8 * missing_);
    }
    exhausted_ = missing_ > 0;
  }

 private:
  static constexpr std::uint32_t kTop = 1u << 24;
  void normalize() {
    do {
      range_ <<= 8;
      code_ = (code_ << 8) | next_byte();
    } while (range_ < kTop);
  }
  std::uint32_t next_byte() {
    if (pos_ < bytes_.size()) return bytes_[pos_++];
    exhausted_ = true;
    ++missing_;  // only meaningful (≤ 4) while the caller stops at exhaustion; see extend()
    return 0;
  }

  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
  std::uint32_t code_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
  std::uint32_t missing_ = 0;  ///< zero bytes read past the span since it was last extended
  bool exhausted_ = false;
};

}  // namespace geomip::codec
