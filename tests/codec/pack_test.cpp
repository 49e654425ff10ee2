// The .gip pack: round trip, every prefix, corruption, versions, trailing bytes, and the committed golden
// pack.
#include "codec/pack.h"

#include "codec/layout_code.h"

#include "tests/codec/pillow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <random>

namespace geomip::codec {
namespace {

using test::make_pillow;
using test::random_layout_seams;
using test::seam_mismatches;

PackModelInput pillow_model(int level, const std::string& name, double scale = 1.0, bool normals = false) {
  test::Pillow p = make_pillow(level, scale);
  PackModelInput m;
  m.name = name;
  m.geometry = p.patches;
  m.seams = p.seams;
  // Any smooth unit field will do for the container tests: the normalized position.
  if (normals) m.normals = test::position_normals(p.patches);
  return m;
}

/// `pack` relabelled as format `version` (the version field rewritten, the manifest's CRC recomputed as that
/// version computes it: from version 11 on it covers the version too): what a writer of that version would
/// have written for the same manifest and chunks.
std::vector<std::uint8_t> relabel(std::vector<std::uint8_t> pack, std::uint16_t version) {
  std::size_t pos = 10, shift = 0;  // magic (8), version (2), then the manifest size varint
  std::uint64_t size = 0;
  while (pack.at(pos) & 0x80) size |= std::uint64_t(pack[pos++] & 0x7f) << shift, shift += 7;
  size |= std::uint64_t(pack[pos++]) << shift;
  pack[8] = static_cast<std::uint8_t>(version & 0xff);
  pack[9] = static_cast<std::uint8_t>(version >> 8);
  const std::uint32_t crc = manifest_crc(version, std::span(pack).subspan(pos + 4, size));
  for (int k = 0; k < 4; ++k) pack[pos + k] = static_cast<std::uint8_t>(crc >> (8 * k));
  return pack;
}

PackWriteOptions geometry_only() {
  PackWriteOptions o;
  o.normals = false;
  return o;
}

/// Largest |decoded − original| over all samples of all patches.
double max_error(const std::vector<Grid3>& decoded, const std::vector<Grid3>& original) {
  double e = 0;
  for (std::size_t p = 0; p < original.size(); ++p)
    for (std::size_t k = 0; k < original[p].values.size(); ++k)
      e = std::max(e, std::abs(static_cast<double>(decoded[p].values[k]) - original[p].values[k]));
  return e;
}

double rms_error(const std::vector<Grid3>& decoded, const std::vector<Grid3>& original) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < original.size(); ++p)
    for (std::size_t k = 0; k < original[p].values.size(); ++k, ++n)
      s += std::pow(static_cast<double>(decoded[p].values[k]) - original[p].values[k], 2);
  return std::sqrt(s / static_cast<double>(n));
}

TEST(Pack, RoundTripWithinQuantization) {
  const std::vector<PackModelInput> models = {pillow_model(6, "a"), pillow_model(6, "b", 2.0)};
  const std::vector<std::uint8_t> pack = write_pack(models, geometry_only());
  const PackDecodeResult r = decode_pack(pack);
  ASSERT_EQ(r.status, Status::kOk);
  ASSERT_EQ(r.models.size(), 2u);
  EXPECT_EQ(r.chunks_decoded, r.info.chunks.size());
  EXPECT_EQ(r.bytes_used, pack.size());
  EXPECT_EQ(r.info.file_size(), pack.size());
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(r.models[m].name, models[m].name);
    const double extent = m == 0 ? 2.0 : 4.0;
    // 14 bits (the default) over the largest extent: rounding to the step, plus float rounding of the output;
    // local frames (version 3) round their rotation and code tangential components one plane coarser: a few
    // steps at most.
    EXPECT_LE(max_error(r.models[m].geometry, models[m].geometry), extent / 16384.0 * 8 + 1e-6);
    EXPECT_EQ(seam_mismatches(r.models[m].geometry, r.models[m].seams), 0u);
  }
}

TEST(Pack, ChunksAreOrderedCoarseToFineAcrossModels) {
  const std::vector<std::uint8_t> pack =
      write_pack({pillow_model(5, "a", 1.0, true), pillow_model(5, "b", 1.0, true)});
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  // Geometry pass p of model 1 never precedes pass p of model 0, nor pass p+1 of model 0 precede pass p of 1.
  std::vector<int> seen(2, -1);
  for (const ChunkInfo& c : info.chunks) {
    if (c.kind != ChunkKind::kGeometry) continue;
    EXPECT_EQ(c.pass, seen[static_cast<std::size_t>(c.model)] + 1);
    seen[static_cast<std::size_t>(c.model)] = c.pass;
    const int other = seen[static_cast<std::size_t>(1 - c.model)];
    EXPECT_GE(other, c.pass - (c.model == 0 ? 1 : 0)) << "model " << c.model << " pass " << c.pass;
  }
  EXPECT_TRUE(std::any_of(info.chunks.begin(), info.chunks.end(),
                          [](const ChunkInfo& c) { return c.kind == ChunkKind::kNormals; }));
}

TEST(Pack, EveryPrefixDecodesToACoarserModelOrTruncated) {
  const std::vector<PackModelInput> models = {pillow_model(4, "a"), pillow_model(4, "b", 1.5)};
  const std::vector<std::uint8_t> pack = write_pack(models, geometry_only());
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  double previous_error = INFINITY;
  for (std::size_t n = 0; n <= pack.size(); ++n) {
    const PackDecodeResult r = decode_pack(pack, {.max_bytes = n});
    if (n < info.manifest_end) {
      EXPECT_EQ(r.status, Status::kTruncated) << n;
      EXPECT_TRUE(r.models.empty()) << n;
      continue;
    }
    ASSERT_EQ(r.status, n == pack.size() ? Status::kOk : Status::kTruncated) << n;
    ASSERT_EQ(r.models.size(), 2u) << n;
    for (const DecodedModel& m : r.models) {
      ASSERT_EQ(m.geometry.size(), 2u);
      EXPECT_EQ(seam_mismatches(m.geometry, m.seams), 0u) << "prefix " << n;
      for (const Grid3& g : m.geometry)
        EXPECT_TRUE(std::all_of(g.values.begin(), g.values.end(), [](float v) { return std::isfinite(v); }));
    }
    // At chunk boundaries (whole passes), more bytes never make the model worse — up to 5 %: with local
    // frames (version 3) a pass that refines normal components can move a sample by the frame rotation's
    // rounding (measured on this fixture: +3 % once, 0.0677 → 0.0698, and +1.6 % at the last pass).
    const bool boundary = std::any_of(info.chunks.begin(), info.chunks.end(),
                                      [&](const ChunkInfo& c) { return c.offset + c.size == n; });
    if (boundary) {
      const double e = rms_error(r.models[0].geometry, models[0].geometry);
      EXPECT_LE(e, previous_error * 1.05) << "prefix " << n;
      previous_error = e;
    }
  }
}

