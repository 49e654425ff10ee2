// libFuzzer target for geomip-view's fetch + decode path without a window or a network: the checks the
// fetcher makes before it allocates (stream_viewer/fetch_plan.cpp: the header, the manifest, its chunk table
// against the source's real size and the kMaxPackBytes cap), then what PackSource decodes — the prefix of
// complete chunks that fits in the planned buffer, with codec::decode_pack as morph::decode_scene calls it.
// libcurl and GL are not linked: the byte-level decisions are all in fetch_plan. Built with
// GEOMIP_FUZZING_NO_CRC so that mutated manifests reach the size checks behind the CRC (as a crafted pack
// with a recomputed CRC would).
//
// The source's size the fetcher is told (file size, Content-Length, Content-Range total) comes from the
// input's length: size % 4 = 0 the bytes' own size (a file), 1 unknown (HTTP without Content-Length), 2 half
// of it (a server that sends less than the manifest lays out), 3 twice it (a server claiming more than it
// has). Invariants (a violation traps): the plan never reserves more than the source's size, the cap or the
// laid-out total; its chunk table is contiguous from the manifest's end; the decoder never uses bytes past
// the prefix.
//
//   CXX=clang++ cmake -S tests/fuzz -B build-fuzz && cmake --build build-fuzz --target viewer_fuzzer
//   ./build-fuzz/viewer_fuzzer -max_len=8192 -max_total_time=60 build-fuzz/corpus-viewer
//   tests/fuzz/seeds/pack
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tests/fuzz/fuzz_bounds.h"
#include "codec/pack.h"
#include "stream_viewer/fetch_plan.h"

namespace {

using geomip::viewer::FetchPlan;

using geomip::fuzz::announced_samples;
using geomip::fuzz::kMaxSamples;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  std::uint64_t available = size;
  switch (size % 4) {
    case 1:
      available = geomip::viewer::kUnknownSize;
      break;
    case 2:
      available = size / 2;
      break;
    case 3:
      available = std::uint64_t{2} * size;
      break;
    default:
      break;
  }
  // The fetcher's order: the fixed header first (or fewer bytes when the source is that short) …
  std::size_t manifest_end = 0;
  const auto head = bytes.first(std::min(size, geomip::codec::kPackHeaderSize));
  if (!geomip::viewer::check_pack_header(head, available, manifest_end).empty()) return 0;
  check(manifest_end >= geomip::codec::kPackHeaderSize);
  check(available == geomip::viewer::kUnknownSize || manifest_end <= available);
  if (manifest_end > size) return 0;  // the connection would close inside the manifest
  // … then exactly the manifest, then the plan.
  FetchPlan plan;
  if (!geomip::viewer::plan_fetch(bytes.first(manifest_end), available, plan).empty()) {
    check(plan.buffer == 0 && plan.total == 0);
    return 0;
  }
  check(plan.buffer <= plan.total && plan.buffer <= geomip::viewer::kMaxPackBytes &&
        plan.buffer <= available);
  check(plan.buffer >= manifest_end && plan.info.manifest_end == manifest_end);
  std::uint64_t offset = manifest_end;
  for (const auto& c : plan.info.chunks) {
    check(c.offset == offset);
    offset += c.size;
  }
  check(std::max<std::uint64_t>(offset, manifest_end) == plan.total);
  if (announced_samples(plan.info) > kMaxSamples) return -1;  // not added to the corpus
  // What arrives: the planned buffer, or less when the source has fewer bytes. PackSource decodes the prefix
  // of complete chunks.
  const std::uint64_t received = std::min<std::uint64_t>(size, plan.buffer);
  std::uint64_t end = manifest_end;
  for (const auto& c : plan.info.chunks)
    if (c.offset + c.size <= received) end = c.offset + c.size;
  if (end == manifest_end) return 0;
  const auto result = geomip::codec::decode_pack(bytes.first(static_cast<std::size_t>(end)),
                                                 {.partial_chunks = false, .max_threads = 1});
  check(result.bytes_used <= end);
  return 0;
}
