// Rate–distortion points, their upper envelope (Pareto front), and the CSV and SVG files `geomip rd` writes.
//
// A point is one coded mesh: its size in bytes and the distortion of its decoded mesh against the original
// (PSNR and Hausdorff distance of gimage/surface_distance.h). The envelope of several parameter sweeps (for
// example decimation × quantization) is the set of points no other point beats in both size and quality: the
// best any choice of parameters achieves, read off as a staircase (`envelope_at`: what one coded file within
// a budget gives) or interpolated in log(bytes) between its points (`envelope_interpolated`: the usual
// reading of a baseline's curve, and the one geomip is compared against).
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace geomip {

struct RdPoint {
  std::string method;         ///< series name, e.g. "draco", "draco_qem", "draco_envelope", "meshopt"
  std::size_t bytes = 0;      ///< coded size in bytes
  double psnr_db = 0;         ///< PSNR of the decoded mesh vs the original, dB (surface_distance)
  double hausdorff_pct = 0;   ///< symmetric Hausdorff distance, % of the original's bounding-box diagonal
  double rms_pct = 0;         ///< symmetric RMS distance, % of the diagonal
  double decode_ms = 0;       ///< decode time, milliseconds
  std::size_t faces = 0;      ///< faces of the coded mesh (after any decimation)
  std::size_t vertices = 0;   ///< vertices of the decoded mesh
  int quantization_bits = 0;  ///< position quantization bits (0 = not quantized / not applicable)
  std::string source;         ///< for envelope points, the method the point came from; empty otherwise
};

/// The Pareto front of `points` for (fewer bytes, higher PSNR): a point is kept iff no other point has
/// bytes ≤ and psnr ≥ its own with at least one strict; of exactly equal points the first is kept. The
/// result is sorted by bytes (ascending), hence also by PSNR (strictly ascending). Points with a NaN PSNR are
/// ignored. O(n log n).
std::vector<RdPoint> upper_envelope(const std::vector<RdPoint>& points);

/// The staircase of a front: the best PSNR among `front`'s points with at most `bytes` bytes, or −infinity
/// when none is that small. `front` may be any set of points (not necessarily a front, in any order);
/// non-decreasing in `bytes`.
double envelope_at(const std::vector<RdPoint>& front, std::size_t bytes);

/// The front read between its points: PSNR linear in log(bytes) between the two points of `front` whose bytes
/// bracket `bytes` (exactly a point's PSNR at its bytes); below the smallest point −infinity, above the
/// largest the largest point's PSNR. `front` must be an upper envelope (upper_envelope()'s output: sorted by
/// bytes, PSNR increasing); never below envelope_at() of the same front. O(log n).
double envelope_interpolated(const std::vector<RdPoint>& front, std::size_t bytes);

/// Writes `points` as CSV: header `method,bytes,psnr_db,hausdorff_pct,decode_ms,rms_pct,faces,vertices,
/// quantization_bits,source` and one row per point, in order. PSNR +infinity is written as `inf`.
void write_rd_csv(std::ostream& out, const std::vector<RdPoint>& points);

struct RdPlotOptions {
  std::string title = "Rate-distortion";
  int width = 900;   ///< SVG width in px
  int height = 560;  ///< SVG height in px
  /// Methods drawn as markers only (a cloud of parameter combinations, where a connecting line means
  /// nothing); every other method is a polyline through its points sorted by bytes, with markers.
  std::vector<std::string> scatter_methods = {"draco_qem"};
};

/// Writes a self-contained SVG plot of `points` (x = size in KB = bytes/1000 on a log axis, y = PSNR in dB):
/// one series per method in order of first appearance, each with its own color, a legend, ticks at 1-2-5
/// steps per decade on x and round dB steps on y, and axis labels. Points with non-finite PSNR or zero bytes
/// are left out of the plot; when none is left (a flat mesh: every decoded copy lies on its surface), the SVG
/// says so in place of the plot.
void write_rd_svg(std::ostream& out, const std::vector<RdPoint>& points, const RdPlotOptions& options = {});

}  // namespace geomip
