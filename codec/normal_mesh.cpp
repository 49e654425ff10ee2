#include "codec/normal_mesh.h"

#include "codec/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace geomip::codec {
namespace {

/// Positions are scaled to this many integer steps across the grid's largest bounding-box extent for the
/// codec's integer transform: rounding moves a prediction by at most 2^−23 of the extent.
constexpr double kIntegerSteps = 4194304.0;  // 2^22

Point3d sub(const Point3d& a, const Point3d& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Point3d cross(const Point3d& a, const Point3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Point3d& a) {
  return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/// One wavelet step's view of the grid: the subgrid at spacing s (level L = level − k + 1, m samples a
/// side), the predictions P of its odd positions from the current samples, and the subdivided coarser grid Q
/// (every odd position predicted with all of this step's details zero).
class StepView {
 public:
  StepView(Grid3& grid, int k, const Point3d& lo, double unit, WaveletFilter filter)
      : grid_(grid),
        k_(k),
        s_(1 << (k - 1)),
        level_(grid.level - k + 1),
        m_((1 << level_) + 1),
        lo_(lo),
        unit_(unit),
        filter_(filter),
        p_(3 * cells()),
        q_(3 * cells()) {}

  int m() const { return m_; }
  /// Recomputes P (and, with `subdivide`, Q) from the grid's current samples.
  void predict(bool subdivide) {
    std::vector<std::int32_t> a(cells()), b(cells());
    for (int c = 0; c < 3; ++c) {
      for (int J = 0; J < m_; ++J) {
        for (int I = 0; I < m_; ++I) {
          a[index(I, J)] = static_cast<std::int32_t>(std::lround((sample(I, J)[c] - lo_[c]) / unit_));
        }
      }
      b = a;
      wavelet_forward(b, level_, 1, filter_, false, k_);
      for (std::size_t i = 0; i < cells(); ++i) {
        // Evens keep their value (no update step): P = a there; odd positions hold the detail a − P.
        p_[3 * i + c] =
            lo_[c] + static_cast<double>(static_cast<std::int64_t>(a[i]) - (odd(i) ? b[i] : 0)) * unit_;
        if (odd(i)) b[i] = 0;
      }
      if (!subdivide) continue;
      wavelet_inverse(b, level_, 1, filter_, false, k_);
      for (std::size_t i = 0; i < cells(); ++i) q_[3 * i + c] = lo_[c] + static_cast<double>(b[i]) * unit_;
    }
  }
  Point3d p(int I, int J) const { return get(p_, I, J); }
  Point3d q(int I, int J) const { return get(q_, I, J); }
  float* sample(int I, int J) {
    const std::size_t size = static_cast<std::size_t>(grid_.size());
    return grid_.values.data() +
           3 * (static_cast<std::size_t>(J) * s_ * size + static_cast<std::size_t>(I) * s_);
  }

 private:
  std::size_t cells() const { return static_cast<std::size_t>(m_) * static_cast<std::size_t>(m_); }
  std::size_t index(int I, int J) const { return static_cast<std::size_t>(J) * m_ + I; }
  bool odd(std::size_t i) const { return (i % m_) % 2 == 1 || (i / m_) % 2 == 1; }
  Point3d get(const std::vector<double>& v, int I, int J) const {
    const std::size_t i = 3 * index(I, J);
    return {v[i], v[i + 1], v[i + 2]};
  }

  Grid3& grid_;
  int k_, s_, level_, m_;  // k_: the wavelet step this view predicts (kCubicLong differs by step)
  Point3d lo_;
  double unit_;
  WaveletFilter filter_;
  std::vector<double> p_, q_;
};

struct RowStats {
  std::size_t candidates = 0, moved = 0, no_crossing = 0, would_fold = 0;
  double shift_sum = 0, shift_max = 0;
};

/// Whether moving the interior sample (I, J) of `view` from `from` to `to` leaves every triangle of its
/// umbrella in the step's grid — (x, E, N), (x, N, W), (x, W, S), (x, S, E) with E = (I+1, J), N = (I, J+1) —
/// that faces along `n` (∂u × ∂v of the predicted surface) facing along it. The four neighbours are samples
/// of the coarser grid or of the step's other pass, so no task writes them while this pass runs.
bool keeps_facing(StepView& view, int I, int J, const Point3d& n, const Point3d& from, const Point3d& to) {
  constexpr int kDi[4] = {1, 0, -1, 0}, kDj[4] = {0, 1, 0, -1};
  std::array<Point3d, 4> ring;
  for (int k = 0; k < 4; ++k) {
    const float* y = view.sample(I + kDi[k], J + kDj[k]);
    ring[static_cast<std::size_t>(k)] = {y[0], y[1], y[2]};
  }
  const auto facing = [&](const Point3d& x, std::size_t k) {
    const Point3d c = cross(sub(ring[k], x), sub(ring[(k + 1) % 4], x));
    return c[0] * n[0] + c[1] * n[1] + c[2] * n[2] > 0;
  };
  for (std::size_t k = 0; k < 4; ++k) {
    if (facing(from, k) && !facing(to, k)) return false;
  }
  return true;
}

/// Moves the interior samples (I, J) of `view` for which `selected(I, J)` holds, one row per task; with
/// `guard`, only where keeps_facing().
template <typename Selected>
void move_samples(StepView& view, const SurfaceCrossing& crossing, const NormalMeshOptions& options,
                  Selected selected, bool guard, std::vector<RowStats>& rows) {
  const int m = view.m();
  parallel_for(m - 2, options.threads, [&](int row) {
    const int J = row + 1;
    RowStats& stats = rows[static_cast<std::size_t>(J)];
    for (int I = 1; I < m - 1; ++I) {
      if (!selected(I, J)) continue;
      ++stats.candidates;
      const Point3d du = sub(view.q(I + 1, J), view.q(I - 1, J));
      const Point3d dv = sub(view.q(I, J + 1), view.q(I, J - 1));
      const Point3d n = cross(du, dv);
      const double spacing = 0.25 * (norm(du) + norm(dv));  // each central difference spans two spacings
      float* x = view.sample(I, J);
      const Point3d here{x[0], x[1], x[2]};
      std::optional<Point3d> hit;
      const double length = norm(n);
      if (length > 0 && spacing > 0) {
        // Look for the crossing near the sample's own normal offset: the foot of the sample on the line.
        const Point3d p = view.p(I, J);
        const Point3d unit{n[0] / length, n[1] / length, n[2] / length};
        const Point3d d = sub(here, p);
        const double t = d[0] * unit[0] + d[1] * unit[1] + d[2] * unit[2];
        const Point3d foot{p[0] + t * unit[0], p[1] + t * unit[1], p[2] + t * unit[2]};
        hit = crossing(p, unit, foot, options.max_shift * spacing);
      }
      if (!hit) {
        ++stats.no_crossing;
        continue;
      }
      if (guard && !keeps_facing(view, I, J, n, here, *hit)) {
        ++stats.would_fold;
        continue;
      }
      const double shift = norm(sub(*hit, here)) / spacing;
      for (int c = 0; c < 3; ++c) x[c] = static_cast<float>((*hit)[c]);
      ++stats.moved;
      stats.shift_sum += shift;
      stats.shift_max = std::max(stats.shift_max, shift);
    }
  });
}

}  // namespace

NormalMeshStats normal_mesh_resample(Grid3& grid, const SurfaceCrossing& crossing,
                                     const NormalMeshOptions& options) {
  if (grid.level < 0 || grid.level > 15 ||
      grid.values.size() !=
          3 * static_cast<std::size_t>(grid.size()) * static_cast<std::size_t>(grid.size())) {
    throw std::invalid_argument("normal_mesh_resample: grid of level " + std::to_string(grid.level) +
                                " has " + std::to_string(grid.values.size()) + " values");
  }
  Point3d lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < grid.values.size(); ++i) {
    const double v = grid.values[i];
    if (!std::isfinite(v)) throw std::invalid_argument("normal_mesh_resample: non-finite sample value");
    lo[i % 3] = std::min(lo[i % 3], v);
    hi[i % 3] = std::max(hi[i % 3], v);
  }
  NormalMeshStats stats;
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const int steps = std::clamp(options.steps, 0, grid.level);
  if (!(extent > 0) || steps == 0 || !crossing) return stats;
  const double unit = extent / kIntegerSteps;

  std::vector<RowStats> rows(static_cast<std::size_t>(grid.size()));
  for (int k = steps; k >= 1; --k) {
    const bool guard = options.fold_guard_from_step > 0 && k >= options.fold_guard_from_step;
    StepView view(grid, k, lo, unit, options.filter);
    view.predict(/*subdivide=*/true);
    // Row and column details: predicted from the coarser grid only.
    move_samples(
        view, crossing, options, [](int I, int J) { return (I % 2) != (J % 2); }, guard, rows);
    // Diagonal details: their prediction uses the row and column samples just placed.
    view.predict(/*subdivide=*/false);
    move_samples(
        view, crossing, options, [](int I, int J) { return I % 2 == 1 && J % 2 == 1; }, guard, rows);
  }
  double shift_sum = 0;
  for (const RowStats& r : rows) {
    stats.candidates += r.candidates;
    stats.moved += r.moved;
    stats.no_crossing += r.no_crossing;
    stats.would_fold += r.would_fold;
    shift_sum += r.shift_sum;
    stats.max_shift = std::max(stats.max_shift, r.shift_max);
  }
  stats.mean_shift = stats.moved ? shift_sum / static_cast<double>(stats.moved) : 0;
  return stats;
}

}  // namespace geomip::codec
