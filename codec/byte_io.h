// Little-endian byte writing and bounds-checked reading for the pack manifest and codec headers.
// ByteReader never reads past its span: every read returns false (and leaves the reader failed) instead.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace geomip::codec::detail {

/// Appends `v` as unsigned LEB128 (7 bits a byte, least significant first, high bit = more follow). The
/// codec's one varint writer: the pack manifest, the codec headers and the per-patch stream sizes use it.
inline void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<std::uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<std::uint8_t>(v));
}

enum class VarintRead { kOk, kTruncated, kCorrupt };

/// Reads an unsigned LEB128 at bytes[pos…] of at most `max_bytes` bytes (≤ 10) and advances `pos` past it.
/// kTruncated when the bytes end inside it (pos unchanged); kCorrupt when it is longer than `max_bytes`,
/// overflows 64 bits or, with `canonical`, ends in a redundant zero byte. The codec's one varint reader:
/// each format states its rule (manifest: 10 bytes; codec header: 5 bytes, canonical; stream sizes: 5 bytes).
inline VarintRead read_varint(std::span<const std::uint8_t> bytes, std::size_t& pos, std::uint64_t& v,
                              int max_bytes, bool canonical) {
  v = 0;
  std::size_t p = pos;
  for (int i = 0; i < max_bytes && i < 10; ++i) {
    if (p >= bytes.size()) return VarintRead::kTruncated;
    const std::uint8_t b = bytes[p++];
    if (i == 9 && b > 1) return VarintRead::kCorrupt;  // beyond 64 bits
    v |= static_cast<std::uint64_t>(b & 0x7F) << (7 * i);
    if (!(b & 0x80)) {
      if (canonical && i > 0 && b == 0) return VarintRead::kCorrupt;
      pos = p;
      return VarintRead::kOk;
    }
  }
  return VarintRead::kCorrupt;
}

class ByteWriter {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void u16(std::uint16_t v) { fixed(v, 2); }
  void u32(std::uint32_t v) { fixed(v, 4); }
  void u64(std::uint64_t v) { fixed(v, 8); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  /// Unsigned LEB128 (put_varint).
  void varint(std::uint64_t v) { put_varint(bytes_, v); }
  void string(const std::string& s) {
    varint(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  void bytes(std::span<const std::uint8_t> b) {
    varint(b.size());
    bytes_.insert(bytes_.end(), b.begin(), b.end());
  }
  std::vector<std::uint8_t>& data() { return bytes_; }

 private:
  void fixed(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  bool u8(std::uint8_t& v) {
    std::uint64_t x;
    if (!fixed(x, 1)) return false;
    v = static_cast<std::uint8_t>(x);
    return true;
  }
  bool u16(std::uint16_t& v) {
    std::uint64_t x;
    if (!fixed(x, 2)) return false;
    v = static_cast<std::uint16_t>(x);
    return true;
  }
  bool u32(std::uint32_t& v) {
    std::uint64_t x;
    if (!fixed(x, 4)) return false;
    v = static_cast<std::uint32_t>(x);
    return true;
  }
  bool u64(std::uint64_t& v) { return fixed(v, 8); }
  bool f64(double& v) {
    std::uint64_t x;
    if (!fixed(x, 8)) return false;
    v = std::bit_cast<double>(x);
    return true;
  }
  /// Unsigned LEB128 of at most 10 bytes (read_varint); false on overflow or end of data.
  bool varint(std::uint64_t& v) {
    if (failed_) return false;
    return read_varint(bytes_, pos_, v, 10, false) == VarintRead::kOk || fail();
  }
  /// A varint that must be <= max.
  bool bounded(std::uint64_t& v, std::uint64_t max) { return varint(v) && (v <= max || fail()); }
  bool string(std::string& s, std::size_t max_size) {
    std::uint64_t n;
    if (!bounded(n, max_size) || n > remaining()) return fail();
    s.assign(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
    pos_ += n;
    return true;
  }
  bool bytes(std::vector<std::uint8_t>& b, std::size_t max_size) {
    std::uint64_t n;
    if (!bounded(n, max_size) || n > remaining()) return fail();
    b.assign(bytes_.begin() + static_cast<std::ptrdiff_t>(pos_),
             bytes_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
    return true;
  }
  /// The bytes not read yet (empty once failed).
  std::span<const std::uint8_t> rest() const {
    return failed_ ? bytes_.subspan(bytes_.size()) : bytes_.subspan(pos_);
  }
  /// Skips `n` bytes; false (and failed) when fewer are left.
  bool skip(std::size_t n) {
    if (failed_ || n > remaining()) return fail();
    pos_ += n;
    return true;
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  std::size_t position() const { return pos_; }
  bool failed() const { return failed_; }

 private:
  bool fail() {
    failed_ = true;
    return false;
  }
  bool fixed(std::uint64_t& v, int n) {
    if (failed_ || remaining() < static_cast<std::size_t>(n)) return fail();
    v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(bytes_[pos_ + i]) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return true;
  }
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

}  // namespace geomip::codec::detail
