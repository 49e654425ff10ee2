// Crafted packs for the viewer's "trust nothing" tests and fuzz seeds: a valid pack whose manifest chunk
// table is rewritten (sizes, count) with a recomputed, valid manifest CRC, so the lie gets past the CRC and
// reaches the size checks. Built from codec's public reader only (codec/pack.h): the chunk table is the
// manifest's tail, varint count then per chunk a varint size (and, before format version 4, a u32 CRC).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "codec/pack.h"

namespace geomip::viewer::testing {

inline void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v) {
  do {
    const std::uint8_t b = v & 0x7f;
    v >>= 7;
    out.push_back(static_cast<std::uint8_t>(v ? b | 0x80 : b));
  } while (v);
}

inline void put_u32(std::vector<std::uint8_t>& out, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out[at + k] = static_cast<std::uint8_t>(v >> (8 * k));
}

/// `pack` with its chunk table's sizes replaced by edit(sizes) (and, if count_delta ≠ 0, its chunk count
/// field changed by that much), manifest CRC recomputed; the chunk bytes follow unchanged. Empty if `pack` is
/// not a readable pack.
inline std::vector<std::uint8_t> craft_pack(std::span<const std::uint8_t> pack,
                                            const std::function<void(std::vector<std::uint64_t>&)>& edit,
                                            std::int64_t count_delta = 0) {
  codec::PackInfo info;
  if (codec::read_pack_info(pack, info) != codec::Status::kOk) return {};
  // Versions 1–3: (varint size, u32 CRC) per chunk; version 4: varint payload sizes only (the CRCs trail
  // the chunks), and a varint manifest size in the fixed header.
  const bool v4 = info.version >= 4;
  std::vector<std::uint8_t> old_table;
  put_varint(old_table, info.chunks.size());
  for (const auto& c : info.chunks) {
    put_varint(old_table, c.payload_size());
    if (!v4) old_table.resize(old_table.size() + 4);
  }
  const std::size_t table_at = info.manifest_end - old_table.size();
  std::size_t header_size = codec::kPackHeaderSize;
  if (v4) {
    header_size = 11;
    while (pack[header_size - 1] & 0x80) ++header_size;
    header_size += 4;
  }
  std::vector<std::uint64_t> sizes;
  for (const auto& c : info.chunks) sizes.push_back(c.payload_size());
  edit(sizes);
  std::vector<std::uint8_t> manifest(pack.begin() + static_cast<std::ptrdiff_t>(header_size),
                                     pack.begin() + static_cast<std::ptrdiff_t>(table_at));
  put_varint(manifest,
             static_cast<std::uint64_t>(static_cast<std::int64_t>(info.chunks.size()) + count_delta));
  for (std::size_t c = 0; c < sizes.size(); ++c) {
    put_varint(manifest, sizes[c]);
    if (v4) continue;
    manifest.resize(manifest.size() + 4);
    put_u32(manifest, manifest.size() - 4, c < info.chunks.size() ? info.chunks[c].crc32 : 0);
  }
  std::vector<std::uint8_t> out(pack.begin(), pack.begin() + 10);  // magic and version
  if (v4) {
    put_varint(out, manifest.size());
  } else {
    out.resize(16, 0);  // flags 0, then the manifest size
    put_u32(out, 12, static_cast<std::uint32_t>(manifest.size()));
  }
  out.resize(out.size() + 4);
  put_u32(out, out.size() - 4, codec::manifest_crc(info.version, manifest));
  out.insert(out.end(), manifest.begin(), manifest.end());
  out.insert(out.end(), pack.begin() + static_cast<std::ptrdiff_t>(info.manifest_end), pack.end());
  return out;
}

}  // namespace geomip::viewer::testing