/// Bytes of the varint manifest size of a version-4 pack (at byte 10).
std::size_t manifest_size_bytes(const std::vector<std::uint8_t>& pack) {
  std::size_t n = 1;
  while (pack[9 + n] & 0x80) ++n;
  return n;
}

TEST(Pack, FlippedBytesAreCorruptNeverACrash) {
  const std::vector<std::uint8_t> pack = write_pack({pillow_model(4, "a", 1.0, true)});
  const std::size_t size_end = 10 + manifest_size_bytes(pack);
  std::mt19937 rng(7);
  for (std::size_t at = 0; at < pack.size(); ++at) {
    std::vector<std::uint8_t> bad = pack;
    bad[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    const PackDecodeResult r = decode_pack(bad);
    if (at >= 8 && at < 10) {
      EXPECT_EQ(r.status, Status::kUnsupportedVersion) << at;  // the version field
    } else if (at >= 10 && at < size_end) {
      // The manifest size: larger reads as a pack whose manifest has not all arrived, smaller fails its CRC.
      EXPECT_TRUE(r.status == Status::kCorrupt || r.status == Status::kTruncated) << at;
    } else {
      EXPECT_EQ(r.status, Status::kCorrupt) << "flipped byte " << at;
    }
    for (const DecodedModel& m : r.models) EXPECT_EQ(seam_mismatches(m.geometry, m.seams), 0u);
  }
}

TEST(Pack, CorruptChunkStopsAtLastGoodPass) {
  const std::vector<PackModelInput> models = {pillow_model(5, "a")};
  const std::vector<std::uint8_t> pack = write_pack(models, geometry_only());
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  // Damage the first non-empty chunk after the third.
  std::size_t victim = 3;
  while (victim < info.chunks.size() && info.chunks[victim].size == 0) ++victim;
  ASSERT_LT(victim, info.chunks.size());
  std::vector<std::uint8_t> bad = pack;
  bad[info.chunks[victim].offset] ^= 0x40;
  const PackDecodeResult r = decode_pack(bad);
  EXPECT_EQ(r.status, Status::kCorrupt);
  // Version 4 verifies CRC groups: decoding stops at the start of the victim's group.
  const std::size_t first = info.chunks[victim].group_first;
  EXPECT_EQ(r.chunks_decoded, first);
  ASSERT_EQ(r.models.size(), 1u);
  const PackDecodeResult good_prefix = decode_pack(
      pack, {.max_bytes = static_cast<std::size_t>(info.chunks[first].offset), .partial_chunks = false});
  EXPECT_EQ(r.models[0].geometry[0].values, good_prefix.models[0].geometry[0].values);
}

TEST(Pack, OtherVersionIsUnsupported) {
  std::vector<std::uint8_t> pack = write_pack({pillow_model(3, "a")});
  pack[8] = static_cast<std::uint8_t>(kPackVersion + 1);
  EXPECT_EQ(decode_pack(pack).status, Status::kUnsupportedVersion);
  std::size_t end = 0;
  EXPECT_EQ(read_pack_header(pack, end), Status::kUnsupportedVersion);
}

// Pack formats 6 and 7 hold codec headers of versions 3 to 5 only: a format-8 pack whose cell frames (codec
// header 6) are relabelled format 7 is refused, the same pack with version 5's frames is a valid format 7.
/// The pillow with its second patch turned by a side: the same surface, a table that is not in the canonical
/// order of a layout code (so format 9 stores it as format 7 did, and relabelling the version stays valid).
PackModelInput turned_pillow_model(int level, const std::string& name) {
  PackModelInput m = pillow_model(level, name);
  m.geometry[1] = rotate_grid(m.geometry[1], 1);  // new side s = old side s + 1
  for (PatchSeam& s : m.seams) {
    if (s.patch == 1) s.side = (s.side + 3) % 4;
    if (s.other_patch == 1) s.other_side = (s.other_side + 3) % 4;
  }
  std::sort(m.seams.begin(), m.seams.end(), [](const PatchSeam& a, const PatchSeam& b) {
    return std::pair(a.patch, a.side) < std::pair(b.patch, b.side);
  });
  return m;
}

TEST(Pack, LayoutCodesNeedFormat9) {
  // The pillow's table is a layout code in canonical order already: format 9 stores it as one. Without
  // headroom (codec header 6) and normal maps a format-11 writer's pack is format 9's but for the version
  // (and the manifest CRC, which covers the version from format 11 on).
  PackWriteOptions no_headroom = geometry_only();
  no_headroom.geometry.headroom_bits = 0;
  std::vector<std::uint8_t> pack = relabel(write_pack({pillow_model(4, "a")}, no_headroom), 9);
  ASSERT_EQ(kPackVersion, 11);
  ASSERT_EQ(decode_pack(pack).status, Status::kOk);
  EXPECT_EQ(decode_pack(relabel(pack, 8)).status, Status::kCorrupt);
  // The turned pillow's table is not: stored as format 7 did, it reads as format 8 too.
  const PackModelInput turned = turned_pillow_model(4, "a");
  ASSERT_EQ(test::seam_mismatches(turned.geometry, turned.seams), 0u);
  std::vector<std::uint8_t> other = relabel(write_pack({turned}, no_headroom), 9);
  const PackDecodeResult as9 = decode_pack(other);
  ASSERT_EQ(as9.status, Status::kOk);
  const PackDecodeResult relabelled = decode_pack(relabel(other, 8));
  ASSERT_EQ(relabelled.status, Status::kOk);
  EXPECT_EQ(relabelled.models.at(0).geometry[1].values, as9.models.at(0).geometry[1].values);
  // With canonical_layout the writer turns it back: the code again, and the pillow's own grids.
  PackWriteOptions o = no_headroom;
  o.canonical_layout = true;
  EXPECT_EQ(relabel(write_pack({turned}, o), 9), pack);
}

TEST(Pack, HeadroomNeedsFormat10) {
  // The default writer's geometry has headroom (codec header 7, a bottom bit-plane): format 10 and later.
  std::vector<std::uint8_t> pack = relabel(write_pack({pillow_model(5, "a")}, geometry_only()), 10);
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  EXPECT_EQ(info.version, 10);
  const GeometryCodecHeader& h = info.models.at(0).geometry;
  EXPECT_EQ(h.version, 7);
  EXPECT_EQ(h.bottom_bitplane, GeometryCodecOptions{}.headroom_bits);
  EXPECT_GT(h.bottom_bitplane, 0);
  // The whole pack decodes complete (not "truncated" for the planes below the bottom one), near-losslessly.
  const PackDecodeResult whole = decode_pack(pack);
  ASSERT_EQ(whole.status, Status::kOk);
  EXPECT_EQ(whole.models.at(0).geometry_passes,
            static_cast<std::size_t>(h.top_bitplane - h.bottom_bitplane + 1));
  EXPECT_LE(max_error(whole.models.at(0).geometry, pillow_model(5, "a").geometry), 8.0 * 2.0 / 16384.0);
  EXPECT_EQ(decode_pack(relabel(pack, 9)).status, Status::kCorrupt);
}

TEST(Pack, CellFramesNeedFormat8) {
  for (const bool cells : {true, false}) {
    PackWriteOptions o = geometry_only();
    o.geometry.cell_frames = cells;
    o.geometry.headroom_bits = 0;  // codec header 6 (7 builds on it)
    std::vector<std::uint8_t> pack = write_pack({turned_pillow_model(4, "a")}, o);
    PackInfo info;
    ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
    ASSERT_EQ(info.models.at(0).geometry.version, cells ? 6 : 5);
    const PackDecodeResult as8 = decode_pack(pack);
    ASSERT_EQ(as8.status, Status::kOk);
    const PackDecodeResult as7 = decode_pack(relabel(pack, 7));
    if (cells) {
      EXPECT_EQ(as7.status, Status::kCorrupt);
      EXPECT_TRUE(as7.models.empty());
    } else {
      ASSERT_EQ(as7.status, Status::kOk);
      EXPECT_EQ(as7.models.at(0).geometry[0].values, as8.models.at(0).geometry[0].values);
    }
  }
}

// The writer refuses what every reader would (more than 2^25 samples): 9 patches of level 11 claim
// 9 · 2049² = 37.8 M. Checked before any grid is read, so the grids here can stay empty.
TEST(Pack, WriterRefusesMoreSamplesThanAPackHolds) {
  PackModelInput m;
  m.name = "big";
  m.geometry.assign(9, Grid3{11, {}});
  try {
    write_pack({m}, geometry_only());
    FAIL() << "written";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("more than a pack holds"), std::string::npos) << e.what();
  }
}

