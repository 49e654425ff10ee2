#include "stream_viewer/fetch_plan.h"

#include <algorithm>

namespace geomip::viewer {

std::string check_pack_header(std::span<const std::uint8_t> head, std::uint64_t available,
                              std::size_t& manifest_end) {
  manifest_end = 0;
  const codec::Status st = codec::read_pack_header(head, manifest_end);
  if (st != codec::Status::kOk) {
    manifest_end = 0;
    return "not a .gip pack (" + std::string(codec::status_message(st)) + ")";
  }
  // Format 4's header is shorter than the first read (codec::kPackHeaderSize bytes); every real manifest
  // reaches past it, and the fetcher's reads assume so.
  if (manifest_end < codec::kPackHeaderSize) {
    const std::size_t claimed = manifest_end;
    manifest_end = 0;
    return "not a usable .gip pack (its manifest ends at byte " + std::to_string(claimed) + ", too short to hold a model)";
  }
  if (available != kUnknownSize && manifest_end > available)
    return "truncated .gip pack (its manifest ends at byte " + std::to_string(manifest_end) +
           ", the source has " + std::to_string(available) + " bytes)";
  return {};
}

std::string plan_fetch(std::span<const std::uint8_t> head, std::uint64_t available, FetchPlan& plan) {
  plan = {};
  std::size_t manifest_end = 0;
  if (std::string e = check_pack_header(head, available, manifest_end); !e.empty()) return e;
  const codec::Status st = codec::read_pack_info(head, plan.info);
  if (st != codec::Status::kOk) {
    plan = {};
    return "not a readable .gip pack (manifest: " + std::string(codec::status_message(st)) + ")";
  }
  // Chunk sizes are < 2^31 each and there are at most a few thousand: the sum cannot overflow 64 bits.
  plan.total = std::max<std::uint64_t>(plan.info.file_size(), plan.info.manifest_end);
  if (plan.total > kMaxPackBytes) {
    const std::uint64_t claimed = plan.total;
    plan = {};
    return "not a usable .gip pack (its manifest lays out " + std::to_string(claimed) +
           " bytes, over the viewer's limit of " + std::to_string(kMaxPackBytes) + ")";
  }
  plan.buffer = std::min(plan.total, available);
  return {};
}

}  // namespace geomip::viewer
