// Property tests of codec/rd_curve.h: the upper envelope is the Pareto front, its staircase is monotone, and
// the CSV and SVG files are well formed.
#include "baselines/rd_curve.h"
#include "mesh/errors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <vector>

namespace geomip {
namespace {

RdPoint point(const std::string& method, std::size_t bytes, double psnr) {
  RdPoint p;
  p.method = method;
  p.bytes = bytes;
  p.psnr_db = psnr;
  return p;
}

bool dominates(const RdPoint& a, const RdPoint& b) {  // a at least as good in both, better in one
  return a.bytes <= b.bytes && a.psnr_db >= b.psnr_db && (a.bytes < b.bytes || a.psnr_db > b.psnr_db);
}
bool same(const RdPoint& a, const RdPoint& b) {
  return a.bytes == b.bytes && a.psnr_db == b.psnr_db;  // equal points: the envelope keeps one of them
}

std::vector<RdPoint> random_points(std::mt19937& rng, int n) {
  std::uniform_int_distribution<std::size_t> bytes(100, 400);  // narrow: many ties in bytes
  std::uniform_int_distribution<int> psnr(300, 800);           // tenths of dB: ties in PSNR too
  std::vector<RdPoint> points;
  for (int i = 0; i < n; ++i) points.push_back(point("m" + std::to_string(i), bytes(rng), psnr(rng) / 10.0));
  if (n > 3) points.push_back(points[1]);  // an exact duplicate
  return points;
}

TEST(UpperEnvelope, IsTheParetoFrontOfRandomPoints) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<RdPoint> points = random_points(rng, 1 + trial % 60);
    const std::vector<RdPoint> front = upper_envelope(points);
    ASSERT_FALSE(front.empty());
    // Sorted by bytes, PSNR strictly increasing.
    for (std::size_t i = 1; i < front.size(); ++i) {
      EXPECT_LT(front[i - 1].bytes, front[i].bytes);
      EXPECT_LT(front[i - 1].psnr_db, front[i].psnr_db);
    }
    for (const RdPoint& p : points) {
      bool kept = false;
      for (const RdPoint& f : front) kept = kept || same(f, p);
      bool dominated = false;
      for (const RdPoint& q : points) dominated = dominated || dominates(q, p);
      // Kept ⇔ not dominated (an exact duplicate of a kept point counts as kept).
      EXPECT_EQ(kept, !dominated) << p.bytes << " B " << p.psnr_db << " dB";
    }
    // Every dropped point is weakly beaten by a kept one.
    for (const RdPoint& p : points) {
      bool covered = false;
      for (const RdPoint& f : front) covered = covered || (f.bytes <= p.bytes && f.psnr_db >= p.psnr_db);
      EXPECT_TRUE(covered);
    }
  }
}

TEST(UpperEnvelope, KeepsOneOfEqualPointsAndHandlesEmptyInput) {
  EXPECT_TRUE(upper_envelope({}).empty());
  const auto front = upper_envelope({point("a", 10, 50), point("b", 10, 50), point("c", 5, 40)});
  ASSERT_EQ(front.size(), 2u);
  EXPECT_EQ(front[0].method, "c");
  EXPECT_EQ(front[1].method, "a");
}

TEST(EnvelopeAt, IsAMonotoneStaircase) {
  std::mt19937 rng(11);
  const std::vector<RdPoint> points = random_points(rng, 40);
  const std::vector<RdPoint> front = upper_envelope(points);
  EXPECT_TRUE(std::isinf(envelope_at(front, 0)));
  EXPECT_LT(envelope_at(front, 0), 0);
  double previous = -INFINITY;
  for (std::size_t b = 0; b <= 500; ++b) {
    const double v = envelope_at(front, b);
    EXPECT_GE(v, previous) << b;
    // The staircase of the front equals the best of all points within the budget.
    EXPECT_EQ(v, envelope_at(points, b)) << b;
    previous = v;
  }
  for (const RdPoint& f : front) EXPECT_EQ(envelope_at(front, f.bytes), f.psnr_db);
}

// The baseline is read between its points in log(bytes), never as the lower staircase (which scored Draco a
// few KB short of the size and overstated geomip's margin in `geomip rd`'s table by up to 1.7 dB).
TEST(EnvelopeInterpolated, IsLogLinearBetweenPointsAndNeverBelowTheStaircase) {
  const std::vector<RdPoint> front =
      upper_envelope({point("a", 1000, 50), point("b", 4000, 60), point("c", 16000, 64)});
  EXPECT_TRUE(std::isinf(envelope_interpolated(front, 999)));
  EXPECT_LT(envelope_interpolated(front, 999), 0);
  EXPECT_EQ(envelope_interpolated(front, 1000), 50);
  EXPECT_EQ(envelope_interpolated(front, 4000), 60);
  EXPECT_NEAR(envelope_interpolated(front, 2000), 55, 1e-12);  // the geometric mean of 1000 and 4000
  EXPECT_NEAR(envelope_interpolated(front, 8000), 62, 1e-12);
  EXPECT_EQ(envelope_interpolated(front, 100000), 64);
  std::mt19937 rng(12);
  const std::vector<RdPoint> random_front = upper_envelope(random_points(rng, 40));
  double previous = -INFINITY;
  for (std::size_t b = 0; b <= 600; ++b) {
    const double v = envelope_interpolated(random_front, b);
    EXPECT_GE(v, previous) << b;
    EXPECT_GE(v, envelope_at(random_front, b)) << b;
    previous = v;
  }
  for (const RdPoint& f : random_front) EXPECT_EQ(envelope_interpolated(random_front, f.bytes), f.psnr_db);
}

