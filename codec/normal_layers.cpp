#include "codec/normal_layers.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <utility>

#include "codec/parallel.h"

namespace geomip::codec {
namespace {

struct Vec {
  double x = 0, y = 0, z = 0;
};
Vec operator-(Vec a, Vec b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec operator*(double s, Vec a) {
  return {s * a.x, s * a.y, s * a.z};
}
double dot(Vec a, Vec b) {
  const double xy = a.x * b.x + a.y * b.y;
  return xy + a.z * b.z;
}
Vec cross(Vec a, Vec b) {
  const double x1 = a.y * b.z, x2 = a.z * b.y, y1 = a.z * b.x, y2 = a.x * b.z, z1 = a.x * b.y, z2 = a.y * b.x;
  return {x1 - x2, y1 - y2, z1 - z2};
}
Vec lerp(Vec a, Vec b, double f) {
  const Vec d = b - a;
  const Vec s = f * d;
  return {a.x + s.x, a.y + s.y, a.z + s.z};
}
/// `v` scaled to unit length; false (v untouched) when its length is 0, infinite or NaN.
bool normalize(Vec& v) {
  const double len = std::sqrt(dot(v, v));
  if (!(len > 0) || !std::isfinite(len)) return false;
  v = {v.x / len, v.y / len, v.z / len};
  return true;
}

struct Frame {
  Vec t{1, 0, 0}, b{0, 1, 0}, g{0, 0, 1};
};

/// The frames of one patch at the texels of a level-`level` grid (see normal_layers.h). The separate products
/// and sums above (no a·b + c in one expression) keep every operation rounded on its own, whatever the
/// compiler is allowed to contract.
class PatchFrames {
 public:
  PatchFrames(const Grid3& geometry, int level, bool along_grid) : level_(level), along_(along_grid) {
    n_ = geometry.size();
    if (geometry.values.size() != 3u * static_cast<std::size_t>(n_) * n_ || n_ < 2) {
      n_ = 0;
      return;
    }
    geometry_ = &geometry;
    du_.resize(static_cast<std::size_t>(n_) * n_);
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < n_; ++i)
        du_[static_cast<std::size_t>(j) * n_ + i] =
            sample(std::min(i + 1, n_ - 1), j) - sample(std::max(i - 1, 0), j);
    shift_ = level_ - geometry.level;
  }

  /// The frame at texel (ti, tj); `axis` (or null): its normal instead of the grid's (t from ∂u as ever).
  Frame at(int ti, int tj, const float* axis = nullptr) const {
    Frame f;
    const Vec du =
        derivative(ti, tj, [&](int i, int j) { return du_[static_cast<std::size_t>(j) * n_ + i]; });
    Vec g;
    if (!axis || !normalize(g = Vec{axis[0], axis[1], axis[2]})) {
      // the grid's own normal, only where there is no axis: ∂v computed here (with axes it is rarely needed)
      const Vec dv = derivative(ti, tj, [&](int i, int j) {
        return sample(i, std::min(j + 1, n_ - 1)) - sample(i, std::max(j - 1, 0));
      });
      g = along_ ? cross(du, dv) : cross(dv, du);
      if (!normalize(g)) return f;
    }
    Vec t = du - dot(du, g) * g;
    if (!normalize(t)) {
      const Vec fallback = std::abs(g.x) < 0.5 ? Vec{1, 0, 0} : Vec{0, 1, 0};
      t = fallback - dot(fallback, g) * g;
      if (!normalize(t)) return f;
    }
    f.g = g, f.t = t, f.b = cross(g, t);
    return f;
  }

 private:
  Vec sample(int i, int j) const {
    const float* p = geometry_->values.data() + 3 * (static_cast<std::size_t>(j) * n_ + i);
    return Vec{p[0], p[1], p[2]};
  }

  /// ∂u or ∂v (`d(i, j)` at grid samples) at texel (ti, tj): the grid's value there, or interpolated
  /// bilinearly between grid samples when the texels are finer; zero without a grid.
  template <typename D>
  Vec derivative(int ti, int tj, const D& d) const {
    if (n_ == 0) return {};
    if (shift_ <= 0) return d(ti << -shift_, tj << -shift_);
    const int mask = (1 << shift_) - 1;
    const int i0 = ti >> shift_, j0 = tj >> shift_;
    const int i1 = std::min(i0 + 1, n_ - 1), j1 = std::min(j0 + 1, n_ - 1);
    const double fi = static_cast<double>(ti & mask) / static_cast<double>(1 << shift_);
    const double fj = static_cast<double>(tj & mask) / static_cast<double>(1 << shift_);
    return lerp(lerp(d(i0, j0), d(i1, j0), fi), lerp(d(i0, j1), d(i1, j1), fi), fj);
  }

  int level_ = 0, n_ = 0, shift_ = 0;
  bool along_ = true;
  const Grid3* geometry_ = nullptr;  ///< ∂v is computed from it where needed (held for the frames' life)
  std::vector<Vec> du_;  ///< ∂u at every grid sample (central differences, one-sided at the border)
};

double sign(double v) {
  return v < 0 ? -1.0 : 1.0;
}

/// Octahedral coordinates of the unit vector (x, y, z) (z: the pole at (0, 0)).
void oct_encode(Vec v, double& u, double& w) {
  const double l1 = std::abs(v.x) + std::abs(v.y) + std::abs(v.z);
  u = v.x / l1, w = v.y / l1;
  if (v.z < 0) {
    const double fu = (1 - std::abs(w)) * sign(u), fw = (1 - std::abs(u)) * sign(w);
    u = fu, w = fw;
  }
}

Vec oct_decode(double u, double w) {
  u = std::clamp(u, -1.0, 1.0), w = std::clamp(w, -1.0, 1.0);
  const double z = 1 - std::abs(u) - std::abs(w);
  if (z >= 0) return {u, w, z};
  return {(1 - std::abs(w)) * sign(u), (1 - std::abs(u)) * sign(w), z};
}

}  // namespace

NormalOrientation normal_orientation(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry) {
  NormalOrientation along;
  for (std::size_t p = 0; p < std::min(normals.size(), geometry.size()); ++p) {
    double sum = 0;
    const PatchFrames frames(geometry[p], normals[p].level, true);
    const int n = normals[p].size();
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float* v = normals[p].values.data() + 3 * (static_cast<std::size_t>(j) * n + i);
        sum += dot(frames.at(i, j).g, Vec{v[0], v[1], v[2]});
      }
    along.push_back(sum >= 0);
  }
  return along;
}

