#include "codec/bitplane_coder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "codec/wavelet.h"

namespace geomip::codec {
namespace {

/// Wavelet coefficients of smooth random-ish fields plus noise, `np` patches.
std::vector<PatchCoefficients> smooth_coefficients(int level, int steps, int np, std::uint32_t seed) {
  const int n = (1 << level) + 1;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 3);
  std::vector<PatchCoefficients> out(np);
  for (int p = 0; p < np; ++p) {
    for (int c = 0; c < 3; ++c) {
      auto& g = out[p][c];
      g.resize(static_cast<std::size_t>(n) * n);
      const double fx = 1 + c + p, fy = 2 + 0.5 * c;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const double u = static_cast<double>(i) / (n - 1), v = static_cast<double>(j) / (n - 1);
          g[j * n + i] = static_cast<std::int32_t>(std::lround(
              30000 * std::sin(fx * u + 0.3 * c) * std::cos(fy * v) + 20000 * u * v + noise(rng)));
        }
      }
      wavelet_forward(g, level, steps, WaveletFilter::kCubic);
    }
  }
  return out;
}

std::vector<std::vector<std::uint8_t>> all_coded(int level, int np) {
  const std::size_t n = (std::size_t{1} << level) + 1;
  return std::vector<std::vector<std::uint8_t>>(np, std::vector<std::uint8_t>(n * n, 1));
}

std::vector<std::span<const std::uint8_t>> spans(const std::vector<std::vector<std::uint8_t>>& segs,
                                                 std::size_t k) {
  std::vector<std::span<const std::uint8_t>> out;
  for (std::size_t i = 0; i < k; ++i) out.emplace_back(segs[i]);
  return out;
}

double squared_error(const std::vector<PatchCoefficients>& a, const std::vector<PatchCoefficients>& b) {
  double e = 0;
  for (std::size_t p = 0; p < a.size(); ++p) {
    for (int c = 0; c < 3; ++c) {
      for (std::size_t i = 0; i < a[p][c].size(); ++i) {
        const double d = static_cast<double>(a[p][c][i]) - b[p][c][i];
        e += d * d;
      }
    }
  }
  return e;
}

/// The stream layouts: one joint stream (version 1); per-patch streams from the first plane; the first two
/// planes joint, then per patch.
std::vector<BitplaneLayout> layouts(int level, int steps, int np) {
  return {{level, steps, np, false, 0}, {level, steps, np, true, 0}, {level, steps, np, true, 2}};
}

TEST(BitplaneCoder, AllSegmentsAreLossless) {
  for (int level : {0, 1, 2, 3, 5, 7}) {
    for (int steps : {0, level / 2, level}) {
      for (const BitplaneLayout& layout : layouts(level, steps, 2)) {
        const auto coefs =
            smooth_coefficients(level, steps, 2, static_cast<std::uint32_t>(level * 10 + steps));
        const auto coded = all_coded(level, 2);
        const auto enc = encode_bitplanes(layout, coefs, coded);
        ASSERT_EQ(enc.segments.size(), static_cast<std::size_t>(enc.top_bitplane) + 1);
        std::vector<PatchCoefficients> out;
        BitplaneDecodeResult r;
        const auto segs = spans(enc.segments, enc.segments.size());
        ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, {}, out, r), Status::kOk);
        EXPECT_EQ(r.segments_complete, enc.segments.size());
        EXPECT_EQ(squared_error(out, coefs), 0) << "level " << level << " steps " << steps;
      }
    }
  }
}

TEST(BitplaneCoder, JointBytesChoosesTheFork) {
  const int level = 6;
  const auto coefs = smooth_coefficients(level, level, 2, 41);
  const auto coded = all_coded(level, 2);
  for (std::size_t joint_bytes :
       {std::size_t{1}, std::size_t{200}, std::size_t{1000}, std::size_t{1} << 30}) {
    BitplaneLayout layout{level, level, 2, true, 0};
    const auto enc = encode_bitplanes(layout, coefs, coded, joint_bytes);
    // The fork follows the first plane at which the joint segments hold joint_bytes (or never happens).
    std::size_t before = 0;
    for (int t = 0; t + 1 < enc.joint_segments; ++t)
      before += enc.segments[static_cast<std::size_t>(t)].size();
    EXPECT_LT(before, joint_bytes);
    if (enc.joint_segments < static_cast<int>(enc.segments.size())) {
      EXPECT_GE(before + enc.segments[static_cast<std::size_t>(enc.joint_segments - 1)].size(), joint_bytes);
    }
    layout.joint_segments = enc.joint_segments;
    std::vector<PatchCoefficients> out;
    BitplaneDecodeResult r;
    ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, spans(enc.segments, enc.segments.size()), {},
                               out, r),
              Status::kOk);
    EXPECT_EQ(squared_error(out, coefs), 0) << joint_bytes;
  }
}

