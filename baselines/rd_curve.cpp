#include "baselines/rd_curve.h"

#include "mesh/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <ostream>
#include <string>

namespace geomip {
namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt("%.6g", v);
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

bool plottable(const RdPoint& p) {
  return p.bytes > 0 && std::isfinite(p.psnr_db);
}

}  // namespace

std::vector<RdPoint> upper_envelope(const std::vector<RdPoint>& points) {
  // Sort by bytes ascending, then PSNR descending, then input order; sweep keeping strict PSNR records.
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (points[a].bytes != points[b].bytes) return points[a].bytes < points[b].bytes;
    return points[a].psnr_db > points[b].psnr_db;
  });
  std::vector<RdPoint> front;
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i : order) {
    const RdPoint& p = points[i];
    if (std::isnan(p.psnr_db)) continue;
    if (front.empty() || p.psnr_db > best) {
      front.push_back(p);
      best = p.psnr_db;
    }
  }
  return front;
}

double envelope_at(const std::vector<RdPoint>& front, std::size_t bytes) {
  double best = -std::numeric_limits<double>::infinity();
  for (const RdPoint& p : front)
    if (p.bytes <= bytes && p.psnr_db > best) best = p.psnr_db;
  return best;
}

double envelope_interpolated(const std::vector<RdPoint>& front, std::size_t bytes) {
  const auto above = std::upper_bound(front.begin(), front.end(), bytes,
                                      [](std::size_t b, const RdPoint& p) { return b < p.bytes; });
  if (above == front.begin()) return -std::numeric_limits<double>::infinity();
  const RdPoint& lo = *(above - 1);
  if (above == front.end() || lo.bytes == bytes || lo.bytes == 0) return lo.psnr_db;
  const RdPoint& hi = *above;
  const double t = (std::log(static_cast<double>(bytes)) - std::log(static_cast<double>(lo.bytes))) /
                   (std::log(static_cast<double>(hi.bytes)) - std::log(static_cast<double>(lo.bytes)));
  return lo.psnr_db + t * (hi.psnr_db - lo.psnr_db);
}

void write_rd_csv(std::ostream& out, const std::vector<RdPoint>& points) {
  out << "method,bytes,psnr_db,hausdorff_pct,decode_ms,rms_pct,faces,vertices,quantization_bits,source\n";
  for (const RdPoint& p : points)
    out << csv_field(p.method) << ',' << p.bytes << ',' << number(p.psnr_db) << ',' << number(p.hausdorff_pct)
        << ',' << number(p.decode_ms) << ',' << number(p.rms_pct) << ',' << p.faces << ',' << p.vertices
        << ',' << p.quantization_bits << ',' << csv_field(p.source) << '\n';
}

