#include "tests/bench/normal_codings.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <utility>

#include "codec/parallel.h"

namespace geomip::bench {
std::size_t stream_bytes(const codec::EncodedGeometry& e) {
  std::size_t n = 0;
  for (const auto& segment : e.segments) n += segment.size();
  return n;
}

std::vector<Grid3> decode_budget(const codec::EncodedGeometry& e, std::size_t budget) {
  std::vector<std::span<const std::uint8_t>> segments;
  std::span<const std::uint8_t> tail;
  std::size_t used = 0;
  for (const auto& segment : e.segments) {
    if (used + segment.size() > budget) {
      tail = std::span<const std::uint8_t>(segment).first(budget - used);
      break;
    }
    segments.push_back(segment);
    used += segment.size();
  }
  codec::DecodedGeometry d;
  codec::decode_geometry(e.header, segments, tail, d);
  return d.patches;
}

}  // namespace geomip::bench