TEST(BitplaneCoder, UncodedSamplesDecodeAsZeroAndDoNotDisturbOthers) {
  const int level = 5, n = 33;
  const BitplaneLayout layout{level, level, 2};
  auto coefs = smooth_coefficients(level, level, 2, 9);
  auto coded = all_coded(level, 2);
  std::mt19937 rng(1);
  for (auto& m : coded) {
    for (auto& v : m) v = (rng() % 4) != 0;
  }
  const auto enc = encode_bitplanes(layout, coefs, coded);
  std::vector<PatchCoefficients> out;
  BitplaneDecodeResult r;
  const auto segs = spans(enc.segments, enc.segments.size());
  ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, {}, out, r), Status::kOk);
  for (int p = 0; p < 2; ++p) {
    for (int c = 0; c < 3; ++c) {
      for (int i = 0; i < n * n; ++i) {
        ASSERT_EQ(out[p][c][i], coded[p][i] ? coefs[p][c][i] : 0);
      }
    }
  }
}

TEST(BitplaneCoder, ErrorNeverIncreasesWithMoreBytes) {
  const int level = 6;
  const BitplaneLayout layout{level, level, 2};
  const auto coefs = smooth_coefficients(level, level, 2, 3);
  const auto coded = all_coded(level, 2);
  const auto enc = encode_bitplanes(layout, coefs, coded);
  double previous = INFINITY;
  for (std::size_t k = 0; k <= enc.segments.size(); ++k) {
    std::vector<PatchCoefficients> out;
    BitplaneDecodeResult r;
    const auto segs = spans(enc.segments, k);
    ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, {}, out, r), Status::kOk);
    const double e = squared_error(out, coefs);
    EXPECT_LE(e, previous) << k << " segments";
    previous = e;
  }
  EXPECT_EQ(previous, 0);
}

TEST(BitplaneCoder, EveryPrefixDecodesExactlyTheCodedBits) {
  // Each decoded coefficient lies in the uncertainty interval of the true one: its known bits are right, so
  // |decoded − true| < 2^q ≤ |true| + ... ; simplest strong check: sign agrees and the error is below the
  // true magnitude's interval width, i.e. decoded coefficients never have the wrong sign or a wrong known
  // bit.
  const int level = 4;
  for (const BitplaneLayout& layout : layouts(level, level, 2)) {
    const auto coefs = smooth_coefficients(level, level, 2, 5);
    const auto coded = all_coded(level, 2);
    const auto enc = encode_bitplanes(layout, coefs, coded);
    for (std::size_t k = 0; k < enc.segments.size(); ++k) {
      const auto segs = spans(enc.segments, k);
      for (std::size_t len = 0; len <= enc.segments[k].size(); ++len) {
        std::vector<PatchCoefficients> out;
        BitplaneDecodeResult r;
        const std::span<const std::uint8_t> tail(enc.segments[k].data(), len);
        ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, tail, out, r), Status::kOk);
        for (int p = 0; p < 2; ++p) {
          for (int c = 0; c < 3; ++c) {
            for (std::size_t i = 0; i < out[p][c].size(); ++i) {
              const std::int64_t d = out[p][c][i], t = coefs[p][c][i];
              if (d != 0) {
                ASSERT_TRUE((d > 0) == (t > 0)) << "wrong sign";
                ASSERT_LE(std::abs(d - t), std::abs(t)) << "decoded value outside the true interval";
              }
            }
          }
        }
      }
    }
  }
}

// Per-patch streams decode on several threads; the result must not depend on how many.
TEST(BitplaneCoder, ThreadCountDoesNotChangeAnyPrefix) {
  const int level = 5, np = 3;
  const BitplaneLayout layout{level, level, np, true, 3};
  const auto coefs = smooth_coefficients(level, level, np, 21);
  const auto coded = all_coded(level, np);
  const auto enc = encode_bitplanes(layout, coefs, coded);
  for (std::size_t k = 0; k < enc.segments.size(); ++k) {
    const auto segs = spans(enc.segments, k);
    for (std::size_t len = 0; len <= enc.segments[k].size(); len += 1 + len / 8) {
      const std::span<const std::uint8_t> tail(enc.segments[k].data(), len);
      std::vector<PatchCoefficients> one, many;
      BitplaneDecodeResult r1, r4;
      ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, tail, one, r1, 1), Status::kOk);
      ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, tail, many, r4, 4), Status::kOk);
      ASSERT_EQ(squared_error(one, many), 0) << k << " segments + " << len << " bytes";
      ASSERT_EQ(r1.segments_complete, r4.segments_complete);
      ASSERT_EQ(r1.partial, r4.partial);
    }
  }
}

