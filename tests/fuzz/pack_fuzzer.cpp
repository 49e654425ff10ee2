// libFuzzer target for the .gip pack decoder: any bytes, whole or as a prefix, must give a Status, never a crash,
// hang, leak or undefined behaviour (run under ASan + UBSan). Built with CRC checks disabled
// (GEOMIP_FUZZING_NO_CRC) so that mutated manifests and chunks reach the parsers behind the checksums.
#include "codec/pack.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  geomip::codec::decode_pack(bytes);
  // A prefix, as a streaming client sees it, and the other decode options.
  geomip::codec::decode_pack(bytes, {.max_bytes = size / 2, .normals = false, .partial_chunks = true,
                                     .drop_finest_steps = 1});
  geomip::codec::decode_pack(bytes, {.max_bytes = size - size / 8, .partial_chunks = false});
  return 0;
}
