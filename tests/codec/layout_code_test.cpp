// The layout code of pack format 9 (codec/layout_code.h): canonical orders and codes of closed genus-0
// quad layouts round-trip, other tables get none, damaged codes are refused, and a pack written in
// canonical order decodes to the same surface with its patches renumbered and turned.
#include "codec/layout_code.h"

#include "codec/pack.h"
#include "tests/codec/pillow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <random>
#include <tuple>

namespace geomip::codec {
namespace {

using test::cube_quads;
using test::Quad;
using test::seams_of;

/// An n × m quad torus (genus 1).
std::vector<Quad> torus_quads(int n, int m) {
  std::vector<Quad> quads;
  const auto v = [&](int i, int j) { return (j % m) * n + (i % n); };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) quads.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
  return quads;
}

/// The quads renumbered at random and each turned by a random number of corners.
std::vector<Quad> shuffled(std::vector<Quad> quads, std::mt19937& rng) {
  std::shuffle(quads.begin(), quads.end(), rng);
  for (Quad& q : quads) std::rotate(q.begin(), q.begin() + rng() % 4, q.end());
  return quads;
}

/// Checks that `canonical` is `input` seen through `order`: canonical side (c, s) is input side
/// (patch[c], s + rotation[c]), and the same pairs are glued.
void expect_same_layout(const std::vector<PatchSeam>& input, const std::vector<PatchSeam>& canonical,
                        const LayoutOrder& order) {
  ASSERT_EQ(input.size(), canonical.size());
  std::vector<int> seen(order.patch);
  std::sort(seen.begin(), seen.end());
  for (std::size_t i = 0; i < seen.size(); ++i)
    ASSERT_EQ(seen[i], static_cast<int>(i)) << "not a permutation";
  const auto to_input = [&](int c, int s) {
    return std::pair{order.patch[static_cast<std::size_t>(c)],
                     (s + order.rotation[static_cast<std::size_t>(c)]) % 4};
  };
  for (const PatchSeam& s : canonical) {
    EXPECT_TRUE(s.reversed);
    const auto [p, side] = to_input(s.patch, s.side);
    const auto [q, other] = to_input(s.other_patch, s.other_side);
    const PatchSeam& in = input[static_cast<std::size_t>(4 * p + side)];
    EXPECT_EQ(in.other_patch, q);
    EXPECT_EQ(in.other_side, other);
  }
}

TEST(LayoutCode, CubesRoundTripInAnyOrder) {
  std::mt19937 rng(7);
  for (int n : {1, 2, 3, 5}) {
    for (int trial = 0; trial < 8; ++trial) {
      const std::vector<PatchSeam> seams = seams_of(shuffled(cube_quads(n), rng));
      ASSERT_FALSE(seams.empty());
      const int patches = static_cast<int>(seams.size() / 4);
      const auto order = layout_order(seams, patches);
      ASSERT_TRUE(order.has_value()) << "cube " << n;
      std::vector<PatchSeam> canonical;
      std::size_t used = 0;
      ASSERT_TRUE(read_layout_code(order->code, patches, canonical, used));
      EXPECT_EQ(used, order->code.size());
      expect_same_layout(seams, canonical, *order);
      // The canonical table is its own canonical order, with the same code.
      const auto again = layout_order(canonical, patches);
      ASSERT_TRUE(again.has_value());
      EXPECT_TRUE(again->identity());
      EXPECT_EQ(again->code, order->code);
      // A few bits per quad, far under format 7's side-pair form (≥ 3 bits per side pair).
      EXPECT_LE(order->code.size() * 8, static_cast<std::size_t>(6 * patches + 8)) << "cube " << n;
    }
  }
}

TEST(LayoutCode, TwoSquaresAreCanonicalAlready) {
  const test::Pillow pillow = test::make_pillow(3);
  const auto order = layout_order(pillow.seams, 2);
  ASSERT_TRUE(order.has_value());
  EXPECT_TRUE(order->identity());
  EXPECT_EQ(order->code.size(), 1u);
}

TEST(LayoutCode, OtherTablesHaveNoCode) {
  // Genus 1: the traversal would need a merge across two cycles.
  EXPECT_FALSE(layout_order(seams_of(torus_quads(4, 3)), 12).has_value());
  // Two cubes side by side in one table: not connected.
  std::vector<Quad> two = cube_quads(1);
  for (Quad q : cube_quads(1)) {
    for (int& c : q) c += 100;
    two.push_back(q);
  }
  EXPECT_FALSE(layout_order(seams_of(two), 12).has_value());
  // A side glued without reversal (not an oriented surface), and random side pairings.
  std::vector<PatchSeam> flipped = seams_of(cube_quads(1));
  flipped[0].reversed = false;
  flipped[static_cast<std::size_t>(4 * flipped[0].other_patch + flipped[0].other_side)].reversed = false;
  EXPECT_FALSE(layout_order(flipped, 6).has_value());
  // A table of the wrong size or out of order.
  std::vector<PatchSeam> cube = seams_of(cube_quads(1));
  EXPECT_FALSE(layout_order(cube, 5).has_value());
  std::swap(cube[0], cube[1]);
  EXPECT_FALSE(layout_order(cube, 6).has_value());
  // Random pairings: whatever has a code reads back as itself.
  std::mt19937 rng(11);
  int coded = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int patches = 1 + static_cast<int>(rng() % 12);
    std::vector<PatchSeam> random = test::random_layout_seams(patches, rng);
    for (PatchSeam& s : random) s.reversed = true;
    const auto order = layout_order(random, patches);
    if (!order) continue;
    std::vector<PatchSeam> canonical;
    std::size_t used = 0;
    ASSERT_TRUE(read_layout_code(order->code, patches, canonical, used));
    expect_same_layout(random, canonical, *order);
    ++coded;
  }
  EXPECT_GT(coded, 10);  // some random gluings are spheres
}

