#include "stream_viewer/camera.h"

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

}  // namespace geomip::viewer
