// The native side of the WASM decoder test (wasm_decoder_test.mjs): decodes every byte prefix 0..size of a
// pack with codec::decode_pack and prints, per prefix, two 32-bit hashes of the result laid out in the
// canonical word order that the test rebuilds from web/geomip.js's decode() (prefix_words below and
// canonicalWords() there). With --dump N it writes instead the raw words of prefix N to stdout (binary), for
// a byte-for-byte comparison of one prefix.
//   pack_prefix_hashes PACK            → lines "bytes status h1 h2"
//   pack_prefix_hashes PACK --dump N   → the words of prefix N, little-endian u32
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "codec/pack.h"

namespace {

using geomip::codec::PackDecodeResult;

// status, bytes used, chunks decoded, models; per model: patches, level, normal level (−1), hole level (−1),
// detail level, geometry passes; then every patch's geometry floats, normal floats and hole-mask bytes (one
// word each), patch by patch, model by model.
std::vector<std::uint32_t> prefix_words(const PackDecodeResult& r) {
  std::vector<std::uint32_t> w;
  w.push_back(static_cast<std::uint32_t>(r.status));
  w.push_back(static_cast<std::uint32_t>(r.bytes_used));
  w.push_back(static_cast<std::uint32_t>(r.chunks_decoded));
  w.push_back(static_cast<std::uint32_t>(r.models.size()));
  for (const auto& m : r.models) {
    const int normal_level = m.normals.empty() ? -1 : m.normals[0].level;
    const int hole_level = m.hole_mask.empty() ? -1 : m.hole_mask_level;
    w.push_back(static_cast<std::uint32_t>(m.geometry.size()));
    w.push_back(static_cast<std::uint32_t>(m.geometry.empty() ? -1 : m.geometry[0].level));
    w.push_back(static_cast<std::uint32_t>(normal_level));
    w.push_back(static_cast<std::uint32_t>(hole_level));
    w.push_back(static_cast<std::uint32_t>(m.detail_level));
    w.push_back(static_cast<std::uint32_t>(m.geometry_passes));
    for (std::size_t p = 0; p < m.geometry.size(); ++p) {
      for (float v : m.geometry[p].values) w.push_back(std::bit_cast<std::uint32_t>(v));
      if (p < m.normals.size())
        for (float v : m.normals[p].values) w.push_back(std::bit_cast<std::uint32_t>(v));
      if (p < m.hole_mask.size())
        for (std::uint8_t b : m.hole_mask[p]) w.push_back(b);
    }
  }
  return w;
}

// Two independent 32-bit hashes (FNV-1a over words; a multiply-rotate mix), as canonicalHashes() in JS.
std::pair<std::uint32_t, std::uint32_t> hashes(const std::vector<std::uint32_t>& words) {
  std::uint32_t h1 = 2166136261u, h2 = 0x9747b28cu;
  for (std::uint32_t x : words) {
    h1 = (h1 ^ x) * 16777619u;
    std::uint32_t k = h2 ^ x;
    k = (k << 13) | (k >> 19);
    h2 = k * 0x85ebca6bu + 1u;
  }
  return {h1, h2};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::strcmp(argv[2], "--dump") == 0)) {
    std::cerr << "usage: pack_prefix_hashes PACK [--dump BYTES]\n";
    return 2;
  }
  std::ifstream in(argv[1], std::ios::binary);
  if (!in) {
    std::cerr << "pack_prefix_hashes: cannot read " << argv[1] << "\n";
    return 2;
  }
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), {}};
  if (argc == 4) {
    const std::size_t n = std::min<std::size_t>(std::stoul(argv[3]), bytes.size());
    const auto words = prefix_words(geomip::codec::decode_pack(std::span(bytes).first(n)));
    std::fwrite(words.data(), sizeof(std::uint32_t), words.size(), stdout);
    return 0;
  }
  for (std::size_t n = 0; n <= bytes.size(); ++n) {
    // Only the first n bytes exist, as in the WASM decoder after n bytes were pushed.
    geomip::codec::PackDecodeOptions options;
    options.max_threads = 1;  // as the WASM build (one thread); the codec promises the same bits on any count
    const PackDecodeResult r = geomip::codec::decode_pack(std::span(bytes).first(n), options);
    const auto [h1, h2] = hashes(prefix_words(r));
    std::printf("%zu %d %08x %08x\n", n, static_cast<int>(r.status), h1, h2);
  }
  return 0;
}