TEST(Pack, TrailingBytesAreTolerated) {
  const std::vector<std::uint8_t> pack = write_pack({pillow_model(4, "a")});
  std::vector<std::uint8_t> longer = pack;
  for (int k = 0; k < 100; ++k) longer.push_back(static_cast<std::uint8_t>(k * 37));
  const PackDecodeResult a = decode_pack(pack), b = decode_pack(longer);
  ASSERT_EQ(b.status, Status::kOk);
  EXPECT_EQ(a.models[0].geometry[0].values, b.models[0].geometry[0].values);
}

TEST(Pack, GarbageAndEmptyInput) {
  EXPECT_EQ(decode_pack({}).status, Status::kTruncated);
  const std::uint8_t magic_only[] = {'G', 'E', 'O', 'M'};
  EXPECT_EQ(decode_pack(magic_only).status, Status::kTruncated);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::uint8_t> garbage(static_cast<std::size_t>(rng() % 300));
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    EXPECT_EQ(decode_pack(garbage).status, garbage.empty() ? Status::kTruncated : Status::kCorrupt);
  }
}

TEST(Pack, HoleMaskRoundTrips) {
  PackModelInput m = pillow_model(4, "holey");
  m.hole_mask.assign(2, std::vector<std::uint8_t>(16 * 16, 0));
  for (int k = 40; k < 70; ++k) m.hole_mask[1][static_cast<std::size_t>(k)] = 1;
  m.hole_mask[0][255] = 1;
  const PackDecodeResult r = decode_pack(write_pack({m}));
  ASSERT_EQ(r.status, Status::kOk);
  EXPECT_EQ(r.models[0].hole_mask, m.hole_mask);
}

// The manifest carries the hole masks two levels coarser; the fine masks arrive in their own chunk, and any
// prefix before it decodes with the coarse ones.
TEST(Pack, HoleMaskIsCoarseUntilItsChunkArrives) {
  PackModelInput m = pillow_model(5, "holey");
  m.hole_mask.assign(2, std::vector<std::uint8_t>(32 * 32, 0));
  for (int j = 10; j < 17; ++j)
    for (int i = 3; i < 12; ++i) m.hole_mask[0][static_cast<std::size_t>(j * 32 + i)] = 1;
  PackWriteOptions options = geometry_only();
  options.hole_mask_after_bytes = 200;
  const std::vector<std::uint8_t> pack = write_pack({m}, options);
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  const auto chunk = std::find_if(info.chunks.begin(), info.chunks.end(),
                                  [](const ChunkInfo& c) { return c.kind == ChunkKind::kHoleMask; });
  ASSERT_NE(chunk, info.chunks.end());
  EXPECT_EQ(info.models[0].hole_mask_level, 3);
  EXPECT_EQ(info.models[0].fine_hole_mask_level, 5);

  const PackDecodeResult before =
      decode_pack(pack, {.max_bytes = static_cast<std::size_t>(chunk->offset + chunk->size - 1)});
  ASSERT_EQ(before.models.size(), 1u);
  EXPECT_EQ(before.models[0].hole_mask_level, 3);
  // Coarse quad (ci, cj) covers fine quads [4ci, 4ci+4) × [4cj, 4cj+4): masked when half of them are.
  const auto& coarse = before.models[0].hole_mask[0];
  ASSERT_EQ(coarse.size(), 64u);
  for (int cj = 0; cj < 8; ++cj)
    for (int ci = 0; ci < 8; ++ci) {
      int count = 0;
      for (int j = 4 * cj; j < 4 * cj + 4; ++j)
        for (int i = 4 * ci; i < 4 * ci + 4; ++i)
          count += m.hole_mask[0][static_cast<std::size_t>(j * 32 + i)];
      EXPECT_EQ(coarse[static_cast<std::size_t>(cj * 8 + ci)], count >= 8 ? 1 : 0) << ci << "," << cj;
    }
  // The fine masks are used once their CRC group (version 4) is complete.
  const auto group_end =
      std::find_if(chunk, info.chunks.end(), [](const ChunkInfo& c) { return c.crc_bytes > 0; });
  ASSERT_NE(group_end, info.chunks.end());
  const PackDecodeResult after =
      decode_pack(pack, {.max_bytes = static_cast<std::size_t>(group_end->offset + group_end->size)});
  EXPECT_EQ(after.models[0].hole_mask_level, 5);
  EXPECT_EQ(after.models[0].hole_mask, m.hole_mask);
}