TEST(BitplaneCoder, APrefixOfASegmentFeedsEveryPatchAlike) {
  // Two identical patches: identical streams, so a prefix holding 2k of a segment's stream bytes must give
  // each patch k of them (interleaved by size), and both patches decode to the same coefficients. A
  // patch-major layout (stream 0, then stream 1) would give patch 0 everything first.
  const int level = 5;
  const BitplaneLayout layout{level, level, 2, true};
  auto coefs = smooth_coefficients(level, level, 2, 31);
  coefs[1] = coefs[0];
  const auto coded = all_coded(level, 2);
  const auto enc = encode_bitplanes(layout, coefs, coded);
  std::size_t checked = 0;
  for (std::size_t t = 0; t < enc.segments.size(); ++t) {
    const auto& seg = enc.segments[t];
    std::size_t header = 0;
    for (int v = 0; v < 2; ++v) {
      while (seg[header] & 0x80) ++header;
      ++header;
    }
    for (std::size_t len = header + 2; len < seg.size(); len += 2) {
      std::vector<PatchCoefficients> out;
      BitplaneDecodeResult r;
      ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, spans(enc.segments, t),
                                 std::span<const std::uint8_t>(seg.data(), len), out, r),
                Status::kOk);
      ASSERT_EQ(out[0], out[1]) << "segment " << t << ", prefix " << len;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20u);
}

// A segment whose stream sizes claim more bytes than it has is corrupt; the planes before it still decode.
TEST(BitplaneCoder, StreamSizesBeyondTheSegmentAreCorrupt) {
  const int level = 4;
  const BitplaneLayout layout{level, level, 2, true};
  const auto coefs = smooth_coefficients(level, level, 2, 8);
  const auto coded = all_coded(level, 2);
  auto enc = encode_bitplanes(layout, coefs, coded);
  const std::size_t bad = enc.segments.size() / 2;
  auto& seg = enc.segments[bad];
  // Replace patch 0's size varint with one larger than the whole segment.
  std::size_t varint_len = 0;
  while (seg[varint_len] & 0x80) ++varint_len;
  seg.erase(seg.begin(), seg.begin() + static_cast<std::ptrdiff_t>(varint_len + 1));
  const std::uint64_t big = seg.size() + 100;
  seg.insert(seg.begin(), {static_cast<std::uint8_t>(big | 0x80), static_cast<std::uint8_t>(big >> 7)});
  std::vector<PatchCoefficients> out, before;
  BitplaneDecodeResult r, rb;
  const auto segs = spans(enc.segments, enc.segments.size());
  EXPECT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, segs, {}, out, r), Status::kCorrupt);
  EXPECT_EQ(r.segments_complete, bad);
  ASSERT_EQ(decode_bitplanes(layout, enc.top_bitplane, coded, spans(enc.segments, bad), {}, before, rb),
            Status::kOk);
  EXPECT_EQ(squared_error(out, before), 0);
}

TEST(BitplaneCoder, GarbageNeverCrashes) {
  const int level = 5;
  for (const BitplaneLayout& layout : layouts(level, level, 2)) {
    const auto coded = all_coded(level, 2);
    std::mt19937 rng(77);
    for (int trial = 0; trial < 200; ++trial) {
      const int top = static_cast<int>(rng() % 50);
      std::vector<std::vector<std::uint8_t>> segs(rng() % 40);
      for (std::size_t t = 0; t < segs.size(); ++t) {
        auto& s = segs[t];
        s.resize(rng() % 200);
        for (auto& b : s) b = static_cast<std::uint8_t>(rng());
        // Half the per-patch segments get stream sizes that fit, so the garbage reaches the patch coders.
        if (layout.independent_patches && t >= static_cast<std::size_t>(layout.joint_segments) && rng() % 2) {
          const std::size_t a = rng() % (s.size() + 1), b = s.size() - a;
          const std::vector<std::uint8_t> head = {
              static_cast<std::uint8_t>(a | 0x80), static_cast<std::uint8_t>(a >> 7),
              static_cast<std::uint8_t>(b | 0x80), static_cast<std::uint8_t>(b >> 7)};
          s.insert(s.begin(), head.begin(), head.end());
        }
      }
      std::vector<std::uint8_t> tail(rng() % 50);
      for (auto& b : tail) b = static_cast<std::uint8_t>(rng());
      std::vector<PatchCoefficients> out;
      BitplaneDecodeResult r;
      const auto sp = spans(segs, segs.size());
      const Status st = decode_bitplanes(layout, top, coded, sp, tail, out, r);
      EXPECT_TRUE(st == Status::kOk || st == Status::kCorrupt);
      EXPECT_EQ(out.size(), 2u);
    }
  }
}

}  // namespace
}  // namespace geomip::codec
