#include "mesh/view_frame.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace geomip {
namespace {

std::vector<Eigen::Vector3d> referenced_points(const TriMesh& mesh) {
  std::vector<char> used(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int v : t)
      if (v >= 0 && static_cast<std::size_t>(v) < used.size()) used[static_cast<std::size_t>(v)] = 1;
  std::vector<Eigen::Vector3d> out;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v] && mesh.positions[v].allFinite()) out.push_back(mesh.positions[v]);
  return out;
}

/// Area of the convex hull of 2D points (Andrew's monotone chain).
double hull_area(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return 0;
  std::sort(p.begin(), p.end(),
            [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  double area = 0;
  for (std::size_t i = 0; i + 1 < k; ++i) area += h[i].x() * h[i + 1].y() - h[i + 1].x() * h[i].y();
  return std::abs(area) / 2;
}

/// The three cues of upright_rotation()'s front, each +1 (the positive end of axis `length`), −1 or 0 (no
/// opinion), summed.
int front_votes(const TriMesh& mesh, const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                int up_index, int length, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const auto sign = [](double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; };
  const int side = 3 - length - up_index;
  const double extent = hi[length] - lo[length];
  // 1. Reach: the largest up coordinate in the quarter of the length at each end.
  // 2. Width: the side extent of the tenth of the length at each end (ears, horns, a turned head).
  double top[2] = {-HUGE_VAL, -HUGE_VAL}, side_lo[2] = {HUGE_VAL, HUGE_VAL},
         side_hi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (const auto& p : points) {
    const double height = up.dot(p);
    if (p[length] <= lo[length] + 0.25 * extent) top[0] = std::max(top[0], height);
    if (p[length] >= hi[length] - 0.25 * extent) top[1] = std::max(top[1], height);
    for (int end = 0; end < 2; ++end)
      if (end == 0 ? p[length] <= lo[length] + 0.1 * extent : p[length] >= hi[length] - 0.1 * extent)
        side_lo[end] = std::min(side_lo[end], p[side]), side_hi[end] = std::max(side_hi[end], p[side]);
  }
  const int reach = sign(top[1] - top[0]);
  const int width = sign((side_hi[1] - side_lo[1]) - (side_hi[0] - side_lo[0]));
  // 3. Mass: the centroid of the enclosed volume (signed tetrahedra from the box centre) lies behind the
  //    middle of the length, towards the body; no opinion for a flat mesh (|volume| ≤ 1e-9 of the box's).
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double volume = 0, moment = 0;
  for (const auto& t : mesh.triangles) {
    bool valid = true;
    for (int v : t) valid = valid && v >= 0 && static_cast<std::size_t>(v) < mesh.positions.size();
    if (!valid) continue;
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(t[0])] - centre,
                          b = mesh.positions[static_cast<std::size_t>(t[1])] - centre,
                          c = mesh.positions[static_cast<std::size_t>(t[2])] - centre;
    if (!a.allFinite() || !b.allFinite() || !c.allFinite()) continue;
    const double v6 = a.dot(b.cross(c));
    volume += v6;
    moment += v6 * (a[length] + b[length] + c[length]) / 4;
  }
  const Eigen::Vector3d box = hi - lo;
  const bool closed = std::abs(volume) / 6 > 1e-9 * box.x() * box.y() * box.z();
  const int mass = closed ? -sign(moment / volume) : 0;
  const int votes = reach + width + mass;
  return votes != 0 ? votes : reach;
}

/// The centroid of the triangles' area; false when the mesh has no area.
bool area_centroid(const TriMesh& mesh, Eigen::Vector3d& centroid) {
  double area = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& t : mesh.triangles) {
    bool valid = true;
    for (int v : t) valid = valid && v >= 0 && static_cast<std::size_t>(v) < mesh.positions.size();
    if (!valid) continue;
    const Eigen::Vector3d& a = mesh.positions[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.positions[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.positions[static_cast<std::size_t>(t[2])];
    const double s = (b - a).cross(c - a).norm() / 2;
    if (!std::isfinite(s)) continue;
    area += s;
    sum += s * (a + b + c) / 3;
  }
  if (!(area > 0)) return false;
  centroid = sum / area;
  return true;
}

/// Per axis in `axes`: the mean distance (capped at 2 % of the box's diagonal, relative to the diagonal) from
/// every k-th point (k = ⌈#points / 4000⌉), reflected across the plane through `centre` normal to that axis,
/// to the nearest point. Small across the left-right axis of a mirror-symmetric body.
std::array<double, 2> mirror_mismatch(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& lo,
                                      const Eigen::Vector3d& hi, const Eigen::Vector3d& centre,
                                      std::array<int, 2> axes) {
  const double diag = (hi - lo).norm(), cap = 0.02 * diag;
  if (!(cap > 0) || !std::isfinite(cap)) return {0, 0};
  // A uniform grid of cells of side `cap` (at most 51 per axis: the diagonal bounds every extent).
  Eigen::Vector3i dims;
  for (int i = 0; i < 3; ++i) dims[i] = static_cast<int>(std::floor((hi[i] - lo[i]) / cap)) + 1;
  const auto cell_of = [&](const Eigen::Vector3d& q, Eigen::Vector3i& c) {
    for (int i = 0; i < 3; ++i) {
      const double f = std::floor((q[i] - lo[i]) / cap);
      if (!(f >= -1 && f <= dims[i])) return false;  // no neighbouring cell holds a point
      c[i] = static_cast<int>(f);
    }
    return true;
  };
  const auto index = [&](const Eigen::Vector3i& c) {
    return (static_cast<std::size_t>(c.z()) * static_cast<std::size_t>(dims.y()) +
            static_cast<std::size_t>(c.y())) *
               static_cast<std::size_t>(dims.x()) +
           static_cast<std::size_t>(c.x());
  };
  const std::size_t cells = static_cast<std::size_t>(dims.x()) * static_cast<std::size_t>(dims.y()) *
                            static_cast<std::size_t>(dims.z());
  std::vector<std::size_t> start(cells + 1, 0), order(points.size());
  std::vector<std::size_t> of(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    Eigen::Vector3i c = Eigen::Vector3i::Zero();
    cell_of(points[p], c);
    for (int i = 0; i < 3; ++i) c[i] = std::clamp(c[i], 0, dims[i] - 1);
    of[p] = index(c);
    ++start[of[p] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t p = 0; p < points.size(); ++p) order[fill[of[p]]++] = p;
  }
  const std::size_t step = std::max<std::size_t>(1, (points.size() + 3999) / 4000);
  std::array<double, 2> out{0, 0};
  for (int k = 0; k < 2; ++k) {
    const int a = axes[static_cast<std::size_t>(k)];
    double total = 0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < points.size(); p += step, ++n) {
      Eigen::Vector3d q = points[p];
      q[a] = 2 * centre[a] - q[a];
      double best = cap * cap;
      Eigen::Vector3i c = Eigen::Vector3i::Zero();
      if (cell_of(q, c))
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const Eigen::Vector3i d = c + Eigen::Vector3i(dx, dy, dz);
              if ((d.array() < 0).any() || (d.array() >= dims.array()).any()) continue;
              const std::size_t i = index(d);
              for (std::size_t j = start[i]; j < start[i + 1]; ++j)
                best = std::min(best, (points[order[j]] - q).squaredNorm());
            }
      total += std::sqrt(best);
    }
    out[static_cast<std::size_t>(k)] = n > 0 ? total / static_cast<double>(n) / diag : 0;
  }
  return out;
}

