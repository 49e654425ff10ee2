// Morph schedules and band-split models (CPU only).
#include "morph/scene_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "tests/viewer/viewer_fixtures.h"

namespace geomip::viewer {
namespace {

TEST(BandWeights, EndPointsAreExactlySourceAndTarget) {
  for (auto schedule : {morph::MorphSchedule::kLinear, morph::MorphSchedule::kWavelet})
    for (int bands : {1, 2, 5, 8}) {
      const auto w0 = morph::band_weights(0, bands, schedule), w1 = morph::band_weights(1, bands, schedule);
      for (int b = 0; b < bands; ++b) {
        EXPECT_EQ(w0.source[b], 1.0f);
        EXPECT_EQ(w0.target[b], 0.0f);
        EXPECT_EQ(w1.source[b], 0.0f);
        EXPECT_EQ(w1.target[b], 1.0f);
      }
    }
}

TEST(BandWeights, WaveletScheduleFadesFineSourceEarlyAndBringsFineTargetLate) {
  const int bands = 5;
  for (float t = 0; t <= 1.0f; t += 0.05f) {
    const auto w = morph::band_weights(t, bands, morph::MorphSchedule::kWavelet);
    EXPECT_NEAR(w.source[0] + w.target[0], 1.0f, 1e-6f) << "the coarse band interpolates";
    EXPECT_NEAR(w.target[0], t, 1e-6f);
    for (int b = 1; b < bands; ++b) {
      EXPECT_LE(w.source[b], w.source[b - 1] + 1e-6f) << "finer source bands leave no later";
      EXPECT_LE(w.target[b], w.target[b - 1] + 1e-6f) << "finer target bands arrive no earlier";
    }
    // monotone in t
    const auto w2 = morph::band_weights(t + 0.05f, bands, morph::MorphSchedule::kWavelet);
    for (int b = 0; b < bands; ++b) {
      EXPECT_LE(w2.source[b], w.source[b] + 1e-6f);
      EXPECT_GE(w2.target[b], w.target[b] - 1e-6f);
    }
  }
  const auto mid = morph::band_weights(0.5f, bands, morph::MorphSchedule::kWavelet);
  EXPECT_EQ(mid.source[bands - 1], 0.0f);
  EXPECT_EQ(mid.target[bands - 1], 0.0f);
}

TEST(SceneModel, NormalizationMapsToTheUnitBox) {
  const auto m = morph::make_scene_model(testing::decoded_model(4, 1));
  float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
  for (std::size_t k = 0; k < m.positions.size(); ++k)
    lo[k % 3] = std::min(lo[k % 3], m.positions[k]), hi[k % 3] = std::max(hi[k % 3], m.positions[k]);
  EXPECT_NEAR(std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}), 1.0f, 1e-5f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lo[c] + hi[c], 0.0f, 1e-5f);
  for (std::size_t k = 0; k < m.normals.size(); k += 3)
    EXPECT_NEAR(std::hypot(m.normals[k], m.normals[k + 1], m.normals[k + 2]), 1.0f, 1e-4f);
}

// Packs from `geomip convert` keep the mesh's units and an identity normalization: the scene fits the
// decoded bounding box to the centred unit box.
TEST(SceneModel, IdentityNormalizationFitsTheUnitBox) {
  auto raw = testing::decoded_model(4, 1);
  raw.normalization = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (auto& g : raw.geometry) {
    for (std::size_t k = 0; k < g.values.size(); ++k)
      g.values[k] = 0.05f * g.values[k] + (k % 3 == 1 ? 7.f : -3.f);
  }
  const auto m = morph::make_scene_model(raw);
  float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
  for (std::size_t k = 0; k < m.positions.size(); ++k)
    lo[k % 3] = std::min(lo[k % 3], m.positions[k]), hi[k % 3] = std::max(hi[k % 3], m.positions[k]);
  EXPECT_NEAR(std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}), 1.0f, 1e-4f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(lo[c] + hi[c], 0.0f, 1e-4f);
}

