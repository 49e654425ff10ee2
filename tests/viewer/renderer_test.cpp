// Renderer properties on synthetic decoded models (no pack needed): a frame covers the projected model,
// coarse levels cover their own coarse grid, holes are left out, morph end points equal the models alone,
// the wavelet schedule's midpoint differs from the linear one's. Needs a display (CTest runs it under
// xvfb-run with Mesa llvmpipe); skips without one.
#include "tests/viewer/viewer_fixtures.h"

#include <epoxy/gl.h>

namespace geomip::viewer {
namespace {

using namespace testing;

constexpr int kW = 320, kH = 240;

class RendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = new GlContext(kW, kH); }  // one context for the suite
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
  }
  void SetUp() override {
    if (!context_->ok()) GTEST_SKIP() << "no OpenGL 3.3 display (run under xvfb-run)";
    renderer_ = std::make_unique<Renderer>();
    target_ = std::make_unique<Offscreen>(kW, kH);
  }
  void TearDown() override {
    target_.reset();
    renderer_.reset();
  }
  std::vector<std::uint8_t> render(const RenderSettings& s) {
    target_->bind();
    renderer_->draw(s);
    glFinish();
    return target_->read_rgb();
  }
  RenderSettings settings() const {
    RenderSettings s;
    s.width = kW;
    s.height = kH;
    return s;
  }
  static GlContext* context_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<Offscreen> target_;
};

GlContext* RendererTest::context_ = nullptr;

// Band-split model whose band-limited versions are exact: drop d = every 2^d-th sample, bilinearly
// interpolated back to the full grid (what a linear-wavelet decode with drop_finest_steps = d gives).
morph::SceneModel banded_model(int level, int shape, int bands) {
  std::vector<codec::DecodedModel> by_drop;
  for (int d = 0; d < bands; ++d) {
    auto m = decoded_model(level, shape);
    const auto coarse = decoded_model(level - d, shape).geometry;
    for (std::size_t p = 0; p < m.geometry.size(); ++p) {
      auto& g = m.geometry[p];
      const auto& c = coarse[p];
      const int n = g.size(), cs = c.size(), st = 1 << d;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < 3; ++k) {
            const int i0 = std::min(i / st, cs - 2), j0 = std::min(j / st, cs - 2);
            const float fu = float(i - i0 * st) / st, fv = float(j - j0 * st) / st;
            auto at = [&](int a, int b) { return c.values[3 * (std::size_t(b) * cs + a) + k]; };
            g.values[3 * (std::size_t(j) * n + i) + k] = (1 - fv) * ((1 - fu) * at(i0, j0) + fu * at(i0 + 1, j0)) +
                                                         fv * ((1 - fu) * at(i0, j0 + 1) + fu * at(i0 + 1, j0 + 1));
          }
    }
    by_drop.push_back(std::move(m));
  }
  return morph::make_banded_scene_model(by_drop);
}

TEST_F(RendererTest, FrameCoversTheProjectedModelAtEveryLevel) {
  const morph::SceneModel model = morph::make_scene_model(decoded_model(6, 0));
  renderer_->set_models({model});
  for (int level : {6, 4, 2}) {
    RenderSettings s = settings();
    s.level = level;
    const auto image = image_coverage(render(s));
    const auto reference = cpu_coverage(model, level, s.camera, kW, kH);
    ASSERT_GT(count(reference), std::size_t(kW * kH / 20)) << "the model should fill a good part of the frame";
    EXPECT_GT(iou(image, reference), 0.97) << "level " << level;
    EXPECT_EQ(interior_misses(image, reference, kW, kH), 0u) << "no cracks at level " << level;
  }
}

TEST_F(RendererTest, CheckerboardAndWireframeKeepTheSilhouette) {
  const morph::SceneModel model = morph::make_scene_model(decoded_model(5, 1));
  renderer_->set_models({model});
  RenderSettings s = settings();
  const auto plain = render(s);
  s.checker = true;
  const auto checker = render(s);
  EXPECT_GT(iou(image_coverage(plain), image_coverage(checker)), 0.99);
  EXPECT_GT(differing(plain, checker, 20), 0.05) << "checkerboard mode should change the colours";
  s.checker = false;
  s.wireframe = true;
  const auto wire = image_coverage(render(s));
  EXPECT_LT(count(wire), count(image_coverage(plain))) << "wireframe draws only edges";
  EXPECT_GT(count(wire), 0u);
}