// Fine masks of every kind (empty, sparse, blobs, nearly full, isolated bits at block borders) arrive
// exactly.
TEST(Pack, RandomHoleMasksRoundTrip) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 12; ++trial) {
    PackModelInput m = pillow_model(5, "holey");
    m.hole_mask.assign(2, std::vector<std::uint8_t>(32 * 32, 0));
    const double density = std::array{0.0, 0.01, 0.1, 0.5, 0.9, 1.0}[static_cast<std::size_t>(trial % 6)];
    for (auto& mask : m.hole_mask) {
      for (auto& b : mask) b = std::uniform_real_distribution<double>(0, 1)(rng) < density;
      if (trial >= 6) {  // a blob too
        const int x0 = static_cast<int>(rng() % 24), y0 = static_cast<int>(rng() % 24);
        for (int j = y0; j < y0 + 7; ++j)
          for (int i = x0; i < x0 + 5; ++i) mask[static_cast<std::size_t>(j * 32 + i)] = 1;
      }
    }
    PackWriteOptions options = geometry_only();
    options.hole_mask_after_bytes = 100;
    const PackDecodeResult r = decode_pack(write_pack({m}, options));
    ASSERT_EQ(r.status, Status::kOk);
    EXPECT_EQ(r.models[0].hole_mask_level, 5);
    EXPECT_EQ(r.models[0].hole_mask, m.hole_mask) << "trial " << trial;
  }
}

TEST(Pack, WriterRejectsBadInput) {
  EXPECT_THROW(write_pack({}), std::invalid_argument);
  PackModelInput m = pillow_model(3, "a");
  m.hole_mask.assign(2, std::vector<std::uint8_t>(5, 0));
  EXPECT_THROW(write_pack({m}), std::invalid_argument);
  PackModelInput nan = pillow_model(3, "nan");
  nan.geometry[0].values[7] = NAN;
  EXPECT_THROW(write_pack({nan}), std::invalid_argument);
}

// Format version 4's header diet: no CRC in the chunk table; one CRC32 trailer per group — a chunk of at
// least crc_group_bytes alone, smaller neighbours together until they reach it — and chunks still tile the
// file.
TEST(Pack, CrcGroupsGatherSmallChunksAndTileTheFile) {
  const std::vector<std::uint8_t> pack = write_pack({pillow_model(5, "a", 1.0, true)});
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  EXPECT_EQ(info.version, kPackVersion);
  EXPECT_EQ(info.file_size(), pack.size());
  const std::uint32_t group_bytes = PackWriteOptions{}.crc_group_bytes;
  std::uint64_t offset = info.manifest_end, gathered = 0;
  std::size_t groups = 0;
  bool open = false;
  for (std::size_t c = 0; c < info.chunks.size(); ++c) {
    const ChunkInfo& chunk = info.chunks[c];
    EXPECT_EQ(chunk.offset, offset) << c;
    offset += chunk.size;
    EXPECT_EQ(chunk.crc32, 0u);
    EXPECT_TRUE(chunk.crc_bytes == 0 || chunk.crc_bytes == 4) << c;
    EXPECT_EQ(chunk.group_first, open ? info.chunks[c - 1].group_first : c) << c;
    open = chunk.crc_bytes == 0;
    if (chunk.payload_size() >= group_bytes) {
      EXPECT_EQ(chunk.group_first, c) << "a large chunk opens its group";
    }
    gathered += chunk.payload_size();
    if (chunk.crc_bytes == 0) {
      // An open group: smaller than the threshold, and not followed by a large chunk.
      EXPECT_LT(gathered, group_bytes) << c;
      ASSERT_LT(c + 1, info.chunks.size());
      EXPECT_LT(info.chunks[c + 1].payload_size(), group_bytes) << c;
    } else {
      ++groups;
      gathered = 0;
      // The trailer is the CRC32 of the group's payloads.
      const std::uint64_t begin = info.chunks[chunk.group_first].offset,
                          end = chunk.offset + chunk.payload_size();
      std::uint32_t stored = 0;
      for (int k = 0; k < 4; ++k) stored |= static_cast<std::uint32_t>(pack[end + k]) << (8 * k);
      EXPECT_EQ(stored, crc32(std::span(pack).subspan(begin, end - begin))) << c;
    }
  }
  EXPECT_EQ(info.chunks.back().crc_bytes, 4u);
  EXPECT_LT(groups, info.chunks.size()) << "the tiny top planes share a CRC";
}

