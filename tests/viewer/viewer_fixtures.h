// Fixtures of the viewer tests: synthetic consistent two-patch models (as decoded models and as pack inputs),
// a hidden GL context, and the CPU reference of a frame's coverage (the model's grid triangles projected with
// the viewer's own camera and rasterized).
#pragma once

#include <epoxy/gl.h>  // before GLFW
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "codec/pack.h"
#include "stream_viewer/camera.h"
#include "stream_viewer/renderer.h"
#include "morph/scene_model.h"

namespace geomip::viewer::testing {

/// A closed surface as two (2^level+1)² geometry images glued along all four sides (patch 1 = patch 0
/// mirrored in i with z negated; seam samples bit-identical). `shape` 0: a mildly bumpy ellipsoid; 1: a
/// rounder body with fine bumps (so the two differ in coarse and fine bands).
inline std::vector<codec::Grid3> two_patch_model(int level, int shape, std::vector<codec::PatchSeam>& seams) {
  const int m = 1 << level, n = m + 1;
  std::vector<codec::Grid3> patches(2);
  for (auto& g : patches) {
    g.level = level;
    g.values.resize(3 * static_cast<std::size_t>(n) * n);
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = 2.0 * i / m - 1, v = 2.0 * j / m - 1;
      const double r = std::max(std::abs(u), std::abs(v)), len = std::hypot(u, v);
      const double x = len > 0 ? u * r / len : 0, y = len > 0 ? v * r / len : 0;
      const bool boundary = i == 0 || j == 0 || i == m || j == m;
      const double z = boundary ? 0.0 : std::sqrt(std::max(0.0, 1 - x * x - y * y));
      for (int p = 0; p < 2; ++p) {
        const double zz = p == 0 ? z : -z;
        float* out = patches[p].values.data() + 3 * (static_cast<std::size_t>(j) * n + (p == 0 ? i : m - i));
        double px, py, pz;
        if (shape == 0) {
          const double s = 1 + 0.05 * std::sin(5 * x + 1) * std::cos(4 * y);
          px = 1.4 * x * s, py = 0.9 * y * s, pz = 0.7 * zz * s;
        } else {
          const double s = 1 + 0.06 * std::sin(23 * x) * std::sin(19 * y) + 0.03 * std::cos(9 * zz);
          px = 0.8 * x * s, py = 1.2 * y * s, pz = 0.9 * zz * s;
        }
        out[0] = static_cast<float>(px);
        out[1] = static_cast<float>(py);
        out[2] = boundary ? 0.0f : static_cast<float>(pz);
      }
    }
  seams = {{0, 0, 1, 0, true}, {0, 1, 1, 3, true}, {0, 2, 1, 2, true}, {0, 3, 1, 1, true},
           {1, 0, 0, 0, true}, {1, 1, 0, 3, true}, {1, 2, 0, 2, true}, {1, 3, 0, 1, true}};
  return patches;
}

/// Outward unit normals of the grids by central differences (outward: away from the origin).
inline std::vector<codec::Grid3> grid_normals(const std::vector<codec::Grid3>& patches) {
  std::vector<codec::Grid3> out = patches;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const int n = patches[p].size();
    const auto& g = patches[p].values;
    auto at = [&](int i, int j, int c) { return g[3 * (static_cast<std::size_t>(std::clamp(j, 0, n - 1)) * n +
                                                        std::clamp(i, 0, n - 1)) + c]; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double du[3], dv[3], nn[3];
        for (int c = 0; c < 3; ++c) du[c] = at(i + 1, j, c) - at(i - 1, j, c), dv[c] = at(i, j + 1, c) - at(i, j - 1, c);
        nn[0] = du[1] * dv[2] - du[2] * dv[1];
        nn[1] = du[2] * dv[0] - du[0] * dv[2];
        nn[2] = du[0] * dv[1] - du[1] * dv[0];
        const double l = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        const double sgn = (nn[0] * at(i, j, 0) + nn[1] * at(i, j, 1) + nn[2] * at(i, j, 2)) < 0 ? -1 : 1;
        for (int c = 0; c < 3; ++c)
          out[p].values[3 * (static_cast<std::size_t>(j) * n + i) + c] =
              static_cast<float>(l > 0 ? sgn * nn[c] / l : 0.0);
      }
  }
  return out;
}

