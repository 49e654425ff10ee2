// OpenGL 3.3 core renderer of geomip-view (needs a current context; libepoxy resolves the entry points).
// Each patch is drawn as a regular (2^k+1)² grid (one triangle strip per row) with no vertex attributes: the vertex shader fetches the
// positions from the model's geometry-image texture array (vertex texture fetch, level k = every 2^(n−k)-th
// sample of the nested grid, so patches that share bit-identical seam samples meet without cracks at every
// level); the fragment shader shades with the normal map (Blinn–Phong) so coarse levels keep their detail
// (paper Fig. 7), discards quads of filled holes, and draws a checkerboard in parameter space on request
// (paper Fig. 4e). Morph: the source and target textures are both bound and blended per wavelet band by the
// weights of scene_model.h (positions in the vertex shader, normals lerped and renormalized per fragment).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "stream_viewer/camera.h"
#include "morph/scene_model.h"

namespace geomip::viewer {

struct RenderSettings {
  Camera camera;
  int width = 1280, height = 720;
  int level = -1;          ///< grid level to draw (clamped to 0…n); −1 = the model's own level n
  int source = 0;          ///< model index
  int target = -1;         ///< model index to morph to; −1 = no morph
  float t = 0;             ///< morph time ∈ [0,1]
  morph::MorphSchedule schedule = morph::MorphSchedule::kLinear;
  bool checker = false;
  bool wireframe = false;
};

/// Background colour (RGB8) of every frame, for coverage tests.
inline constexpr std::uint8_t kBackground[3] = {26, 26, 31};

class Renderer {
 public:
  Renderer();  ///< compiles the shaders; throws std::runtime_error on a GL failure
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Replaces the models (uploads their textures). Throws std::invalid_argument for more than 8 bands.
  void set_models(const std::vector<morph::SceneModel>& models);
  int model_count() const;
  /// Grid level n of model `i`, or −1.
  int model_level(int i) const;

  /// Draws into the bound framebuffer (viewport width×height); clears it first.
  void draw(const RenderSettings& settings);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// An offscreen RGBA8 + depth framebuffer of a fixed size: frames are drawn here and read back (screenshots),
/// or blitted to the window.
class Offscreen {
 public:
  Offscreen(int width, int height);
  ~Offscreen();
  Offscreen(const Offscreen&) = delete;
  Offscreen& operator=(const Offscreen&) = delete;
  void bind() const;
  /// Copies the colour buffer to the default framebuffer (window of size window_w×window_h).
  void blit_to_window(int window_w, int window_h) const;
  /// RGB8, rows top to bottom.
  std::vector<std::uint8_t> read_rgb() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_, height_;
  unsigned fbo_ = 0, color_ = 0, depth_ = 0;
};

}  // namespace geomip::viewer
