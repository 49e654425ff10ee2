// zlib's crc32() for the WASM build (see zlib/zlib.h): table-driven CRC-32/IEEE; crc32(0, nullptr, 0) = 0 and
// crc32(crc32(0, a), b) = crc32(0, a‖b), as zlib's.
#include "zlib.h"

#include <array>
#include <cstdint>

namespace {

constexpr std::array<std::uint32_t, 256> make_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr auto kTable = make_table();

}  // namespace

extern "C" uLong crc32(uLong crc, const Bytef* buf, uInt len) {
  if (buf == nullptr) return 0;
  std::uint32_t c = static_cast<std::uint32_t>(crc) ^ 0xFFFFFFFFu;
  for (uInt i = 0; i < len; ++i) c = kTable[(c ^ buf[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}