void write_rd_svg(std::ostream& out, const std::vector<RdPoint>& points, const RdPlotOptions& options) {
  // Series in order of first appearance.
  std::vector<std::string> names;
  std::map<std::string, std::vector<RdPoint>> series;
  double kb_lo = INFINITY, kb_hi = -INFINITY, db_lo = INFINITY, db_hi = -INFINITY;
  for (const RdPoint& p : points) {
    if (!plottable(p)) continue;
    if (series.find(p.method) == series.end()) names.push_back(p.method);
    series[p.method].push_back(p);
    const double kb = static_cast<double>(p.bytes) / 1000.0;
    kb_lo = std::min(kb_lo, kb);
    kb_hi = std::max(kb_hi, kb);
    db_lo = std::min(db_lo, p.psnr_db);
    db_hi = std::max(db_hi, p.psnr_db);
  }
  if (names.empty()) {
    // Nothing to plot (e.g. a flat mesh: every coded copy lies on its surface, PSNR infinite): a valid SVG
    // that says so, so that a run's table and plot are still written as one set.
    const double W = options.width, H = options.height;
    out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
        << "\" viewBox=\"0 0 " << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect x=\"0\" y=\"0\" width=\"" << W << "\" height=\"" << H << "\" fill=\"white\"/>\n"
        << "<text x=\"" << W / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">"
        << xml_escape(options.title) << "</text>\n"
        << "<text x=\"" << W / 2 << "\" y=\"" << H / 2
        << "\" text-anchor=\"middle\">nothing to plot: no point has bytes &gt; 0 and a finite PSNR (every "
           "decoded mesh lies on the original's surface)</text>\n"
        << "</svg>\n";
    return;
  }

  // Axes: x in whole decades (log10), y in round steps.
  const double x0 = std::floor(std::log10(kb_lo)), x1 = std::max(x0 + 1, std::ceil(std::log10(kb_hi)));
  const double span = std::max(db_hi - db_lo, 1.0);
  const double raw_step = span / 8;
  double ystep = 1;
  for (double s : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0})
    if (s >= raw_step) {
      ystep = s;
      break;
    }
  const double y0 = std::floor(db_lo / ystep) * ystep,
               y1 = std::max(y0 + ystep, std::ceil(db_hi / ystep) * ystep);

  const double W = options.width, H = options.height;
  const double left = 70, right = 190, top = 40, bottom = 55;
  const double pw = W - left - right, ph = H - top - bottom;
  auto sx = [&](double kb) { return left + (std::log10(kb) - x0) / (x1 - x0) * pw; };
  auto sy = [&](double db) { return top + (y1 - db) / (y1 - y0) * ph; };
  static const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};

  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
      << "\" viewBox=\"0 0 " << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << W << "\" height=\"" << H << "\" fill=\"white\"/>\n"
      << "<text x=\"" << left + pw / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">"
      << xml_escape(options.title) << "</text>\n";

  // Grid and ticks.
  out << "<g stroke=\"#ddd\" stroke-width=\"1\">\n";
  std::string labels;
  for (int d = static_cast<int>(x0); d <= static_cast<int>(x1); ++d)
    for (double m : {1.0, 2.0, 5.0}) {
      const double kb = m * std::pow(10.0, d);
      if (std::log10(kb) > x1 + 1e-9) break;
      const double x = sx(kb);
      out << "<line x1=\"" << fmt("%.2f", x) << "\" y1=\"" << top << "\" x2=\"" << fmt("%.2f", x)
          << "\" y2=\"" << top + ph << "\"/>\n";
      labels += "<text x=\"" + fmt("%.2f", x) + "\" y=\"" + fmt("%.2f", top + ph + 18) +
                "\" text-anchor=\"middle\">" + fmt("%g", kb) + "</text>\n";
    }
  for (double db = y0; db <= y1 + 1e-9; db += ystep) {
    const double y = sy(db);
    out << "<line x1=\"" << left << "\" y1=\"" << fmt("%.2f", y) << "\" x2=\"" << left + pw << "\" y2=\""
        << fmt("%.2f", y) << "\"/>\n";
    labels += "<text x=\"" + fmt("%.2f", left - 8) + "\" y=\"" + fmt("%.2f", y + 4) +
              "\" text-anchor=\"end\">" + fmt("%g", db) + "</text>\n";
  }
  out << "</g>\n"
      << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
      << "\" fill=\"none\" stroke=\"black\"/>\n"
      << labels << "<text x=\"" << left + pw / 2 << "\" y=\"" << H - 12
      << "\" text-anchor=\"middle\">size (kB = 1000 bytes, log scale)</text>\n"
      << "<text transform=\"translate(18," << top + ph / 2
      << ") rotate(-90)\" text-anchor=\"middle\">PSNR (dB)</text>\n";

  // Series and legend.
  for (std::size_t s = 0; s < names.size(); ++s) {
    const std::string& name = names[s];
    std::vector<RdPoint> pts = series[name];
    std::stable_sort(pts.begin(), pts.end(),
                     [](const RdPoint& a, const RdPoint& b) { return a.bytes < b.bytes; });
    const char* color = kColors[s % (sizeof kColors / sizeof kColors[0])];
    const bool scatter = std::find(options.scatter_methods.begin(), options.scatter_methods.end(), name) !=
                         options.scatter_methods.end();
    out << "<g class=\"series\" data-method=\"" << xml_escape(name) << "\">\n";
    if (!scatter && pts.size() > 1) {
      out << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"1.8\" points=\"";
      for (const RdPoint& p : pts)
        out << fmt("%.2f", sx(static_cast<double>(p.bytes) / 1000.0)) << ',' << fmt("%.2f", sy(p.psnr_db))
            << ' ';
      out << "\"/>\n";
    }
    for (const RdPoint& p : pts) {
      out << "<circle cx=\"" << fmt("%.2f", sx(static_cast<double>(p.bytes) / 1000.0)) << "\" cy=\""
          << fmt("%.2f", sy(p.psnr_db)) << "\" r=\"" << (scatter ? 2.2 : 3.0) << "\" fill=\"" << color << "\""
          << (scatter ? " fill-opacity=\"0.45\"" : "") << "><title>" << xml_escape(name) << ": " << p.bytes
          << " B, " << fmt("%.2f", p.psnr_db) << " dB, " << p.faces << " faces, Q" << p.quantization_bits
          << "</title></circle>\n";
    }
    const double ly = top + 10 + 20.0 * static_cast<double>(s);
    const double lx = left + pw + 15;
    out << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 22 << "\" y2=\"" << ly
        << "\" stroke=\"" << color << "\" stroke-width=\"" << (scatter ? 0 : 1.8) << "\"/>\n"
        << "<circle cx=\"" << lx + 11 << "\" cy=\"" << ly << "\" r=\"3\" fill=\"" << color << "\"/>\n"
        << "<text x=\"" << lx + 28 << "\" y=\"" << ly + 4 << "\">" << xml_escape(name) << "</text>\n"
        << "</g>\n";
  }
  out << "</svg>\n";
}

}  // namespace geomip
