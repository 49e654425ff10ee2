// libFuzzer target for the .gip pack decoder: any bytes, whole or as a prefix, must give a Status, never a
// crash, hang, leak or undefined behaviour (run under ASan + UBSan). Built with CRC checks disabled
// (GEOMIP_FUZZING_NO_CRC) so that mutated manifests and chunks reach the parsers behind the checksums.
//
// Bounded work per input: a manifest that parses but describes grids larger than kMaxSamples (a mutated level
// byte turns a level-5 pillow into 4097² samples per patch) is not decoded. The decoder's limits for such
// packs (kMaxPackLevel, allocation failures mapped to kCorrupt) are the unit tests' business; spending the
// fuzzer's time on them would leave it at ~25 inputs/s instead of a thousand and more. The check is here, in
// the harness: it reads the same manifest the decoder reads, with read_pack_info(), and changes nothing in
// codec/.
#include "codec/pack.h"

#include <cstddef>
#include <cstdint>

namespace {

// Samples of the grids a pack's manifest announces (geometry, normal maps, hole masks), saturating.
std::uint64_t announced_samples(const geomip::codec::PackInfo& info) {
  constexpr std::uint64_t kCap = std::uint64_t{1} << 40;
  auto grid = [](int level) {
    if (level < 0 || level > 16) return kCap;
    const std::uint64_t side = (std::uint64_t{1} << level) + 1;
    return side * side;
  };
  std::uint64_t total = 0;
  for (const auto& m : info.models) {
    const auto patches = static_cast<std::uint64_t>(m.geometry.num_patches < 0 ? 0 : m.geometry.num_patches);
    total += patches * grid(m.geometry.level);
    if (m.has_normals) total += patches * grid(m.normals.level);
    total += patches * grid(m.fine_hole_mask_level);
    if (total > kCap) return kCap;
  }
  return total;
}

// About 2 ms of decoding under ASan: every seed (tests/fuzz/seeds/pack/: cubes at levels 1 to 3, with and
// without normal maps, an open cube with its hole mask, two models) fits; a mutated level byte does not.
constexpr std::uint64_t kMaxSamples = 2'500;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  geomip::codec::PackInfo info;
  if (geomip::codec::read_pack_info(bytes, info) == geomip::codec::Status::kOk &&
      announced_samples(info) > kMaxSamples) {
    return -1;  // not added to the corpus
  }
  // One decode per input, its options chosen by the input's length: the whole pack; a prefix as a streaming
  // client sees it (partial chunks, no normals, the finest step dropped); a longer prefix of whole chunks
  // only. One thread: starting a thread per patch and input would cost more than the decoding.
  switch (size % 3) {
    case 0:
      geomip::codec::decode_pack(bytes, {.max_threads = 1});
      break;
    case 1:
      geomip::codec::decode_pack(bytes, {.max_bytes = size / 2,
                                         .normals = false,
                                         .partial_chunks = true,
                                         .drop_finest_steps = 1,
                                         .max_threads = 1});
      break;
    default:
      geomip::codec::decode_pack(bytes,
                                 {.max_bytes = size - size / 8, .partial_chunks = false, .max_threads = 1});
      break;
  }
  return 0;
}