// The open CRC group (its trailer not yet arrived) is used unverified, as a partial chunk is: the first
// passes of every model decode before the first trailer; once complete and verified it gives the same
// models; if its CRC fails, the incremental decoder drops what it took from it (as the one-shot decode).
TEST(Pack, OpenCrcGroupIsUsedUntilItsCrcFails) {
  const std::vector<std::uint8_t> pack =
      write_pack({pillow_model(4, "a"), pillow_model(4, "b", 1.5)}, geometry_only());
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  const auto end = std::find_if(info.chunks.begin(), info.chunks.end(),
                                [](const ChunkInfo& c) { return c.crc_bytes > 0; });
  ASSERT_NE(end, info.chunks.end());
  ASSERT_GE(end - info.chunks.begin(), 2) << "the first group holds pass 0 of both models";
  const std::size_t before_trailer = static_cast<std::size_t>(end->offset + end->payload_size());
  const PackDecodeResult open = decode_pack(pack, {.max_bytes = before_trailer});
  const PackDecodeResult verified =
      decode_pack(pack, {.max_bytes = before_trailer + 4, .partial_chunks = false});
  ASSERT_EQ(open.status, Status::kTruncated);
  EXPECT_EQ(open.chunks_decoded, 0u);
  EXPECT_EQ(verified.chunks_decoded, static_cast<std::size_t>(end - info.chunks.begin()) + 1);
  ASSERT_EQ(open.models.size(), 2u);
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_GT(
        rms_error(open.models[m].geometry, std::vector<Grid3>(2, Grid3{4, std::vector<float>(17 * 17 * 3)})),
        0)
        << "model " << m << " has a shape before the trailer";
    for (std::size_t p = 0; p < 2; ++p)
      EXPECT_EQ(open.models[m].geometry[p].values, verified.models[m].geometry[p].values) << m;
  }
  // The same group damaged: before its trailer the damage is not seen; with it, everything from the group
  // on is dropped, incrementally as one-shot.
  std::vector<std::uint8_t> bad = pack;
  bad[before_trailer - 1] ^= 0x10;
  PackDecoder decoder;
  decoder.update(std::span(bad).first(before_trailer));
  EXPECT_EQ(decoder.result().status, Status::kTruncated);
  decoder.update(bad);
  const PackDecodeResult incremental = decoder.result(), one_shot = decode_pack(bad);
  EXPECT_EQ(one_shot.status, Status::kCorrupt);
  EXPECT_EQ(incremental.status, Status::kCorrupt);
  EXPECT_EQ(incremental.chunks_decoded, 0u);
  ASSERT_EQ(incremental.models.size(), 2u);
  for (std::size_t m = 0; m < 2; ++m)
    for (std::size_t p = 0; p < 2; ++p)
      EXPECT_EQ(incremental.models[m].geometry[p].values, one_shot.models[m].geometry[p].values) << m;
}

// Doubles of version 4 are float32 only where that is exact: any normalization round-trips bit for bit.
TEST(Pack, NormalizationRoundTripsBitForBit) {
  const std::array<double, 16> transforms[] = {
      {0.25, 0, 0, -1.5, 0, 0.25, 0, 2, 0, 0, 0.25, -0.0, 0, 0, 0, 1},                 // float32-exact
      {1.0 / 3, 0, 0, 0.1, 0, 1.0 / 3, 0, -1e-300, 0, 0, 1.0 / 3, 1e300, 0, 0, 0, 1},  // not
      {1, 2, 3, 4, 5, 6, 7, 8.5, 0.1, 0.2, 0.3, 0.4, 0, 0, 0, 1},                      // full, mixed
  };
  for (const auto& t : transforms) {
    PackModelInput m = pillow_model(3, "a");
    m.normalization = t;
    const PackDecodeResult r = decode_pack(write_pack({m}, geometry_only()));
    ASSERT_EQ(r.status, Status::kOk);
    for (int k = 0; k < 16; ++k)
      EXPECT_EQ(std::bit_cast<std::uint64_t>(r.models[0].normalization[static_cast<std::size_t>(k)]),
                std::bit_cast<std::uint64_t>(t[static_cast<std::size_t>(k)]))
          << k;
  }
}

/// A level-5 pillow with deterministic interior ripples of every frequency (seam samples untouched, so they
/// stay bit-identical), coded with the default options: its geometry stream runs well past the joint part
/// (GeometryCodecOptions::joint_bytes), so most of the pack is per-patch streams.
std::vector<std::uint8_t> per_patch_pack(std::vector<PackModelInput>* models_out = nullptr) {
  PackModelInput m = pillow_model(5, "rough");
  for (Grid3& g : m.geometry) {
    const int size = g.size();
    for (int j = 1; j + 1 < size; ++j)
      for (int i = 1; i + 1 < size; ++i)
        for (int c = 0; c < 3; ++c) {
          const unsigned hash = (static_cast<unsigned>(i) * 73856093u) ^
                                (static_cast<unsigned>(j) * 19349663u) ^
                                (static_cast<unsigned>(c) * 83492791u);
          g.values[3 * (static_cast<std::size_t>(j) * size + i) + c] +=
              0.003f * (static_cast<float>(hash % 1001) / 500.0f - 1.0f);
        }
  }
  if (models_out) *models_out = {m};
  return write_pack({m}, geometry_only());
}

TEST(PackPerPatch, FixtureHasNonEmptyPerPatchStreams) {
  const std::vector<std::uint8_t> pack = per_patch_pack();
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  const GeometryCodecHeader& h = info.models[0].geometry;
  const int plane_count = h.top_bitplane + 1;
  const int joint_plane_count = h.joint_segments;  // bit-planes in the joint stream (a count)
  const int per_patch_plane_count = plane_count - joint_plane_count;
  EXPECT_GE(per_patch_plane_count, 3);  // several bit-planes are coded per patch, not only the last ones
  std::size_t per_patch_bytes = 0, joint_bytes = 0, per_patch_chunks = 0;
  for (const ChunkInfo& c : info.chunks) {
    (c.pass >= joint_plane_count ? per_patch_bytes : joint_bytes) += c.payload_size();
    per_patch_chunks += c.pass >= joint_plane_count && c.payload_size() > 0;
  }
  EXPECT_GE(joint_bytes, GeometryCodecOptions{}.joint_bytes);
  // Measured: 1655 of the 4.6 KB in 5 per-patch passes (pack format 4, codec header 3).
  EXPECT_GT(per_patch_bytes, pack.size() / 4);
  EXPECT_GE(per_patch_chunks, 3u);
}

