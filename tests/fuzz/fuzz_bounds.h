// The pack fuzzers' bound on work per input (harness-side, not codec-side): the samples a pack's manifest
// announces, so a mutated level byte cannot make one input cost seconds. Shared by pack_fuzzer.cpp and
// viewer_fuzzer.cpp.
#pragma once

#include "codec/pack.h"

#include <cstdint>

namespace geomip::fuzz {

/// Samples of the grids the manifest announces (geometry, normal maps and their second layer, hole masks),
/// saturating at 2^40.
inline std::uint64_t announced_samples(const codec::PackInfo& info) {
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
    if (m.normal_layers == 2) total += patches * grid(m.normal_residual.level);  // format 11's layer 2
    total += patches * grid(m.fine_hole_mask_level);
    if (total > kCap) return kCap;
  }
  return total;
}

/// About 2 ms of decoding under ASan: every seed (tests/fuzz/seeds/pack/: cubes at levels 1 to 3, with and
/// without normal maps, an open cube with its hole mask, two models) fits; a mutated level byte does not.
inline constexpr std::uint64_t kMaxSamples = 2'500;

}  // namespace geomip::fuzz