TEST(LayoutCode, DamagedCodesAreRefusedOrReadAsALayout) {
  std::mt19937 rng(3);
  const std::vector<PatchSeam> seams = seams_of(shuffled(cube_quads(4), rng));
  const int patches = static_cast<int>(seams.size() / 4);
  const auto order = layout_order(seams, patches);
  ASSERT_TRUE(order.has_value());
  std::vector<PatchSeam> out;
  std::size_t used = 0;
  // Every truncation is refused (the code ends only where its last cycle closes).
  for (std::size_t n = 0; n < order->code.size(); ++n)
    EXPECT_FALSE(read_layout_code(std::span(order->code).first(n), patches, out, used)) << n;
  // Extra bytes after the code are not read; the wrong patch count is refused.
  std::vector<std::uint8_t> longer = order->code;
  longer.push_back(0xFF);
  ASSERT_TRUE(read_layout_code(longer, patches, out, used));
  EXPECT_EQ(used, order->code.size());
  EXPECT_FALSE(read_layout_code(order->code, patches - 1, out, used));
  EXPECT_FALSE(read_layout_code(order->code, patches + 1, out, used));
  // Every single-bit flip: refused, or read as a closed genus-0 table in canonical order.
  for (std::size_t bit = 0; bit < 8 * order->code.size(); ++bit) {
    std::vector<std::uint8_t> bad = order->code;
    bad[bit / 8] = static_cast<std::uint8_t>(bad[bit / 8] ^ (1u << (bit % 8)));
    if (!read_layout_code(bad, patches, out, used)) continue;
    const auto check = layout_order(out, patches);
    ASSERT_TRUE(check.has_value()) << bit;
    EXPECT_TRUE(check->identity()) << bit;
  }
  // Random bytes never crash; whatever reads is a layout.
  int read = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> bytes(1 + rng() % 24);
    for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    const int k = 1 + static_cast<int>(rng() % 40);
    if (!read_layout_code(bytes, k, out, used)) continue;
    EXPECT_LE(used, bytes.size());
    const auto check = layout_order(out, k);
    ASSERT_TRUE(check.has_value());
    EXPECT_TRUE(check->identity());
    ++read;
  }
  EXPECT_GT(read, 0);  // small layouts take few bits: random bytes are sometimes one
  // A huge patch count with a few bytes is refused before anything is allocated for it.
  EXPECT_FALSE(read_layout_code(order->code, 1 << 30, out, used));
}

TEST(LayoutCode, TurnsMoveSidesAsTheSeamConventionSays) {
  const int level = 3, n = (1 << level) + 1;
  Grid3 g;
  g.level = level;
  g.values.resize(3 * static_cast<std::size_t>(n) * n);
  std::iota(g.values.begin(), g.values.end(), 0.f);
  for (int turn = 0; turn < 4; ++turn) {
    const Grid3 r = rotate_grid(g, turn);
    for (int s = 0; s < 4; ++s) {
      for (int k = 0; k < n; ++k) {
        int i, j, ri, rj;
        test::side_sample(level, (s + turn) % 4, k, i, j);  // input side s + turn …
        test::side_sample(level, s, k, ri, rj);             // … is side s of the turned grid
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(r.values[static_cast<std::size_t>(3 * (rj * n + ri) + c)],
                    g.values[static_cast<std::size_t>(3 * (j * n + i) + c)]);
      }
    }
    // The quad mask turns with the samples: quad (qi, qj) of the turned mask has the turned grid's samples.
    std::vector<std::uint8_t> mask(static_cast<std::size_t>((n - 1) * (n - 1)), 0);
    mask[5] = 1;  // quad (5, 0)
    const std::vector<std::uint8_t> rm = rotate_quad_mask(mask, turn);
    const auto at = [&](const Grid3& grid, int i, int j) {
      return grid.values[static_cast<std::size_t>(3 * (j * n + i))];
    };
    const auto found = std::find(rm.begin(), rm.end(), 1);
    ASSERT_NE(found, rm.end());
    const int q = static_cast<int>(found - rm.begin()), qi = q % (n - 1), qj = q / (n - 1);
    std::vector<float> before{at(g, 5, 0), at(g, 6, 0), at(g, 5, 1), at(g, 6, 1)};
    std::vector<float> after{at(r, qi, qj), at(r, qi + 1, qj), at(r, qi, qj + 1), at(r, qi + 1, qj + 1)};
    std::sort(before.begin(), before.end()), std::sort(after.begin(), after.end());
    EXPECT_EQ(before, after) << "turn " << turn;
  }
}

