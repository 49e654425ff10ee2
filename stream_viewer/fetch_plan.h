// What the viewer's fetch may trust of a pack before it allocates: the fixed header and the manifest (its CRC
// verified by codec::read_pack_info), checked against the real size of the source (the file's size, the HTTP
// Content-Length or the total of a Content-Range). Pure functions on bytes: no I/O, no GL, no libcurl, so the
// libFuzzer target tests/fuzz/viewer_fuzzer.cpp runs them as they are.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "codec/pack.h"

namespace geomip::viewer {

/// The most bytes the viewer ever reserves for one pack (1 GiB; the codec's own caps — 2^25 samples per pack
/// — keep real packs far below). A manifest that lays out more is refused before anything is allocated.
inline constexpr std::uint64_t kMaxPackBytes = std::uint64_t{1} << 30;
/// `available` when the source's size is not known (HTTP without Content-Length or Content-Range total).
inline constexpr std::uint64_t kUnknownSize = std::numeric_limits<std::uint64_t>::max();

struct FetchPlan {
  codec::PackInfo info;      ///< header + manifest: models and the chunk table
  std::uint64_t total = 0;   ///< bytes the manifest lays out (header + manifest + every chunk)
  std::uint64_t buffer = 0;  ///< bytes to reserve and fetch: min(total, available) ≤ kMaxPackBytes
  bool truncated() const { return buffer < total; }  ///< the source ends before the last chunk does
};

/// Checks the fixed header (`head` holds at least its first codec::kPackHeaderSize bytes, or the whole source
/// when it is shorter), that the manifest ends at or past byte codec::kPackHeaderSize (a format-4 header is
/// shorter, but no manifest that holds a model is) and that it fits in `available` bytes. Returns "" and sets `manifest_end`,
/// or one line saying why the source is not a usable pack. Never throws.
std::string check_pack_header(std::span<const std::uint8_t> head, std::uint64_t available,
                              std::size_t& manifest_end);

/// Reads header + manifest from `head` (≥ manifest_end bytes) and plans the fetch against `available`:
/// refuses a manifest that is unreadable or lays out more than kMaxPackBytes; a manifest whose chunks run
/// past the source's end is accepted with plan.buffer = available (the prefix is still a coarser level; the
/// fetch reports the truncation). Returns "" and fills `plan`, or one line. Never throws; allocates only what
/// codec::read_pack_info does (bounded by the manifest's size).
std::string plan_fetch(std::span<const std::uint8_t> head, std::uint64_t available, FetchPlan& plan);

}  // namespace geomip::viewer
