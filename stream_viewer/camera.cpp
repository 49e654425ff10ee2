#include "stream_viewer/camera.h"

#include <algorithm>
#include <cmath>

namespace geomip::viewer {
namespace {

using Mat4 = std::array<float, 16>;  // column-major: m[4 * col + row]

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int r_ = 0; r_ < 4; ++r_) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[4 * k + r_] * b[4 * c + k];
      r[4 * c + r_] = s;
    }
  return r;
}

}  // namespace

std::array<float, 3> eye_position(const Camera& camera) {
  const float cp = std::cos(camera.pitch);
  return {camera.distance * cp * std::sin(camera.yaw), camera.distance * std::sin(camera.pitch),
          camera.distance * cp * std::cos(camera.yaw)};
}

std::array<float, 16> view_projection(const Camera& camera, int width, int height) {
  const auto eye = eye_position(camera);
  // look-at the origin, up = +y
  float f[3] = {-eye[0], -eye[1], -eye[2]};
  const float fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (float& v : f) v /= fl;
  const float up[3] = {0, 1, 0};
  float s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
  const float sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (float& v : s) v /= sl;
  const float u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
  Mat4 view{};
  view[0] = s[0], view[4] = s[1], view[8] = s[2];
  view[1] = u[0], view[5] = u[1], view[9] = u[2];
  view[2] = -f[0], view[6] = -f[1], view[10] = -f[2];
  view[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
  view[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
  view[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
  view[15] = 1;

  const float aspect = static_cast<float>(width) / static_cast<float>(height > 0 ? height : 1);
  const float near_plane = 0.05f, far_plane = 50.0f;
  const float t = 1.0f / std::tan(camera.fov_y_deg * 3.14159265f / 360.0f);
  Mat4 proj{};
  proj[0] = t / aspect;
  proj[5] = t;
  proj[10] = (far_plane + near_plane) / (near_plane - far_plane);
  proj[11] = -1;
  proj[14] = 2 * far_plane * near_plane / (near_plane - far_plane);
  return multiply(proj, view);
}

float framing_distance(const Camera& camera, std::span<const float> xyz, int width, int height, float fill,
                       float max_width_fill) {
  const std::size_t points = xyz.size() / 3;
  if (points == 0) return camera.distance;
  const std::size_t stride = std::max<std::size_t>(1, points / 20000);
  // How full the viewport is at distance d: max(height fraction / fill, width fraction / max_width_fill)
  // (1 = framed), or infinity when a point is behind the near plane (too close).
  const auto span_at = [&](float d) {
    Camera c = camera;
    c.distance = d;
    const auto m = view_projection(c, width, height);
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (std::size_t k = 0; k < points; k += stride) {
      const float* p = &xyz[3 * k];
      const float w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
      if (!(w > 0.05f)) return INFINITY;
      for (int r = 0; r < 2; ++r) {
        const float v = (m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]) / w;
        lo[r] = std::min(lo[r], v);
        hi[r] = std::max(hi[r], v);
      }
    }
    return std::max((hi[1] - lo[1]) / (2 * fill), (hi[0] - lo[0]) / (2 * max_width_fill));  // NDC spans 2
  };
  float near_d = 0.3f, far_d = 20.0f;  // span decreases with the distance
  for (int it = 0; it < 40; ++it) {
    const float mid = 0.5f * (near_d + far_d);
    (span_at(mid) > 1 ? near_d : far_d) = mid;
  }
  return far_d;
}

}  // namespace geomip::viewer