TEST(SceneModel, BandsSumToTheFullGeometry) {
  std::vector<codec::DecodedModel> by_drop;
  for (int d = 0; d < 3; ++d) {
    auto m = testing::decoded_model(4, d == 0 ? 1 : 0);  // any grids of one layout
    by_drop.push_back(m);
  }
  const auto banded = morph::make_banded_scene_model(by_drop);
  const auto full = morph::make_scene_model(by_drop[0]);
  ASSERT_EQ(banded.bands, 3);
  const auto sum = morph::evaluate_morph(banded, banded, 0.0f, morph::MorphSchedule::kWavelet);
  const std::size_t per = 3u * full.size() * full.size();
  for (int p = 0; p < full.num_patches; ++p)
    for (std::size_t k = 0; k < per; ++k) EXPECT_NEAR(sum[p][k], full.positions[p * per + k], 1e-5f);
}

// A rotation about an oblique axis, row-major.
std::array<double, 9> oblique_rotation(double angle) {
  const double a[3] = {1 / std::sqrt(3.0), -1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
  const double c = std::cos(angle), s = std::sin(angle);
  std::array<double, 9> r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[3 * i + j] = (i == j ? c : 0) + (1 - c) * a[i] * a[j];
  r[1] -= s * a[2], r[2] += s * a[1], r[3] += s * a[2], r[5] -= s * a[0], r[6] -= s * a[1], r[7] += s * a[0];
  return r;
}

TEST(Alignment, RecoversAKnownSimilarity) {
  for (int bands : {1, 3}) {
    morph::SceneModel reference;
    if (bands == 1) {
      reference = morph::make_scene_model(testing::decoded_model(4, 1));
    } else {
      std::vector<codec::DecodedModel> by_drop;
      for (int d = 0; d < bands; ++d) by_drop.push_back(testing::decoded_model(4, d == 0 ? 1 : 0));
      reference = morph::make_banded_scene_model(by_drop);
    }
    morph::SceneModel moved = reference;
    const morph::Similarity xf{0.6, oblique_rotation(2.1), {0.3, -0.2, 0.7}};
    morph::apply_similarity(xf, moved);
    const morph::Similarity back = morph::best_alignment(moved, reference);
    EXPECT_NEAR(back.scale, 1 / 0.6, 1e-4) << bands;
    morph::SceneModel restored = moved;
    morph::apply_similarity(back, restored);
    for (std::size_t k = 0; k < reference.positions.size(); ++k)
      ASSERT_NEAR(restored.positions[k], reference.positions[k], 2e-5f) << bands << " " << k;
    for (std::size_t k = 0; k < reference.normals.size(); ++k)
      ASSERT_NEAR(restored.normals[k], reference.normals[k], 2e-5f) << bands << " " << k;
    // A proper rotation: orthonormal with determinant +1 (no reflection).
    const auto& r = back.rotation;
    const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                       r[2] * (r[3] * r[7] - r[4] * r[6]);
    EXPECT_NEAR(det, 1.0, 1e-9);
  }
  EXPECT_THROW(morph::best_alignment(morph::make_scene_model(testing::decoded_model(4, 1)),
                                     morph::make_scene_model(testing::decoded_model(3, 1))),
               std::invalid_argument);
}

}  // namespace
}  // namespace geomip::viewer