/// Row-major transform mapping the bounding box of `patches` to a unit box centred at the origin.
inline std::array<double, 16> unit_box(const std::vector<codec::Grid3>& patches) {
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  for (const auto& g : patches)
    for (std::size_t k = 0; k < g.values.size(); ++k)
      lo[k % 3] = std::min(lo[k % 3], double(g.values[k])), hi[k % 3] = std::max(hi[k % 3], double(g.values[k]));
  const double s = 1.0 / std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  return {s, 0, 0, -s * 0.5 * (lo[0] + hi[0]), 0, s, 0, -s * 0.5 * (lo[1] + hi[1]),
          0, 0, s, -s * 0.5 * (lo[2] + hi[2]), 0, 0, 0, 1};
}

inline codec::DecodedModel decoded_model(int level, int shape, bool normals = true) {
  codec::DecodedModel m;
  m.name = shape == 0 ? "ellipsoid" : "bumpy";
  m.geometry = two_patch_model(level, shape, m.seams);
  if (normals) m.normals = grid_normals(m.geometry);
  m.normalization = unit_box(m.geometry);
  m.detail_level = level;
  m.geometry_passes = 1;
  return m;
}

inline codec::PackModelInput pack_input(int level, int shape) {
  codec::PackModelInput in;
  in.name = shape == 0 ? "ellipsoid" : "bumpy";
  in.geometry = two_patch_model(level, shape, in.seams);
  in.normals = grid_normals(in.geometry);
  in.normalization = unit_box(in.geometry);
  return in;
}

/// A hidden window with an OpenGL 3.3 core context, or skip when there is no display.
class GlContext {
 public:
  GlContext(int width, int height) {
    if (!glfwInit()) return;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    window_ = glfwCreateWindow(width, height, "viewer test", nullptr, nullptr);
    if (window_) glfwMakeContextCurrent(window_);
  }
  ~GlContext() {
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
  }
  bool ok() const { return window_ != nullptr; }

 private:
  GLFWwindow* window_ = nullptr;
};

