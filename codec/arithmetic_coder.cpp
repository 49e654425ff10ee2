#include "codec/arithmetic_coder.h"

namespace geomip::codec {

void ArithmeticEncoder::shift_low() {
  // The byte at bits 24..31 of low_ is final unless a later carry can still reach it: it is held in cache_
  // (followed by pending_ − 1 bytes of 0xFF) until a byte below 0xFF, or a carry, settles it.
  if (static_cast<std::uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
    const auto carry = static_cast<std::uint8_t>(low_ >> 32);
    std::uint8_t byte = cache_;
    do {
      if (first_) {
        first_ = false;  // the leading byte of the code value is always 0 (the value lies in [0, 1))
      } else {
        out_.push_back(static_cast<std::uint8_t>(byte + carry));
      }
      byte = 0xFF;
    } while (--pending_ != 0);
    cache_ = static_cast<std::uint8_t>(static_cast<std::uint32_t>(low_) >> 24);
  }
  ++pending_;
  low_ = (low_ & 0x00FFFFFFu) << 8;
}

std::vector<std::uint8_t> ArithmeticEncoder::finish() {
  // Any value in [low, low + range) identifies the symbols; the decoder pads with zero bytes, so pick the
  // one with the most trailing zero bits and drop the zero bytes it ends with.
  const std::uint64_t hi = low_ + range_;  // exclusive
  for (int b = 32; b >= 0; --b) {
    const std::uint64_t mask = (std::uint64_t{1} << b) - 1;
    const std::uint64_t v = (low_ + mask) & ~mask;
    if (v < hi) {
      low_ = v;
      break;
    }
  }
  for (int i = 0; i < 5; ++i) shift_low();
  while (!out_.empty() && out_.back() == 0) out_.pop_back();
  return std::move(out_);
}

}  // namespace geomip::codec