// Every byte prefix of a pack with per-patch streams decodes: Truncated (no models inside the manifest),
// finite samples, seams bit-identical (watertight), and kOk only for the whole pack. Fed to one PackDecoder
// byte by byte (equal to one-shot decodes: incremental_decode_test).
TEST(PackPerPatch, EveryBytePrefixDecodesWatertight) {
  const std::vector<std::uint8_t> pack = per_patch_pack();
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  PackDecoder decoder({.max_threads = 1});
  int detail_level = -1;
  for (std::size_t n = 0; n <= pack.size(); ++n) {
    decoder.update(std::span(pack).first(n));
    const PackDecodeResult r = decoder.result();
    ASSERT_EQ(r.status, n == pack.size() ? Status::kOk : Status::kTruncated) << n;
    if (n < info.manifest_end) {
      ASSERT_TRUE(r.models.empty()) << n;
      continue;
    }
    ASSERT_EQ(r.models.size(), 1u) << n;
    const DecodedModel& m = r.models[0];
    ASSERT_EQ(m.geometry.size(), 2u) << n;
    ASSERT_EQ(seam_mismatches(m.geometry, m.seams), 0u) << "prefix " << n;
    for (const Grid3& g : m.geometry)
      ASSERT_TRUE(std::all_of(g.values.begin(), g.values.end(), [](float v) { return std::isfinite(v); }))
          << n;
    EXPECT_GE(m.detail_level, detail_level) << "a longer prefix never gives a coarser level: " << n;
    detail_level = m.detail_level;
  }
  EXPECT_EQ(detail_level, 5);
}

// Single-bit flips all over a pack with per-patch streams (every bit of the header and manifest, then a
// deterministic spread of ~2000 bits over the chunks and their CRC trailers): the header and manifest are
// refused (no models); a flip in a chunk or trailer is kCorrupt and decodes exactly to the prefix before its
// CRC group — a valid coarser model, watertight.
TEST(PackPerPatch, EverySingleBitFlipIsRefusedOrACoarserModel) {
  const std::vector<std::uint8_t> pack = per_patch_pack();
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  std::vector<std::size_t> bits;
  for (std::size_t b = 0; b < 8 * info.manifest_end; ++b) bits.push_back(b);
  const std::size_t chunk_bits = 8 * (pack.size() - info.manifest_end);
  const std::size_t stride = std::max<std::size_t>(1, chunk_bits / 2000) | 1;  // odd: every bit position
  for (std::size_t b = 8 * info.manifest_end; b < 8 * pack.size(); b += stride) bits.push_back(b);
  for (const ChunkInfo& c : info.chunks)  // every trailer's first and last bit
    if (c.crc_bytes)
      bits.insert(bits.end(), {8 * (c.offset + c.payload_size()), 8 * (c.offset + c.size) - 1});
  std::map<std::size_t, PackDecodeResult> coarser;  // by group: the prefix that ends before it
  for (std::size_t bit : bits) {
    std::vector<std::uint8_t> bad = pack;
    const std::size_t at = bit / 8;
    bad[at] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    const PackDecodeResult r = decode_pack(bad, {.max_threads = 1});
    ASSERT_NE(r.status, Status::kOk) << "bit " << bit;
    if (at < info.manifest_end) {
      ASSERT_TRUE(r.models.empty()) << "bit " << bit;
      continue;
    }
    ASSERT_EQ(r.status, Status::kCorrupt) << "bit " << bit;
    const auto chunk = std::find_if(info.chunks.begin(), info.chunks.end(),
                                    [&](const ChunkInfo& c) { return at < c.offset + c.size; });
    ASSERT_NE(chunk, info.chunks.end());
    const std::size_t first = chunk->group_first;
    EXPECT_EQ(r.chunks_decoded, first) << "bit " << bit;
    auto expected = coarser.find(first);
    if (expected == coarser.end())
      expected =
          coarser
              .emplace(first,
                       decode_pack(pack, {.max_bytes = static_cast<std::size_t>(info.chunks[first].offset),
                                          .partial_chunks = false,
                                          .max_threads = 1}))
              .first;
    ASSERT_EQ(r.models.size(), 1u) << "bit " << bit;
    const DecodedModel& m = r.models[0];
    EXPECT_EQ(seam_mismatches(m.geometry, m.seams), 0u) << "bit " << bit;
    for (std::size_t p = 0; p < m.geometry.size(); ++p)
      ASSERT_EQ(m.geometry[p].values, expected->second.models[0].geometry[p].values) << "bit " << bit;
  }
}

bool same_seams(const std::vector<PatchSeam>& a, const std::vector<PatchSeam>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const PatchSeam& x, const PatchSeam& y) {
    return x.patch == y.patch && x.side == y.side && x.other_patch == y.other_patch &&
           x.other_side == y.other_side && x.reversed == y.reversed;
  });
}

// Format 7's seam tables: a layout's mirrored table stored once per side pair, a table equal to the one just
// before (the normal maps', the next model's) as a reference, any other table listed; each reads back to
// the writer's table, and the prefixes stay watertight.
TEST(Pack, SeamTablesRoundTripInTheirCompactForms) {
  std::vector<PackModelInput> models = {pillow_model(3, "a", 1.0, true), pillow_model(3, "b", 2.0, true),
                                        pillow_model(3, "c")};
  models[2].seams.resize(4);  // patch 0's side of each seam only: not mirrored, listed
  const std::vector<std::uint8_t> pack = write_pack(models);
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  ASSERT_EQ(info.models.size(), 3u);
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_TRUE(same_seams(info.models[m].geometry.seams, models[m].seams)) << m;
    if (m < 2) {
      EXPECT_TRUE(same_seams(info.models[m].normals.seams, models[m].seams)) << m;
    }
  }
  for (std::size_t n = info.manifest_end; n <= pack.size(); n += 97) {
    const PackDecodeResult r = decode_pack(pack, {.max_bytes = n});
    for (const DecodedModel& model : r.models) EXPECT_EQ(seam_mismatches(model.geometry, model.seams), 0u);
  }

  // 40 patches glued at random: the mirrored form holds 80 pairs in about 8 bits each, where listing the 160
  // seams takes 3 bytes each (format 6).
  std::mt19937 rng(7);
  PackModelInput many;
  many.name = "k";
  for (int p = 0; p < 40; ++p) {
    Grid3 g{1, std::vector<float>(27)};
    for (float& v : g.values) v = static_cast<float>(rng() % 1000) / 1000.0f;
    many.geometry.push_back(g);
  }
  many.seams = random_layout_seams(40, rng);
  const std::vector<std::uint8_t> packed = write_pack({many, many}, geometry_only());
  ASSERT_EQ(read_pack_info(packed, info), Status::kOk);
  for (const PackModelInfo& model : info.models) EXPECT_TRUE(same_seams(model.geometry.seams, many.seams));
  // A byte count (deterministic for this seeded layout), not a time: under half of the listed form's bytes.
  const std::size_t listed_seam_bytes = 160 * 3;
  EXPECT_LT(info.manifest_end, listed_seam_bytes / 2);
  const PackDecodeResult r = decode_pack(packed);
  ASSERT_EQ(r.status, Status::kOk);
  for (const DecodedModel& model : r.models) EXPECT_EQ(seam_mismatches(model.geometry, model.seams), 0u);
}