/// Coverage mask (1 = covered) of the model's triangles at grid level `level`, projected with `camera`.
inline std::vector<std::uint8_t> cpu_coverage(const morph::SceneModel& model, int level, const Camera& camera, int width,
                                              int height, const std::vector<std::vector<float>>* positions = nullptr) {
  const auto vp = view_projection(camera, width, height);
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(width) * height, 0);
  const int n = model.size(), s = (1 << level) + 1, stride = 1 << (model.level - level);
  const std::size_t per = 3u * n * n;
  for (int p = 0; p < model.num_patches; ++p) {
    auto pos = [&](int i, int j, int c) -> float {
      const std::size_t k = 3 * (static_cast<std::size_t>(j * stride) * n + i * stride) + c;
      if (positions) return (*positions)[p][k];
      float v = 0;
      for (int b = 0; b < model.bands; ++b) v += model.positions[(static_cast<std::size_t>(p) * model.bands + b) * per + k];
      return v;
    };
    std::vector<std::array<float, 2>> screen(static_cast<std::size_t>(s) * s);
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i) {
        const float x = pos(i, j, 0), y = pos(i, j, 1), z = pos(i, j, 2);
        float clip[4];
        for (int r = 0; r < 4; ++r) clip[r] = vp[r] * x + vp[4 + r] * y + vp[8 + r] * z + vp[12 + r];
        screen[j * s + i] = {(clip[0] / clip[3] * 0.5f + 0.5f) * width, (0.5f - clip[1] / clip[3] * 0.5f) * height};
      }
    auto hole = [&](int i, int j) {  // a drawn quad whose centre lies in a masked hole-mask quad
      if (model.holes.empty()) return false;
      const int q = 1 << model.hole_level;
      const int hi = std::min(int((i + 0.5) / (s - 1) * q), q - 1), hj = std::min(int((j + 0.5) / (s - 1) * q), q - 1);
      return model.holes[static_cast<std::size_t>(p) * q * q + static_cast<std::size_t>(hj) * q + hi] != 0;
    };
    auto raster = [&](const std::array<float, 2>& a, const std::array<float, 2>& b, const std::array<float, 2>& c) {
      const float area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
      if (std::abs(area) < 1e-12f) return;
      const int x0 = std::max(0, int(std::floor(std::min({a[0], b[0], c[0]}))));
      const int x1 = std::min(width - 1, int(std::ceil(std::max({a[0], b[0], c[0]}))));
      const int y0 = std::max(0, int(std::floor(std::min({a[1], b[1], c[1]}))));
      const int y1 = std::min(height - 1, int(std::ceil(std::max({a[1], b[1], c[1]}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const float px = x + 0.5f, py = y + 0.5f;
          const float w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
          const float w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
          const float w2 = 1 - w0 - w1;
          if (w0 >= 0 && w1 >= 0 && w2 >= 0) mask[static_cast<std::size_t>(y) * width + x] = 1;
        }
    };
    // Squared 3D distance between grid samples (i0, j0) and (i1, j1), as the renderer computes it.
    auto d2 = [&](int i0, int j0, int i1, int j1) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) {
        const double e = static_cast<double>(pos(i0, j0, k)) - pos(i1, j1, k);
        sum += e * e;
      }
      return sum;
    };
    for (int j = 0; j + 1 < s; ++j)
      for (int i = 0; i + 1 < s; ++i) {
        if (hole(i, j)) continue;
        const auto &a = screen[j * s + i], &b = screen[j * s + i + 1], &c = screen[(j + 1) * s + i],
                   &d = screen[(j + 1) * s + i + 1];
        // The renderer's split (and `geomip decode`'s): along the shorter diagonal; the four corner quads of a
        // patch and ties along a–d when i + j + p is even, b–c otherwise.
        bool along_ad = (i + j + p) % 2 == 0;
        const bool corner = (i == 0 || i == s - 2) && (j == 0 || j == s - 2);
        if (!corner) {
          const double ad = d2(i, j, i + 1, j + 1), bc = d2(i + 1, j, i, j + 1);
          if (ad < bc) along_ad = true;
          if (ad > bc) along_ad = false;
        }
        if (along_ad) {
          raster(a, b, d);
          raster(a, d, c);
        } else {
          raster(a, c, b);
          raster(c, d, b);
        }
      }
  }
  return mask;
}

/// 1 where a pixel differs from the background.
inline std::vector<std::uint8_t> image_coverage(const std::vector<std::uint8_t>& rgb) {
  std::vector<std::uint8_t> mask(rgb.size() / 3);
  for (std::size_t k = 0; k < mask.size(); ++k) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(rgb[3 * k + c]) - int(kBackground[c])));
    mask[k] = d > 3;
  }
  return mask;
}

inline double iou(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::size_t inter = 0, uni = 0;
  for (std::size_t k = 0; k < a.size(); ++k) inter += a[k] && b[k], uni += a[k] || b[k];
  return uni ? double(inter) / double(uni) : 1.0;
}

/// Pixels well inside the reference coverage (the pixel and its 8 neighbours covered) that the image leaves
/// at the background: cracks between patches or missing triangles. A closed model should have none.
inline std::size_t interior_misses(const std::vector<std::uint8_t>& image, const std::vector<std::uint8_t>& reference,
                                   int width, int height) {
  std::size_t misses = 0;
  for (int y = 1; y + 1 < height; ++y)
    for (int x = 1; x + 1 < width; ++x) {
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && reference[(std::size_t(y) + dy) * width + x + dx];
      misses += inside && !image[std::size_t(y) * width + x];
    }
  return misses;
}

inline std::size_t count(const std::vector<std::uint8_t>& m) {
  std::size_t c = 0;
  for (auto v : m) c += v != 0;
  return c;
}

/// Fraction of pixels whose largest channel difference exceeds `tol`.
inline double differing(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, int tol) {
  std::size_t diff = 0;
  for (std::size_t k = 0; k < a.size() / 3; ++k) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[3 * k + c]) - int(b[3 * k + c])));
    diff += d > tol;
  }
  return double(diff) / double(a.size() / 3);
}

}  // namespace geomip::viewer::testing