// Tag balance of an XML text: every <x ...> closed by </x> in order, self-closing tags and the prolog
// skipped.
bool balanced_tags(const std::string& xml, std::string& why) {
  std::vector<std::string> stack;
  std::size_t i = 0;
  while ((i = xml.find('<', i)) != std::string::npos) {
    const std::size_t end = xml.find('>', i);
    if (end == std::string::npos) {
      why = "unterminated tag";
      return false;
    }
    std::string tag = xml.substr(i + 1, end - i - 1);
    i = end + 1;
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    if (tag.back() == '/') continue;
    const bool closing = tag[0] == '/';
    std::string name = tag.substr(closing ? 1 : 0);
    name = name.substr(0, name.find_first_of(" \t\n"));
    if (!closing) {
      stack.push_back(name);
    } else if (stack.empty() || stack.back() != name) {
      why = "</" + name + "> does not close " + (stack.empty() ? "anything" : "<" + stack.back() + ">");
      return false;
    } else {
      stack.pop_back();
    }
  }
  if (!stack.empty()) why = "<" + stack.back() + "> never closed";
  return stack.empty();
}

std::vector<RdPoint> sample_curve() {
  std::vector<RdPoint> points;
  for (int q = 6; q <= 12; ++q) points.push_back(point("draco", 15000 + 2000 * q, 40 + 3.5 * q));
  for (int f = 1; f <= 5; ++f) points.push_back(point("draco_qem", 1000 * f, 50 + 4.0 * f));
  points.push_back(point("meshopt", 60000, 95.5));
  points.push_back(point("a<b&\"c\"", 3000, 61));     // a method name that needs escaping
  points.push_back(point("draco", 0, 30));            // not plottable: zero bytes
  points.push_back(point("draco", 99000, INFINITY));  // not plottable: lossless
  return points;
}

TEST(RdFiles, CsvHasTheHeaderAndOneRowPerPoint) {
  const std::vector<RdPoint> points = sample_curve();
  std::ostringstream out;
  write_rd_csv(out, points);
  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("method,bytes,psnr_db,hausdorff_pct,decode_ms", 0), 0u) << line;
  const auto columns = std::count(line.begin(), line.end(), ',');
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    if (line.find('"') == std::string::npos) {
      EXPECT_EQ(std::count(line.begin(), line.end(), ','), columns) << line;
    }
  }
  EXPECT_EQ(rows, points.size());
  EXPECT_NE(out.str().find(",inf,"), std::string::npos);
  EXPECT_NE(out.str().find("\"a<b&\"\"c\"\"\""), std::string::npos);
}

TEST(RdFiles, SvgIsBalancedAndHasEverySeries) {
  std::ostringstream out;
  write_rd_svg(out, sample_curve());
  const std::string svg = out.str();
  std::string why;
  EXPECT_TRUE(balanced_tags(svg, why)) << why;
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  for (const char* method : {"draco", "draco_qem", "meshopt", "a&lt;b&amp;&quot;c&quot;"})
    EXPECT_NE(svg.find(std::string("data-method=\"") + method + "\""), std::string::npos) << method;
  EXPECT_EQ(svg.find("a<b"), std::string::npos);  // escaped everywhere
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  EXPECT_NE(svg.find("PSNR (dB)"), std::string::npos);
  EXPECT_NE(svg.find("size (kB = 1000 bytes, log scale)"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
  // 7 + 5 + 1 + 1 plotted points and one legend marker per series (4).
  std::size_t circles = 0;
  for (std::size_t i = 0; (i = svg.find("<circle", i)) != std::string::npos; ++i) ++circles;
  EXPECT_EQ(circles, 14u + 4u);

  // Nothing plottable (zero bytes, or every PSNR infinite as on a flat mesh): a valid SVG that says so, no
  // series, no "inf" or "nan" in it.
  std::ostringstream empty;
  write_rd_svg(empty, {point("x", 0, 10), point("y", 100, INFINITY)});
  const std::string nothing = empty.str();
  EXPECT_EQ(nothing.rfind("<?xml", 0), 0u);
  EXPECT_NE(nothing.find("nothing to plot"), std::string::npos) << nothing;
  EXPECT_EQ(nothing.find("data-method"), std::string::npos) << nothing;
  EXPECT_EQ(nothing.find("inf"), std::string::npos) << nothing;
  EXPECT_EQ(nothing.find("nan"), std::string::npos) << nothing;
  EXPECT_NE(nothing.find("</svg>"), std::string::npos);
}

}  // namespace
}  // namespace geomip