/// Smooth grids on a shuffled 2×2×2 cube layout (24 patches), the samples on each glued side equal.
std::vector<Grid3> cube_grids(const std::vector<Quad>& quads, int level) {
  // Each corner id gets a random point; a patch is the bilinear blend of its corners' points, so the samples
  // of a side depend only on its two corners and agree in both patches that share it.
  std::vector<Grid3> grids;
  const int n = (1 << level) + 1;
  std::mt19937 rng(5);
  std::map<int, std::array<double, 3>> corner;
  for (const Quad& q : quads)
    for (int c : q)
      if (!corner.count(c)) corner[c] = {0, 0, 0};
  for (auto& [id, p] : corner) {
    std::normal_distribution<double> d;
    p = {d(rng), d(rng), d(rng)};
  }
  for (const Quad& q : quads) {
    Grid3 g;
    g.level = level;
    g.values.resize(3 * static_cast<std::size_t>(n) * n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double u = static_cast<double>(i) / (n - 1), v = static_cast<double>(j) / (n - 1);
        for (int c = 0; c < 3; ++c) {
          const double x = (1 - u) * (1 - v) * corner[q[0]][c] + u * (1 - v) * corner[q[1]][c] +
                           u * v * corner[q[2]][c] + (1 - u) * v * corner[q[3]][c];
          g.values[static_cast<std::size_t>(3 * (j * n + i) + c)] = static_cast<float>(x);
        }
      }
    }
    grids.push_back(std::move(g));
  }
  return grids;
}

TEST(LayoutCode, CanonicalPackDecodesToTheSameSurfaceTurned) {
  std::mt19937 rng(9);
  const std::vector<Quad> quads = shuffled(cube_quads(2), rng);
  PackModelInput model;
  model.name = "cube";
  model.seams = seams_of(quads);
  model.geometry = cube_grids(quads, 4);
  ASSERT_EQ(test::seam_mismatches(model.geometry, model.seams), 0u);
  const int patches = static_cast<int>(quads.size());
  model.hole_mask.assign(static_cast<std::size_t>(patches), std::vector<std::uint8_t>(256, 0));
  model.hole_mask[3][17] = 1;
  PackWriteOptions options;
  options.normals = false;
  options.geometry.frame_steps = 0;  // lossless up to the quantization: the two decodes must agree exactly
  options.geometry.headroom_bits = 0;
  const std::vector<std::uint8_t> plain = write_pack({model}, options);
  options.canonical_layout = true;
  const std::vector<std::uint8_t> canonical = write_pack({model}, options);
  PackInfo plain_info, canonical_info;
  ASSERT_EQ(read_pack_info(plain, plain_info), Status::kOk);
  ASSERT_EQ(read_pack_info(canonical, canonical_info), Status::kOk);
  EXPECT_EQ(canonical_info.version, kPackVersion);
  // The table's code instead of one entry per side pair: the manifest shrinks.
  EXPECT_LT(canonical_info.manifest_end + 20, plain_info.manifest_end);
  const auto order = layout_order(model.seams, patches);
  ASSERT_TRUE(order.has_value());
  EXPECT_TRUE(layout_order(canonical_info.models[0].geometry.seams, patches)->identity());

  const PackDecodeResult a = decode_pack(plain), b = decode_pack(canonical);
  ASSERT_EQ(a.status, Status::kOk);
  ASSERT_EQ(b.status, Status::kOk);
  ASSERT_EQ(b.models[0].geometry.size(), static_cast<std::size_t>(patches));
  EXPECT_EQ(test::seam_mismatches(b.models[0].geometry, canonical_info.models[0].geometry.seams), 0u);
  for (int c = 0; c < patches; ++c) {
    const Grid3 turned =
        rotate_grid(a.models[0].geometry[static_cast<std::size_t>(order->patch[c])], order->rotation[c]);
    EXPECT_EQ(b.models[0].geometry[static_cast<std::size_t>(c)].values, turned.values) << "patch " << c;
    EXPECT_EQ(b.models[0].hole_mask[static_cast<std::size_t>(c)],
              rotate_quad_mask(a.models[0].hole_mask[static_cast<std::size_t>(order->patch[c])],
                               order->rotation[c]));
  }
}

}  // namespace
}  // namespace geomip::codec