/// The face cue of an upright shape along axis `axis`: per end (−, +), among the points at least 40 % of the
/// height above the lowest, the area of the 2D convex hull (side axis × up) of those within 2 % of the axis's
/// extent from the extreme one. A nose, a muzzle or a snout is a small tip; the back of a head is a dome.
std::array<double, 2> tip_areas(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                                int axis, int side, double extent, double u0, double height) {
  std::array<double, 2> out{0, 0};
  for (int end = 0; end < 2; ++end) {
    const double s = end == 0 ? -1 : 1;
    double extreme = -HUGE_VAL;
    for (const auto& p : points)
      if (up.dot(p) >= u0 + 0.4 * height) extreme = std::max(extreme, s * p[axis]);
    std::vector<Eigen::Vector2d> cap;
    for (const auto& p : points)
      if (up.dot(p) >= u0 + 0.4 * height && s * p[axis] >= extreme - 0.02 * extent)
        cap.emplace_back(p[side], up.dot(p));
    out[static_cast<std::size_t>(end)] = hull_area(std::move(cap));
  }
  return out;
}

}  // namespace

Eigen::Vector3d ground_direction(const TriMesh& mesh, double band) {
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  if (points.empty()) return -Eigen::Vector3d::UnitY();
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d extent = hi - lo;
  // The support polygon of the box face (axis, sign) within `depth` × the extent, relative to the face's
  // area.
  const auto support = [&](int axis, int sign, double depth) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double face = extent[a] * extent[b];
    if (!(face > 0)) return 0.0;
    const double plane = sign < 0 ? lo[axis] : hi[axis];
    std::vector<Eigen::Vector2d> contact;
    for (const auto& p : points)
      if (std::abs(p[axis] - plane) <= depth * extent[axis]) contact.emplace_back(p[a], p[b]);
    return hull_area(std::move(contact)) / face;
  };
  // 1. The axis: that of the face with the largest support polygon.
  int axis = 1, sign = -1;
  double best = -1;
  for (int c : {1, 0, 2})
    for (int s : {-1, 1})
      if (const double ratio = support(c, s, band); ratio > best) best = ratio, axis = c, sign = s;
  // 2. Its end: the one whose contact hull grows less from `band` to 4 × `band` (legs, a neck or a cut keep
  //    their width; a back or a crown is a dome); growths within 5 % of each other: the larger support
  //    polygon.
  const double near_lo = support(axis, -1, band), near_hi = support(axis, 1, band);
  const auto growth = [&](int s, double near) {
    return near > 0 ? support(axis, s, 4 * band) / near : HUGE_VAL;
  };
  const double grow_lo = growth(-1, near_lo), grow_hi = growth(1, near_hi);
  if (std::isfinite(grow_lo) && std::isfinite(grow_hi) &&
      std::abs(grow_lo - grow_hi) > 0.05 * std::max(grow_lo, grow_hi))
    sign = grow_lo < grow_hi ? -1 : 1;
  else if (std::isfinite(grow_lo) != std::isfinite(grow_hi))
    sign = std::isfinite(grow_lo) ? -1 : 1;
  return Eigen::Vector3d::Unit(axis) * sign;
}

