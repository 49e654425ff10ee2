// Incremental decoding (PackDecoder, GeometryDecoder, BitplaneDecoder): after ANY split of a pack's bytes
// into increments, the decoder's result equals a one-shot decode_pack() of the same prefix bit for bit —
// geometry and normal maps, every drop of finest steps, with and without partial chunks, joint and per-patch
// (post-joint) streams, 2 and 4 patches, and the committed golden packs of format versions 1 to 4.
#include "codec/pack.h"

#include "tests/codec/pillow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace geomip::codec {
namespace {

/// A pillow with deterministic noise (so that the bottom bit-planes are large), optionally with normal maps
/// and with `extra_patches` more patches (copies of the pillow's, scaled, not glued: P = 2 + extra_patches).
PackModelInput noisy_pillow(int level, const std::string& name, bool normals, int extra_patches,
                            unsigned seed) {
  test::Pillow p = test::make_pillow(level, 1.0);
  PackModelInput m;
  m.name = name;
  m.geometry = p.patches;
  m.seams = p.seams;
  for (int e = 0; e < extra_patches; ++e) {
    Grid3 g = p.patches[static_cast<std::size_t>(e % 2)];
    for (float& v : g.values) v = v * 0.5f + 1.5f;
    m.geometry.push_back(std::move(g));
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(-0.004f, 0.004f);
  // Noise on interior samples only: seam samples stay bit-identical across their patches.
  for (Grid3& g : m.geometry) {
    const int size = g.size();
    for (int j = 1; j + 1 < size; ++j)
      for (int i = 1; i + 1 < size; ++i)
        for (int c = 0; c < 3; ++c) g.values[3 * (static_cast<std::size_t>(j) * size + i) + c] += noise(rng);
  }
  if (normals) m.normals = test::position_normals(m.geometry);
  return m;
}

/// Two models (one with 4 patches), normal maps, a joint part of 256 bytes: most of the pack is in per-patch
/// streams.
std::vector<std::uint8_t> test_pack() {
  PackWriteOptions options;
  options.geometry.joint_bytes = 256;
  options.normal_codec.joint_bytes = 256;
  return write_pack({noisy_pillow(5, "a", true, 0, 1), noisy_pillow(4, "b", true, 2, 2)}, options);
}

void expect_same_grids(const std::vector<Grid3>& a, const std::vector<Grid3>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t p = 0; p < a.size(); ++p) {
    ASSERT_EQ(a[p].level, b[p].level) << what;
    ASSERT_EQ(a[p].values.size(), b[p].values.size()) << what;
    // Bit for bit (memcmp: NaN-safe, −0 ≠ +0).
    EXPECT_EQ(std::memcmp(a[p].values.data(), b[p].values.data(), a[p].values.size() * sizeof(float)), 0)
        << what << ", patch " << p;
  }
}

void expect_same(const PackDecodeResult& a, const PackDecodeResult& b, const std::string& what) {
  EXPECT_EQ(a.status, b.status) << what;
  EXPECT_EQ(a.chunks_decoded, b.chunks_decoded) << what;
  EXPECT_EQ(a.bytes_used, b.bytes_used) << what;
  ASSERT_EQ(a.models.size(), b.models.size()) << what;
  for (std::size_t m = 0; m < a.models.size(); ++m) {
    const DecodedModel &x = a.models[m], &y = b.models[m];
    const std::string at = what + ", model " + std::to_string(m);
    EXPECT_EQ(x.detail_level, y.detail_level) << at;
    EXPECT_EQ(x.geometry_passes, y.geometry_passes) << at;
    EXPECT_EQ(x.hole_mask, y.hole_mask) << at;
    EXPECT_EQ(x.hole_mask_level, y.hole_mask_level) << at;
    expect_same_grids(x.geometry, y.geometry, at + " geometry");
    expect_same_grids(x.normals, y.normals, at + " normals");
  }
}

/// Random cut points: `increments` prefixes ending at `end`, each at least as long as the one before.
std::vector<std::size_t> random_cuts(std::mt19937& rng, std::size_t end, int increments) {
  std::uniform_int_distribution<std::size_t> at(0, end);
  std::vector<std::size_t> cuts;
  for (int k = 0; k + 1 < increments; ++k) cuts.push_back(at(rng));
  std::sort(cuts.begin(), cuts.end());
  cuts.push_back(end);
  return cuts;
}

/// Feeds `pack` in the increments `cuts` (each prefix copied to fresh memory: the decoder must not keep
/// pointers into an old buffer) and compares with one-shot decodes at every cut.
void check_split(const std::vector<std::uint8_t>& pack, const std::vector<std::size_t>& cuts,
                 const PackDecodeOptions& options, const std::string& what) {
  PackDecoder decoder(options);
  for (std::size_t k = 0; k < cuts.size(); ++k) {
    const std::vector<std::uint8_t> prefix(pack.begin(), pack.begin() + static_cast<std::ptrdiff_t>(cuts[k]));
    decoder.update(prefix);
    // Compare at the last cut always, and at a few of the intermediate ones.
    if (k + 1 != cuts.size() && k % 5 != 2) continue;
    PackDecodeOptions one = options;
    const std::string at = what + ", cut " + std::to_string(k) + " at " + std::to_string(cuts[k]) + " bytes";
    expect_same(decoder.result(), decode_pack(prefix, one), at);
  }
}

TEST(IncrementalDecode, FixtureHasPerPatchStreams) {
  const std::vector<std::uint8_t> pack = test_pack();
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  for (const PackModelInfo& m : info.models) {
    // Segments after joint_segments are per-patch streams: they must exist and hold bytes.
    // Counts of segments (not times): the shared ones must leave room for per-patch ones.
    const int geometry_plane_count = m.geometry.top_bitplane + 1;
    const int normal_plane_count = m.normals.top_bitplane + 1;
    const int geometry_shared_count = m.geometry.joint_segments,
              normal_shared_count = m.normals.joint_segments;
    EXPECT_LT(geometry_shared_count, geometry_plane_count - 4) << m.name;
    EXPECT_LT(normal_shared_count, normal_plane_count) << m.name;
  }
  std::size_t per_patch_bytes = 0;
  for (const ChunkInfo& c : info.chunks) {
    const PackModelInfo& m = info.models[static_cast<std::size_t>(c.model)];
    if (c.kind == ChunkKind::kGeometry && c.pass >= m.geometry.joint_segments) per_patch_bytes += c.size;
  }
  EXPECT_GT(per_patch_bytes, pack.size() / 2);
  EXPECT_GT(info.models[1].geometry.num_patches, 2);
  // Two-layer normal maps (format 11) on both models: layer 2's stream is split and resumed too.
  for (const PackModelInfo& m : info.models) EXPECT_EQ(m.normal_layers, 2) << m.name;
}

TEST(IncrementalDecode, AnySplitEqualsOneShotDecode) {
  const std::vector<std::uint8_t> pack = test_pack();
  std::mt19937 rng(16);
  const PackDecodeOptions variants[] = {
      {},
      {.normals = false},
      {.partial_chunks = false},
      {.drop_finest_steps = 2, .max_threads = 1},
      {.max_threads = 1},
  };
  for (int round = 0; round < 24; ++round) {
    const PackDecodeOptions& options = variants[round % std::size(variants)];
    // The whole pack or a random prefix, in 1 to 64 increments.
    std::uniform_int_distribution<std::size_t> end_at(0, pack.size());
    const std::size_t end = round % 2 == 0 ? pack.size() : end_at(rng);
    const int increments = std::uniform_int_distribution<int>(1, 64)(rng);
    check_split(pack, random_cuts(rng, end, increments), options,
                "round " + std::to_string(round) + ", " + std::to_string(increments) + " increments");
  }
}

TEST(IncrementalDecode, ByteByByteEqualsOneShotDecode) {
  // Every increment a single byte: the decoder stops and resumes at every possible symbol boundary.
  PackWriteOptions options;
  options.geometry.joint_bytes = 64;
  options.normal_codec.joint_bytes = 64;
  const std::vector<std::uint8_t> pack = write_pack({noisy_pillow(3, "a", true, 0, 3)}, options);
  std::vector<std::size_t> cuts(pack.size());
  for (std::size_t k = 0; k < pack.size(); ++k) cuts[k] = k + 1;
  PackDecoder decoder;
  for (std::size_t n : cuts) {
    const std::span<const std::uint8_t> prefix(pack.data(), n);
    decoder.update(prefix);
    expect_same(decoder.result(), decode_pack(prefix), "prefix of " + std::to_string(n) + " bytes");
  }
}

TEST(IncrementalDecode, BandsFromOneDecodeEqualSeparateDecodes) {
  const std::vector<std::uint8_t> pack = test_pack();
  for (std::size_t end : {pack.size() / 3, pack.size()}) {
    const std::span<const std::uint8_t> prefix(pack.data(), end);
    PackDecoder decoder({.partial_chunks = false});
    decoder.update(prefix);
    for (int drop = 0; drop < 4; ++drop) {
      const PackDecodeResult one =
          decode_pack(prefix, {.normals = false, .partial_chunks = false, .drop_finest_steps = drop});
      expect_same(decoder.result(drop, false), one, "drop " + std::to_string(drop));
    }
  }
}

TEST(IncrementalDecode, TakenResultEqualsCopiedResult) {
  // take_result() moves the grids out of the caches (decode_pack's way); result() copies them. Both, and a
  // result() after a take (the cache rebuilt), with the same and with other drops, give the same bits.
  const std::vector<std::uint8_t> pack = test_pack();
  for (std::size_t end : {pack.size() / 4, pack.size()}) {
    const std::span<const std::uint8_t> prefix(pack.data(), end);
    PackDecoder copied, taken;
    copied.update(prefix);
    taken.update(prefix);
    const std::string at = std::to_string(end) + " bytes";
    expect_same(taken.take_result(), copied.result(), at + ", taken");
    expect_same(taken.result(), copied.result(), at + ", result after a take");
    for (int drop = 0; drop < 3; ++drop) {
      expect_same(taken.take_result(drop), copied.result(drop), at + ", taken, drop " + std::to_string(drop));
      expect_same(taken.result(drop), copied.result(drop), at + ", after a take, drop " + std::to_string(drop));
    }
  }
}

TEST(IncrementalDecode, GoldenPacksOfEveryVersion) {
  for (const char* file :
       {"golden-pillow.gip", "golden-pillow-v2.gip", "golden-pillow-v3.gip", "golden-pillow-v4.gip",
        "golden-pillow-v5.gip"}) {
    std::ifstream in(std::string(GEOMIP_SOURCE_DIR) + "/tests/data/" + file, std::ios::binary);
    ASSERT_TRUE(in) << file;
    const std::vector<std::uint8_t> pack((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
    std::mt19937 rng(7);
    for (int round = 0; round < 6; ++round)
      check_split(pack, random_cuts(rng, pack.size(), 1 + round * 7), {}, std::string(file));
  }
}

TEST(IncrementalDecode, CrcFailureAfterAPartialChunkEqualsOneShotDecode) {
  // A chunk whose prefix was decoded as a partial tail fails its CRC once complete: its stream is decoded
  // again without it, as the one-shot decode never used it.
  std::vector<std::uint8_t> pack = test_pack();
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  const ChunkInfo& chunk = info.chunks[info.chunks.size() / 2];
  ASSERT_GT(chunk.size, 8u);
  pack[static_cast<std::size_t>(chunk.offset + chunk.size - 1)] ^=
      0x40;  // its last byte: the prefix is intact
  const std::vector<std::size_t> cuts = {static_cast<std::size_t>(chunk.offset + chunk.size / 2),
                                         static_cast<std::size_t>(chunk.offset + chunk.size + 3),
                                         pack.size()};
  check_split(pack, cuts, {}, "flipped last byte of chunk");
  PackDecoder decoder;
  for (std::size_t n : cuts) decoder.update(std::span<const std::uint8_t>(pack.data(), n));
  EXPECT_EQ(decoder.result().status, Status::kCorrupt);
}

}  // namespace
}  // namespace geomip::codec