// Every byte of a manifest changed (each bit flipped; set to 0, 1, 2, 255), the manifest CRC recomputed so
// the change reaches the parser (seam tables included: a partner given twice, a reference with nothing before
// it, a patch out of range, non-zero padding): refused, or read as a pack whose seams the decoder can use —
// never a crash.
TEST(Pack, ManifestByteChangesAreRefusedOrReadAsValid) {
  const std::vector<std::uint8_t> pack = write_pack({pillow_model(2, "a", 1.0, true)});
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  // Format 4 and later: magic (8), version (2), manifest size (varint), manifest CRC (4), manifest.
  std::size_t crc_at = 10;
  while (pack[crc_at] & 0x80) ++crc_at;
  ++crc_at;
  const std::size_t begin = crc_at + 4;
  ASSERT_LT(begin, info.manifest_end);
  int accepted = 0, refused = 0;
  for (std::size_t at = begin; at < info.manifest_end; ++at) {
    // Each single-bit flip, and the byte set to 0, 1, 2 and 255.
    std::vector<std::uint8_t> values = {0, 1, 2, 255};
    for (int b = 0; b < 8; ++b) values.push_back(static_cast<std::uint8_t>(pack[at] ^ (1 << b)));
    for (std::uint8_t v : values) {
      if (v == pack[at]) continue;
      std::vector<std::uint8_t> bad = pack;
      bad[at] = v;
      bad = relabel(std::move(bad), kPackVersion);  // the manifest CRC made to match the change
      PackInfo changed;
      if (read_pack_info(bad, changed) != Status::kOk) {
        ++refused;
        continue;
      }
      ++accepted;
      for (const PackModelInfo& model : changed.models)
        for (const PatchSeam& s : model.geometry.seams)
          ASSERT_TRUE(s.patch >= 0 && s.patch < model.geometry.num_patches && s.other_patch >= 0 &&
                      s.other_patch < model.geometry.num_patches && s.side >= 0 && s.side < 4 &&
                      s.other_side >= 0 && s.other_side < 4);
      // Decoded only when small (a changed level or patch count may ask for large grids, which is allowed).
      const bool small =
          std::all_of(changed.models.begin(), changed.models.end(), [](const PackModelInfo& m) {
            return m.geometry.num_patches <= 4 && m.geometry.level <= 3 &&
                   (!m.has_normals || m.normals.level <= 3);
          });
      if (small) decode_pack(bad, {.max_bytes = changed.manifest_end + 64});
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(accepted, 0);
}

/// Mean and largest angle (radians) between decoded and reference unit normals.
std::pair<double, double> normal_angles(const std::vector<Grid3>& decoded,
                                        const std::vector<Grid3>& reference) {
  double sum = 0, largest = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < reference.size(); ++p)
    for (std::size_t k = 0; k + 2 < reference[p].values.size(); k += 3, ++n) {
      const float *a = decoded[p].values.data() + k, *b = reference[p].values.data() + k;
      const double cx = double(a[1]) * b[2] - double(a[2]) * b[1],
                   cy = double(a[2]) * b[0] - double(a[0]) * b[2],
                   cz = double(a[0]) * b[1] - double(a[1]) * b[0];
      const double angle = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz),
                                      double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2]);
      sum += angle;
      largest = std::max(largest, angle);
    }
  return {sum / double(std::max<std::size_t>(n, 1)), largest};
}

// Two-layer normal maps (format 11): the manifest says so and where layer 1 ends; the whole pack's normals
// are on average at least as close to the maps as the xyz coding's (measured on this pillow: mean 0.0202°
// against 0.0256°, largest 0.092° against 0.083°), every byte prefix decodes to unit normals whose seam
// copies are bit-identical, and once layer 1 is complete no prefix is more than twice as far off as it.
TEST(PackNormalLayers, TwoLayersDecodeEveryPrefixToUnitSeamedNormals) {
  const PackModelInput model = pillow_model(5, "a", 1.0, true);
  PackWriteOptions one_layer;
  one_layer.normal_layers = 1;
  const std::vector<std::uint8_t> pack = write_pack({model}), plain = write_pack({model}, one_layer);
  PackInfo info, plain_info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  ASSERT_EQ(read_pack_info(plain, plain_info), Status::kOk);
  const PackModelInfo& mi = info.models.at(0);
  EXPECT_EQ(info.version, 11);
  ASSERT_EQ(mi.normal_layers, 2);
  EXPECT_EQ(plain_info.models.at(0).normal_layers, 1);
  EXPECT_GE(mi.normal_base_passes, 1);
  EXPECT_LT(mi.normal_base_passes, mi.normals.top_bitplane - mi.normals.bottom_bitplane + 1);
  EXPECT_TRUE(mi.normal_residual.seams.empty());
  EXPECT_EQ(mi.normal_residual.level, mi.normals.level);
  EXPECT_EQ(mi.normal_orientation.size(), 2u);
  std::size_t normal_chunks = 0;
  for (const ChunkInfo& c : info.chunks) normal_chunks += c.kind == ChunkKind::kNormals;
  EXPECT_EQ(normal_chunks, static_cast<std::size_t>(mi.normal_passes()));

  const PackDecodeResult whole = decode_pack(pack), xyz = decode_pack(plain);
  ASSERT_EQ(whole.status, Status::kOk);
  ASSERT_EQ(xyz.status, Status::kOk);
  const auto [mean2, max2] = normal_angles(whole.models.at(0).normals, model.normals);
  const auto [mean1, max1] = normal_angles(xyz.models.at(0).normals, model.normals);
  std::cout << "[ figures  ] two layers " << mean2 * 180 / M_PI << " / " << max2 * 180 / M_PI << ", xyz "
            << mean1 * 180 / M_PI << " / " << max1 * 180 / M_PI << "\n";
  EXPECT_LE(mean2, mean1) << "two layers: " << mean2 * 180 / M_PI << "°, xyz " << mean1 * 180 / M_PI << "°";
  EXPECT_LE(max2, 2 * max1);
  EXPECT_EQ(whole.models.at(0).geometry[0].values, xyz.models.at(0).geometry[0].values);

  // Layer 1 alone: the prefix that ends with its last chunk (layer 2's first chunk may come before it).
  const auto layer1_end = [&] {
    std::size_t end = 0;
    for (const ChunkInfo& c : info.chunks)
      if (c.kind == ChunkKind::kNormals && c.pass == mi.normal_base_passes - 1) end = c.offset + c.size;
    return end;
  }();
  double layer1_mean = 0;
  for (std::size_t n = info.manifest_end; n <= pack.size();
       n += std::max<std::size_t>(1, pack.size() / 400)) {
    const PackDecodeResult r = decode_pack(pack, {.max_bytes = n});
    ASSERT_NE(r.status, Status::kCorrupt) << n;
    ASSERT_EQ(r.models.size(), 1u) << n;
    const DecodedModel& m = r.models[0];
    if (m.normals.empty()) continue;
    for (const Grid3& g : m.normals)
      for (std::size_t k = 0; k + 2 < g.values.size(); k += 3) {
        const double len =
            std::sqrt(double(g.values[k]) * g.values[k] + double(g.values[k + 1]) * g.values[k + 1] +
                      double(g.values[k + 2]) * g.values[k + 2]);
        ASSERT_NEAR(len, 1.0, 1e-5) << "prefix " << n;
      }
    ASSERT_EQ(seam_mismatches(m.normals, mi.normals.seams), 0u) << "prefix " << n;
    const double mean = normal_angles(m.normals, model.normals).first;
    if (n >= layer1_end && layer1_mean == 0) layer1_mean = mean;
    if (layer1_mean > 0) {
      EXPECT_LE(mean, 2 * layer1_mean) << "prefix " << n;
    }
  }
  EXPECT_GT(layer1_mean, mean2);
}

