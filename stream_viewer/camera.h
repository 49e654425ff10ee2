// Orbit camera of geomip-view. The same matrices are used by the renderer and by the tests that project a
// model on the CPU to check a screenshot's coverage.
#pragma once

#include <array>
#include <span>

namespace geomip::viewer {

/// Orbits the origin of the normalized frame (unit bounding box, centred) at `distance`.
struct Camera {
  float yaw = 0.6f;         ///< radians, about +y
  float pitch = 0.35f;      ///< radians, elevation above the xz plane
  float distance = 3.2f;    ///< from the origin, normalized units
  float fov_y_deg = 35.0f;  ///< vertical field of view
};

/// Column-major 4×4 (OpenGL order) projection · view for a width×height viewport.
std::array<float, 16> view_projection(const Camera& camera, int width, int height);

/// Eye position in the normalized frame.
std::array<float, 3> eye_position(const Camera& camera);

/// The camera distance at which `xyz` (points as x, y, z triples, normalized frame), seen from `camera`'s yaw
/// and pitch, spans `fill` of a width×height viewport's height — or `max_width_fill` of its width, whichever
/// is reached first (so a model wider than the viewport's aspect still fills most of it and is not cut off).
/// Bisection over distances in [0.3, 20] (the range the scroll wheel allows) on at most ~20,000 of the
/// points; returns camera.distance when `xyz` is empty.
float framing_distance(const Camera& camera, std::span<const float> xyz, int width, int height,
                       float fill = 0.7f, float max_width_fill = 0.9f);

}  // namespace geomip::viewer
