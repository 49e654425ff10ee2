// The fetch plan (stream_viewer/fetch_plan.h) on crafted manifests: valid CRC, lying chunk table. Properties:
// never more reserved than the source's real size, the laid-out total or kMaxPackBytes; refusals are one
// line; the committed golden pack plans exactly its own size. No display needed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "stream_viewer/fetch_plan.h"
#include "tests/viewer/crafted_pack.h"

namespace geomip::viewer {
namespace {

using testing::craft_pack;

std::vector<std::uint8_t> golden() {
  std::ifstream in(std::filesystem::path(GEOMIP_SOURCE_DIR) / "tests/data/golden-pillow-v2.gip",
                   std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// plan_fetch as the fetcher calls it: header first (against `available`), then exactly the manifest.
std::string plan(std::span<const std::uint8_t> bytes, std::uint64_t available, FetchPlan& out) {
  std::size_t manifest_end = 0;
  std::string e = check_pack_header(bytes.first(std::min<std::size_t>(bytes.size(), codec::kPackHeaderSize)),
                                    available, manifest_end);
  if (!e.empty()) return e;
  if (manifest_end > bytes.size()) return "truncated";
  return plan_fetch(bytes.first(manifest_end), available, out);
}

void expect_bounded(const FetchPlan& p, std::uint64_t available) {
  EXPECT_LE(p.buffer, p.total);
  EXPECT_LE(p.buffer, kMaxPackBytes);
  EXPECT_LE(p.buffer, available);
  EXPECT_GE(p.buffer, p.info.manifest_end);
}

TEST(FetchPlan, GoldenPackPlansItsOwnSize) {
  const auto bytes = golden();
  ASSERT_FALSE(bytes.empty());
  FetchPlan p;
  EXPECT_EQ(plan(bytes, bytes.size(), p), "");
  EXPECT_EQ(p.total, bytes.size());
  EXPECT_EQ(p.buffer, bytes.size());
  EXPECT_FALSE(p.truncated());
  EXPECT_EQ(plan(bytes, kUnknownSize, p), "");
  EXPECT_EQ(p.buffer, bytes.size());
  // a craft that changes nothing gives the same bytes back (the crafting itself is right)
  EXPECT_EQ(craft_pack(bytes, [](auto&) {}), bytes);
}

TEST(FetchPlan, ClaimsOverTheCapAreRefusedBeforeAnyAllocation) {
  const auto bytes = golden();
  for (std::uint64_t chunk : {std::uint64_t{0x7fffffff}, std::uint64_t{1} << 26}) {
    const auto crafted = craft_pack(bytes, [&](auto& s) {
      for (auto& v : s) v = chunk;
    });
    for (std::uint64_t available : {std::uint64_t(crafted.size()), kUnknownSize, std::uint64_t{1} << 40}) {
      FetchPlan p;
      const std::string e = plan(crafted, available, p);
      EXPECT_NE(e.find("over the viewer's limit"), std::string::npos) << e;
      EXPECT_EQ(e.find('\n'), std::string::npos);
      EXPECT_EQ(p.buffer, 0u);
    }
  }
}

TEST(FetchPlan, SizesPastTheEndReserveOnlyTheRealSize) {
  const auto bytes = golden();
  const auto crafted = craft_pack(bytes, [](auto& s) {
    s.back() += 100u << 20;
    s.front() += 7;
  });
  FetchPlan p;
  ASSERT_EQ(plan(crafted, crafted.size(), p), "");
  EXPECT_TRUE(p.truncated());
  EXPECT_EQ(p.buffer, crafted.size());
  expect_bounded(p, crafted.size());
  // the server tells a smaller size (Content-Length): that is all that is reserved
  ASSERT_EQ(plan(crafted, crafted.size() / 2, p), "");
  EXPECT_EQ(p.buffer, crafted.size() / 2);
  // unknown size: the laid-out total, under the cap
  ASSERT_EQ(plan(crafted, kUnknownSize, p), "");
  EXPECT_EQ(p.buffer, p.total);
  expect_bounded(p, kUnknownSize);
}

TEST(FetchPlan, ZeroLengthChunksAndBadCountsAreHandled) {
  const auto bytes = golden();
  FetchPlan p;
  const auto zero = craft_pack(bytes, [](auto& s) {
    for (auto& v : s) v = 0;
  });
  ASSERT_EQ(plan(zero, zero.size(), p), "");  // plannable; the decoder then finds no geometry (exit 2)
  EXPECT_EQ(p.total, p.info.manifest_end);
  expect_bounded(p, zero.size());
  for (std::int64_t delta : {std::int64_t{1}, std::int64_t{-1}, std::int64_t{1'000'000'000}}) {
    const auto counted = craft_pack(
        bytes, [](auto&) {}, delta);
    const std::string e = plan(counted, counted.size(), p);
    EXPECT_NE(e.find("not a readable .gip pack"), std::string::npos) << delta << ": " << e;
    EXPECT_EQ(p.buffer, 0u);
  }
}

TEST(FetchPlan, ManifestPastTheSourceOrBadHeaderIsOneLine) {
  const auto bytes = golden();
  FetchPlan p;
  std::size_t manifest_end = 0;
  std::string e = check_pack_header(std::span(bytes).first(codec::kPackHeaderSize), 100, manifest_end);
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  e = check_pack_header(std::span(bytes).first(5), 5, manifest_end);
  EXPECT_NE(e.find("not a .gip pack"), std::string::npos) << e;
  // A format-4 header (magic, version 4, varint manifest size 2, CRC: 15 bytes) announcing a 2-byte manifest:
  // it would end inside the first read.
  const std::vector<std::uint8_t> tiny = {'G', 'E', 'O', 'M', 'I', 'P', 'K', 0x1a, 4, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  e = check_pack_header(tiny, tiny.size(), manifest_end);
  EXPECT_NE(e.find("manifest ends at byte"), std::string::npos) << e;
  EXPECT_EQ(manifest_end, 0u);
  std::vector<std::uint8_t> text(64, 'x');
  e = plan(text, text.size(), p);
  EXPECT_NE(e.find("not a .gip pack"), std::string::npos) << e;
  // every prefix of the golden pack: refused with one line or planned within its size, never more
  for (std::size_t n = 0; n <= bytes.size(); n += 7) {
    const std::span<const std::uint8_t> prefix(bytes.data(), n);
    const std::string r = plan(prefix, n, p);
    if (r.empty())
      expect_bounded(p, n);
    else
      EXPECT_EQ(r.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace geomip::viewer