// The committed golden packs (tests/data/golden-pillow.gip written by format version 1, golden-pillow-v2.gip
// by version 2, golden-pillow-v3.gip by version 3, golden-pillow-v4.gip by version 4, golden-pillow-v5.gip by
// version 5: codec header version 4, the lifting update; golden-pillow-v6.gip by version 6: codec header
// version 5, the filter kCubicLong; golden-pillow-v7.gip by version 7: compact seam tables;
// golden-pillow-v8.gip by version 8: codec header version 6, cell frames; golden-pillow-v9.gip by version 9:
// the two squares' seam table as a layout code; golden-pillow-v10.gip by version 10: codec header version 7,
// a bottom bit-plane 4 planes up; golden-pillow-v11.gip by version 11: two-layer normal maps) must keep
// decoding to
// the pillow they were made from: decoders of old streams do not silently change.
class GoldenPack : public ::testing::TestWithParam<std::pair<const char*, int>> {};

TEST_P(GoldenPack, Decodes) {
  const auto [file, version] = GetParam();
  std::ifstream in(std::string(GEOMIP_SOURCE_DIR) + "/tests/data/" + file, std::ios::binary);
  ASSERT_TRUE(in) << "missing tests/data/" << file;
  const std::vector<std::uint8_t> pack((std::istreambuf_iterator<char>(in)),
                                       std::istreambuf_iterator<char>());
  PackInfo info;
  ASSERT_EQ(read_pack_info(pack, info), Status::kOk);
  EXPECT_EQ(info.version, version);
  EXPECT_EQ(info.models.at(0).geometry.version, version >= 10  ? 7
                                                : version >= 8 ? 6
                                                : version >= 6 ? 5
                                                : version >= 5 ? 4
                                                               : std::min(version, 3));
  EXPECT_EQ(info.models.at(0).geometry.filter, version >= 6 ? WaveletFilter::kCubicLong : WaveletFilter::kCubic);
  EXPECT_EQ(info.models.at(0).geometry.lifting_update, version >= 5);
  EXPECT_EQ(info.models.at(0).geometry.bottom_bitplane, version >= 10 ? 4 : 0);
  const PackDecodeResult r = decode_pack(pack);
  ASSERT_EQ(r.status, Status::kOk);
  ASSERT_EQ(r.models.size(), 2u);
  const std::vector<PackModelInput> expected = {pillow_model(5, "a", 1.0, true),
                                                pillow_model(5, "b", 2.0, true)};
  for (std::size_t m = 0; m < 2; ++m) {
    EXPECT_EQ(r.models[m].name, expected[m].name);
    // Version 3 codes local frames: near-lossless (rotation rounding, tangential components one plane
    // coarser).
    EXPECT_LE(max_error(r.models[m].geometry, expected[m].geometry),
              (version >= 3 ? 8.0 : 1.0) * (m == 0 ? 2.0 : 4.0) / 16384.0);
    ASSERT_EQ(r.models[m].normals.size(), 2u);
    EXPECT_LE(max_error(r.models[m].normals, expected[m].normals), 4.0 / 1024);
    EXPECT_EQ(info.models[m].normal_layers, version >= 11 ? 2 : 1);
  }
  // Every prefix of the golden pack: a coarser model or a clean Truncated.
  for (std::size_t n = 0; n < pack.size(); n += 1 + n / 64) {
    const PackDecodeResult p = decode_pack(pack, {.max_bytes = n});
    EXPECT_EQ(p.status, Status::kTruncated) << n;
    for (const DecodedModel& model : p.models) EXPECT_EQ(seam_mismatches(model.geometry, model.seams), 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Versions, GoldenPack,
                         ::testing::Values(std::pair<const char*, int>{"golden-pillow.gip", 1},
                                           std::pair<const char*, int>{"golden-pillow-v2.gip", 2},
                                           std::pair<const char*, int>{"golden-pillow-v3.gip", 3},
                                           std::pair<const char*, int>{"golden-pillow-v4.gip", 4},
                                           std::pair<const char*, int>{"golden-pillow-v5.gip", 5},
                                           std::pair<const char*, int>{"golden-pillow-v6.gip", 6},
                                           std::pair<const char*, int>{"golden-pillow-v7.gip", 7},
                                           std::pair<const char*, int>{"golden-pillow-v8.gip", 8},
                                           std::pair<const char*, int>{"golden-pillow-v9.gip", 9},
                                           std::pair<const char*, int>{"golden-pillow-v10.gip", 10},
                                           std::pair<const char*, int>{"golden-pillow-v11.gip", 11}));

}  // namespace
}  // namespace geomip::codec