Eigen::Matrix3d upright_rotation(const TriMesh& mesh, UpAxis up_axis, const Eigen::Vector3d& front_axis) {
  const Eigen::Vector3d up = up_axis == UpAxis::kX   ? Eigen::Vector3d::UnitX()
                             : up_axis == UpAxis::kY ? Eigen::Vector3d::UnitY()
                             : up_axis == UpAxis::kZ ? Eigen::Vector3d::UnitZ()
                                                     : Eigen::Vector3d(-ground_direction(mesh));
  int up_index = 0;
  up.cwiseAbs().maxCoeff(&up_index);
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  if (!points.empty()) {
    lo = hi = points[0];
    for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  // The longer horizontal axis (ties: the first in x, y, z order).
  int length = -1;
  for (int c = 0; c < 3; ++c)
    if (c != up_index && (length < 0 || hi[c] - lo[c] > hi[length] - lo[length])) length = c;
  // A given front: a signed unit axis across up, shown as +x.
  int front_index = 0;
  front_axis.cwiseAbs().maxCoeff(&front_index);
  const bool given =
      front_index != up_index && std::abs(front_axis[front_index]) == 1 && front_axis.cwiseAbs().sum() == 1;
  const auto rows = [&](const Eigen::Vector3d& x) {
    Eigen::Matrix3d r;
    r.row(0) = x.transpose();
    r.row(1) = up.transpose();
    r.row(2) = x.cross(up).transpose();
    return r;
  };
  if (given) return rows(front_axis);
  // The front-back axis: the length, unless the body is clearly more mirror-symmetric across it than across
  // the other horizontal axis (then the length is a left-right span: a biped's arms).
  const int other = 3 - length - up_index;
  int axis = length;
  Eigen::Vector3d centre;
  if (!points.empty() && area_centroid(mesh, centre)) {
    const std::array<double, 2> mirror = mirror_mismatch(points, lo, hi, centre, {length, other});
    if (mirror[0] < 0.8 * mirror[1]) axis = other;
  }
  const int side = 3 - axis - up_index;
  const double extent = hi[axis] - lo[axis];
  // Upright: the vertices within 5 % of the height from the ground span under 45 % of the axis (a neck, two
  // feet under the body); four legs or a lying body span more.
  double u0 = HUGE_VAL, u1 = -HUGE_VAL;
  for (const auto& p : points) u0 = std::min(u0, up.dot(p)), u1 = std::max(u1, up.dot(p));
  const double height = u1 - u0;
  double foot_lo = HUGE_VAL, foot_hi = -HUGE_VAL;
  for (const auto& p : points)
    if (up.dot(p) <= u0 + 0.05 * height)
      foot_lo = std::min(foot_lo, p[axis]), foot_hi = std::max(foot_hi, p[axis]);
  const bool upright = extent > 0 && height > 0 && foot_hi - foot_lo < 0.45 * extent;
  int sign = front_votes(mesh, points, up, up_index, axis, lo, hi) < 0 ? -1 : 1;
  if (upright) {
    // The face: the end with the smaller tip, when the other's is at least 1.5 × as large.
    const std::array<double, 2> tip = tip_areas(points, up, axis, side, extent, u0, height);
    const double small = std::min(tip[0], tip[1]), large = std::max(tip[0], tip[1]);
    if (large > 0 && large >= 1.5 * small) sign = tip[0] < tip[1] ? -1 : 1;
    // Turned to +z, the default camera's side: +x = up × front.
    const Eigen::Vector3d front = Eigen::Vector3d::Unit(axis) * sign;
    return rows(up.cross(front));
  }
  return rows(Eigen::Vector3d::Unit(axis) * sign);
}

std::array<double, 16> view_normalization(const TriMesh& mesh, const Eigen::Matrix3d& rotation) {
  const std::vector<Eigen::Vector3d> points = referenced_points(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  if (!points.empty()) {
    lo = hi = rotation * points[0];
    for (const auto& p : points) {
      const Eigen::Vector3d q = rotation * p;
      lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    }
  }
  double extent = (hi - lo).maxCoeff();
  if (!(extent > 0) || !std::isfinite(extent)) extent = 1;
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  std::array<double, 16> m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[static_cast<std::size_t>(4 * r + c)] = rotation(r, c) / extent;
    m[static_cast<std::size_t>(4 * r + 3)] = -centre[r] / extent;
  }
  m[15] = 1;
  return m;
}

bool is_rotation(const std::array<double, 9>& r, double tolerance) {
  double worst = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      worst = std::max(worst, std::abs(r[3 * a] * r[3 * b] + r[3 * a + 1] * r[3 * b + 1] +
                                       r[3 * a + 2] * r[3 * b + 2] - (a == b ? 1.0 : 0.0)));
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  return worst <= tolerance && std::abs(det - 1) <= tolerance;  // false for NaN too
}

std::array<double, 9> frame_rotation(const std::array<double, 16>& n) {
  const std::array<double, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double scale = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(scale > 0) || !std::isfinite(scale)) return identity;
  std::array<double, 9> r{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) r[3 * row + col] = n[4 * row + col] / scale;
  return is_rotation(r) ? r : identity;
}

}  // namespace geomip
