// Orbit camera of geomip-view. The same matrices are used by the renderer and by the tests that project a
// model on the CPU to check a screenshot's coverage.
#pragma once

#include <array>

namespace geomip::viewer {

/// Orbits the origin of the normalized frame (unit bounding box, centred) at `distance`.
struct Camera {
  float yaw = 0.6f;          ///< radians, about +y
  float pitch = 0.35f;       ///< radians, elevation above the xz plane
  float distance = 3.2f;     ///< from the origin, normalized units
  float fov_y_deg = 35.0f;   ///< vertical field of view
};

/// Column-major 4×4 (OpenGL order) projection · view for a width×height viewport.
std::array<float, 16> view_projection(const Camera& camera, int width, int height);

/// Eye position in the normalized frame.
std::array<float, 3> eye_position(const Camera& camera);

}  // namespace geomip::viewer