std::vector<Grid3> normal_residual(const std::vector<Grid3>& normals, const std::vector<Grid3>& geometry,
                                   const NormalOrientation& orientation, const std::vector<Grid3>* axes) {
  if (normals.size() != geometry.size() || (axes && normals.size() != axes->size()))
    throw std::invalid_argument(
        "normal_residual: normal maps, axes and geometry have different patch counts");
  std::vector<Grid3> out(normals.size());
  for (std::size_t p = 0; p < normals.size(); ++p) {
    if (axes &&
        ((*axes)[p].values.size() != normals[p].values.size() || (*axes)[p].level != normals[p].level))
      throw std::invalid_argument("normal_residual: normal maps and axes differ in size");
    const PatchFrames frames(geometry[p], normals[p].level, p >= orientation.size() || orientation[p]);
    const int n = normals[p].size();
    out[p].level = normals[p].level;
    out[p].values.assign(3u * static_cast<std::size_t>(n) * n, 0.f);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t k = 3 * (static_cast<std::size_t>(j) * n + i);
        const float* v = normals[p].values.data() + k;
        Vec nv{v[0], v[1], v[2]};
        if (!normalize(nv)) nv = {0, 0, 1};
        const Frame f = frames.at(i, j, axes ? (*axes)[p].values.data() + k : nullptr);
        double u, w;
        oct_encode({dot(nv, f.t), dot(nv, f.b), dot(nv, f.g)}, u, w);
        out[p].values[k] = static_cast<float>(u);
        out[p].values[k + 1] = static_cast<float>(w);
      }
  }
  return out;
}

void apply_normal_residual(std::vector<Grid3>& maps, const std::vector<Grid3>& geometry,
                           const NormalOrientation& orientation, const std::vector<Grid3>* axes,
                           int max_threads) {
  const Grid3 none;
  std::vector<PatchFrames> frames;
  frames.reserve(maps.size());
  for (std::size_t p = 0; p < maps.size(); ++p)
    frames.emplace_back(p < geometry.size() ? geometry[p] : none, maps[p].level,
                        p >= orientation.size() || orientation[p]);
  // Independent texels: tasks of kRows rows of one patch.
  constexpr int kRows = 64;
  std::vector<std::pair<std::size_t, int>> tasks;
  for (std::size_t p = 0; p < maps.size(); ++p)
    if (maps[p].values.size() == 3u * static_cast<std::size_t>(maps[p].size()) * maps[p].size())
      for (int j = 0; j < maps[p].size(); j += kRows) tasks.emplace_back(p, j);
  parallel_for(static_cast<int>(tasks.size()), max_threads, [&](int task) {
    const auto [p, j0] = tasks[static_cast<std::size_t>(task)];
    Grid3& map = maps[p];
    const int n = map.size();
    const bool with_axes = axes && p < axes->size() && (*axes)[p].values.size() == map.values.size();
    for (int j = j0; j < std::min(n, j0 + kRows); ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t k = 3 * (static_cast<std::size_t>(j) * n + i);
        float* v = map.values.data() + k;
        const double u = std::isnan(v[0]) ? 0.0 : v[0], w = std::isnan(v[1]) ? 0.0 : v[1];
        const Vec local = oct_decode(u, w);
        const Frame f = frames[p].at(i, j, with_axes ? (*axes)[p].values.data() + k : nullptr);
        const Vec a = local.x * f.t, b = local.y * f.b, c = local.z * f.g;
        Vec out{a.x + b.x + c.x, a.y + b.y + c.y, a.z + b.z + c.z};
        if (!normalize(out)) out = f.g;
        v[0] = static_cast<float>(out.x), v[1] = static_cast<float>(out.y), v[2] = static_cast<float>(out.z);
      }
  });
}

void normalize_normal_maps(std::vector<Grid3>& maps) {
  for (Grid3& grid : maps) {
    for (std::size_t k = 0; k + 2 < grid.values.size(); k += 3) {
      float* n = grid.values.data() + k;
      const float xx = n[0] * n[0], yy = n[1] * n[1], zz = n[2] * n[2];
      const float len = std::sqrt(xx + yy + zz);
      if (len > 0) n[0] /= len, n[1] /= len, n[2] /= len;
    }
  }
}

}  // namespace geomip::codec