namespace geomip::viewer {
namespace {

// Two consistent models of one shape in different poses (the second turned by 100° about an oblique axis, as
// meshes from different sources are): decoded with alignment, the mid-morph is the shape itself; without, the
// morph sweeps through the rotation and the midpoint shrinks.
TEST(DecodeScene, AlignedModelsMorphWithoutCollapsing) {
  auto a = testing::pack_input(4, 1);
  auto b = a;
  b.name = "turned";
  const auto r = oblique_rotation(100 * M_PI / 180);
  for (auto& g : b.geometry)
    for (std::size_t k = 0; k < g.values.size(); k += 3) {
      const float x = g.values[k], y = g.values[k + 1], z = g.values[k + 2];
      for (int i = 0; i < 3; ++i)
        g.values[k + i] = static_cast<float>(r[3 * i] * x + r[3 * i + 1] * y + r[3 * i + 2] * z);
    }
  b.normalization = testing::unit_box(b.geometry);
  const auto bytes = codec::write_pack({a, b});
  auto extent = [](const std::vector<float>& p) {
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (std::size_t k = 0; k < p.size(); ++k)
      lo[k % 3] = std::min(lo[k % 3], p[k]), hi[k % 3] = std::max(hi[k % 3], p[k]);
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  };
  for (bool align : {true, false}) {
    codec::Status status;
    std::size_t used = 0;
    const auto models =
        morph::decode_scene(bytes, morph::DecodeSettings{.bands = 1, .align = align}, status, used);
    ASSERT_EQ(models.size(), 2u);
    const auto mid = morph::evaluate_morph(models[0], models[1], 0.5f, morph::MorphSchedule::kLinear);
    std::vector<float> all;
    float worst = 0;  // largest distance of a mid-morph sample from the same sample of model 0
    const std::size_t per = 3u * models[0].size() * models[0].size();
    for (int p = 0; p < models[0].num_patches; ++p) {
      all.insert(all.end(), mid[p].begin(), mid[p].end());
      for (std::size_t k = 0; k < per; k += 3) {
        const float* m0 = &models[0].positions[p * per + k];
        worst = std::max(worst, std::hypot(mid[p][k] - m0[0], mid[p][k + 1] - m0[1], mid[p][k + 2] - m0[2]));
      }
    }
    if (align) {
      EXPECT_LT(worst, 2e-3f) << "aligned: the mid-morph is model 0 up to the coding error";
      EXPECT_NEAR(extent(all), 1.0f, 5e-3f);
    } else {
      EXPECT_GT(worst, 0.1f) << "unaligned: the mid-morph is far from either pose";
      EXPECT_LT(extent(all), 0.95f) << "unaligned: the mid-morph shrinks";
    }
  }
}

// --up: the chosen axis becomes +y (a rotation: lengths and handedness kept).
TEST(UpRotation, TurnsTheUpAxisIntoPlusY) {
  for (char up : {'x', 'y', 'z'}) {
    const auto r = morph::up_rotation(up).rotation;
    const int a = up - 'x';
    // Column a of R is R·e_a: it must be +y.
    EXPECT_EQ(r[static_cast<std::size_t>(a)], 0.0) << up;
    EXPECT_EQ(r[static_cast<std::size_t>(3 + a)], 1.0) << up;
    EXPECT_EQ(r[static_cast<std::size_t>(6 + a)], 0.0) << up;
    const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                       r[2] * (r[3] * r[7] - r[4] * r[6]);
    EXPECT_EQ(det, 1.0) << up;
  }
}

// The pack's frame (`geomip convert --up` stores a rotation in the normalization) is what the scene shows;
// DecodeSettings::up ('x', 'y', 'z': the viewer's --up) overrides it: the decode's box fitted, that axis of
// the model's units turned to +y.
TEST(ViewTransform, PackFrameByDefaultAndUpOverridesIt) {
  codec::DecodedModel m = testing::decoded_model(4, 0, false);
  // A frame that turns the model's +z into +y (−90° about x) and halves it.
  m.normalization = {0.5, 0, 0, 0.1, 0, 0, 0.5, 0.2, 0, -0.5, 0, 0.3, 0, 0, 0, 1};
  EXPECT_EQ(morph::view_transform(m), m.normalization);
  const morph::SceneModel framed = morph::make_scene_model(m);
  const auto& g = m.geometry[0].values;
  EXPECT_FLOAT_EQ(framed.positions[1], static_cast<float>(0.5 * g[2] + 0.2)) << "model z → scene y";
  for (char up : {'x', 'y', 'z'}) {
    const auto t = morph::view_transform(m, up);
    // the override ignores the pack's frame: box fitted (largest extent 1, centred), `up` → +y
    const int a = up - 'x';
    EXPECT_EQ(t[static_cast<std::size_t>(a)], 0.0) << up;
    EXPECT_GT(t[static_cast<std::size_t>(4 + a)], 0.0) << up;
    EXPECT_EQ(t[static_cast<std::size_t>(8 + a)], 0.0) << up;
    const morph::SceneModel s = morph::make_scene_model(m, up);
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (std::size_t k = 0; k < s.positions.size(); ++k)
      lo[k % 3] = std::min(lo[k % 3], s.positions[k]), hi[k % 3] = std::max(hi[k % 3], s.positions[k]);
    EXPECT_NEAR(std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}), 1.0f, 1e-5f) << up;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(lo[c] + hi[c], 0.0f, 1e-5f) << up;
  }
}