TEST_F(RendererTest, HoleMaskQuadsAreNotDrawn) {
  morph::SceneModel model = morph::make_scene_model(decoded_model(5, 0));
  model.hole_level = 3;  // a coarser mask than the grid, as packs may store it
  const int q = 1 << model.hole_level;
  model.holes.assign(static_cast<std::size_t>(2) * q * q, 0);
  for (int p = 0; p < 2; ++p)  // a square hole in the middle of both patches: a tunnel through the body
    for (int j = q / 4; j < 3 * q / 4; ++j)
      for (int i = q / 4; i < 3 * q / 4; ++i) model.holes[(static_cast<std::size_t>(p) * q + j) * q + i] = 1;
  renderer_->set_models({model});
  RenderSettings s = settings();
  s.camera.yaw = 0;  // look at patch 0 (z > 0) head on
  s.camera.pitch = 0;
  const auto image = image_coverage(render(s));
  const auto reference = cpu_coverage(model, model.level, s.camera, kW, kH);
  EXPECT_GT(iou(image, reference), 0.97);
  morph::SceneModel full = model;
  full.holes.clear();
  EXPECT_LT(count(image), count(cpu_coverage(full, full.level, s.camera, kW, kH)) * 0.95)
      << "the background should show through the holes";
}

TEST_F(RendererTest, MorphEndPointsRenderLikeEachModelAlone) {
  const std::vector<morph::SceneModel> banded = {banded_model(6, 0, 4), banded_model(6, 1, 4)};
  const std::vector<morph::SceneModel> plain = {morph::make_scene_model(decoded_model(6, 0)), morph::make_scene_model(decoded_model(6, 1))};
  for (auto schedule : {morph::MorphSchedule::kLinear, morph::MorphSchedule::kWavelet}) {
    const auto& models = schedule == morph::MorphSchedule::kLinear ? plain : banded;
    renderer_->set_models(models);
    RenderSettings s = settings();
    s.schedule = schedule;
    const auto a_alone = render(s);
    s.source = 1;
    const auto b_alone = render(s);
    s.source = 0;
    s.target = 1;
    s.t = 0;
    const auto t0 = render(s);
    s.t = 1;
    const auto t1 = render(s);
    EXPECT_LT(differing(t0, a_alone, 2), 0.001);
    EXPECT_LT(differing(t1, b_alone, 2), 0.001);
    EXPECT_GT(differing(a_alone, b_alone, 2), 0.05) << "the two models should look different";
    // the frame at t = 0.5 covers the CPU-evaluated morph
    s.t = 0.5f;
    const auto mid = image_coverage(render(s));
    const auto geometry = morph::evaluate_morph(models[0], models[1], 0.5f, schedule);
    EXPECT_GT(iou(mid, cpu_coverage(models[0], models[0].level, s.camera, kW, kH, &geometry)), 0.97);
  }
}

TEST_F(RendererTest, WaveletMidpointDiffersFromLinearMidpoint) {
  const std::vector<morph::SceneModel> banded = {banded_model(6, 0, 4), banded_model(6, 1, 4)};
  renderer_->set_models(banded);
  RenderSettings s = settings();
  s.target = 1;
  s.t = 0.5f;
  s.schedule = morph::MorphSchedule::kLinear;
  const auto linear = render(s);
  s.schedule = morph::MorphSchedule::kWavelet;
  const auto wavelet = render(s);
  EXPECT_GT(differing(linear, wavelet, 8), 0.02) << "the schedules should give visibly different midpoints";
  // geometry: at the midpoint the wavelet schedule has neither model's finest band, the linear one half of each
  const auto gl = morph::evaluate_morph(banded[0], banded[1], 0.5f, morph::MorphSchedule::kLinear);
  const auto gw = morph::evaluate_morph(banded[0], banded[1], 0.5f, morph::MorphSchedule::kWavelet);
  double diff = 0;
  for (std::size_t p = 0; p < gl.size(); ++p)
    for (std::size_t k = 0; k < gl[p].size(); ++k) diff = std::max(diff, double(std::abs(gl[p][k] - gw[p][k])));
  EXPECT_GT(diff, 1e-3);
}

}  // namespace
}  // namespace geomip::viewer
