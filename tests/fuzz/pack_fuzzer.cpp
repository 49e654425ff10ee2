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
#include "tests/fuzz/fuzz_bounds.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace {

using geomip::fuzz::announced_samples;
using geomip::fuzz::kMaxSamples;

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
  // only; the whole pack fed to the incremental decoder in increments of 1 to 64 bytes (the first byte
  // decides), as the viewer feeds it. One thread: starting a thread per patch and input would cost more than
  // the decoding.
  switch (size % 4) {
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
    case 2:
      geomip::codec::decode_pack(bytes,
                                 {.max_bytes = size - size / 8, .partial_chunks = false, .max_threads = 1});
      break;
    default: {
      geomip::codec::PackDecoder decoder({.max_threads = 1});
      const std::size_t step = 1 + (size > 0 ? data[0] % 64 : 0);
      for (std::size_t n = 0; n < size; n = std::min(size, n + step)) decoder.update(bytes.first(n));
      decoder.update(bytes);
      decoder.result();
      break;
    }
  }
  return 0;
}