// The streaming viewer's decoder (morph::SceneDecoder, each byte decoded once, the bands of the wavelet morph
// from one decode) gives, after every update, exactly what a one-shot decode_scene of that prefix gives.
TEST(SceneDecoder, StreamEqualsOneShotDecodeOfEveryPrefix) {
  const auto bytes = codec::write_pack({testing::pack_input(5, 0), testing::pack_input(5, 1)});
  for (int bands : {1, 3}) {
    morph::SceneDecoder decoder(morph::DecodeSettings{.bands = bands});
    for (std::size_t n = 0; n <= bytes.size(); n += 1 + n / 7) {
      codec::Status status = codec::Status::kOk, one_status = codec::Status::kOk;
      std::size_t used = 0, one_used = 0;
      const auto models = decoder.update({bytes.data(), n}, status, used);
      const auto one =
          morph::decode_scene({bytes.data(), n}, morph::DecodeSettings{.bands = bands}, one_status, one_used);
      EXPECT_EQ(status, one_status) << n;
      EXPECT_EQ(used, one_used) << n;
      ASSERT_EQ(models.size(), one.size()) << n;
      for (std::size_t m = 0; m < models.size(); ++m) {
        EXPECT_EQ(models[m].bands, bands);
        EXPECT_EQ(models[m].detail_level, one[m].detail_level) << n;
        ASSERT_EQ(models[m].positions.size(), one[m].positions.size());
        EXPECT_EQ(std::memcmp(models[m].positions.data(), one[m].positions.data(),
                              models[m].positions.size() * sizeof(float)),
                  0)
            << n << " bytes, model " << m << ", " << bands << " bands";
        EXPECT_EQ(models[m].normals, one[m].normals) << n;
      }
    }
  }
}

// What the streaming viewer does with every prefix that arrives: morph::decode_scene never throws on a
// prefix, and gives either nothing (no geometry pass of model 0 yet) or both models at the pack's level,
// finite, with more bytes never giving fewer models.
TEST(DecodeScene, EveryPrefixOfAPackDecodesCleanly) {
  const auto bytes = codec::write_pack({testing::pack_input(4, 0), testing::pack_input(4, 1)});
  bool seen_models = false;
  for (std::size_t n = 0; n <= bytes.size(); n += (n < 64 ? 1 : 37)) {
    codec::Status status = codec::Status::kOk;
    std::size_t used = 0;
    std::vector<morph::SceneModel> models;
    for (int bands : {1, 3}) {
      ASSERT_NO_THROW(models = morph::decode_scene({bytes.data(), n}, morph::DecodeSettings{.bands = bands},
                                                   status, used))
          << n << " bytes";
      EXPECT_LE(used, n);
      if (models.empty()) {
        EXPECT_FALSE(seen_models && bands == 1) << "a longer prefix lost the models at " << n << " bytes";
        continue;
      }
      if (bands == 1) seen_models = true;
      ASSERT_EQ(models.size(), 2u);
      for (const auto& m : models) {
        EXPECT_EQ(m.level, 4);
        EXPECT_EQ(m.bands, bands);
        for (float v : m.positions) ASSERT_TRUE(std::isfinite(v)) << n << " bytes";
      }
    }
  }
  EXPECT_TRUE(seen_models);
  codec::Status status;
  std::size_t used = 0;
  EXPECT_EQ(morph::decode_scene(bytes, {}, status, used).size(), 2u);
  EXPECT_EQ(status, codec::Status::kOk);
  EXPECT_EQ(used, bytes.size());
}

}  // namespace
}  // namespace geomip::viewer
