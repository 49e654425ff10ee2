#include "morph/scene_model.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace geomip::morph {
namespace {

void check_model(const codec::DecodedModel& m, const char* fn) {
  if (m.geometry.empty()) throw std::invalid_argument(std::string(fn) + ": model has no patches");
  for (const auto& g : m.geometry)
    if (g.level != m.geometry[0].level || g.values.size() != 3u * g.size() * g.size())
      throw std::invalid_argument(std::string(fn) + ": patches of different levels or bad grid size");
}

// Affine part of the row-major normalization transform.
struct Affine {
  double m[3][4];
  explicit Affine(const std::array<double, 16>& a) {
    bool zero = true;
    for (double v : a) zero = zero && v == 0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m[r][c] = zero ? (r == c ? 1.0 : 0.0) : a[4 * r + c];
  }
  void point(const float* p, float* out) const {
    for (int r = 0; r < 3; ++r)
      out[r] = static_cast<float>(m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]);
  }
  void vector(const float* p, float* out) const {
    for (int r = 0; r < 3; ++r) out[r] = static_cast<float>(m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2]);
  }
  // inverse transpose of the linear part, for normals
  void normal(const float* n, float* out) const {
    const double(&a)[3][4] = m;
    double c[3][3];  // cofactor matrix = det · inverse transpose
    c[0][0] = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    c[0][1] = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    c[0][2] = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    c[1][0] = a[0][2] * a[2][1] - a[0][1] * a[2][2];
    c[1][1] = a[0][0] * a[2][2] - a[0][2] * a[2][0];
    c[1][2] = a[0][1] * a[2][0] - a[0][0] * a[2][1];
    c[2][0] = a[0][1] * a[1][2] - a[0][2] * a[1][1];
    c[2][1] = a[0][2] * a[1][0] - a[0][0] * a[1][2];
    c[2][2] = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    const double det = a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
    double v[3];
    for (int r = 0; r < 3; ++r)
      v[r] = (c[r][0] * n[0] + c[r][1] * n[1] + c[r][2] * n[2]) * (det < 0 ? -1 : 1);
    const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int r = 0; r < 3; ++r) out[r] = static_cast<float>(l > 0 ? v[r] / l : 0.0);
  }
};

void fill_common(const codec::DecodedModel& m, char up, SceneModel& s) {
  s.name = m.name;
  s.level = m.geometry[0].level;
  s.num_patches = static_cast<int>(m.geometry.size());
  s.detail_level = m.detail_level;
  const Affine xf(view_transform(m, up));
  s.normal_level = -1;
  s.normals.clear();
  if (m.normals.size() == m.geometry.size()) {
    const int nl = m.normals[0].level;
    bool ok = true;
    for (const auto& g : m.normals) ok = ok && g.level == nl && g.values.size() == 3u * g.size() * g.size();
    if (ok) {
      s.normal_level = nl;
      for (const auto& g : m.normals) {
        const std::size_t base = s.normals.size();
        s.normals.resize(base + g.values.size());
        for (std::size_t k = 0; k < g.values.size(); k += 3) xf.normal(&g.values[k], &s.normals[base + k]);
      }
    }
  }
  s.holes.clear();
  s.hole_level = std::clamp(m.hole_mask_level, 0, s.level);
  const std::size_t quads = std::size_t{1} << (2 * s.hole_level);
  if (m.hole_mask.size() == m.geometry.size()) {
    bool ok = true;
    for (const auto& h : m.hole_mask) ok = ok && h.size() == quads;
    if (ok)
      for (const auto& h : m.hole_mask) s.holes.insert(s.holes.end(), h.begin(), h.end());
  }
}

}  // namespace

// The pack's normalization, or — when it is the identity (packs from `geomip convert` store positions in the
// mesh's units and spend no manifest bytes on a frame) — the transform of this decode's bounding box to the
// centred unit box. (Recomputed per prefix: the box of a coarse level is within about 1 % of the full one.)
std::array<double, 16> view_transform(const codec::DecodedModel& m, char up) {
  const auto& n = m.normalization;
  const std::array<double, 16> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (up == 0 && n != identity && n != std::array<double, 16>{}) return n;
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& g : m.geometry) {
    for (std::size_t k = 0; k + 2 < g.values.size(); k += 3) {
      for (int c = 0; c < 3; ++c) {
        const double v = g.values[k + static_cast<std::size_t>(c)];
        if (std::isfinite(v)) lo[c] = std::min(lo[c], v), hi[c] = std::max(hi[c], v);
      }
    }
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(extent > 0) || !std::isfinite(extent)) return identity;
  std::array<double, 16> fit = identity;
  for (int c = 0; c < 3; ++c) {
    fit[static_cast<std::size_t>(5 * c)] = 1.0 / extent;
    fit[static_cast<std::size_t>(4 * c + 3)] = -0.5 * (lo[c] + hi[c]) / extent;
  }
  if (up == 0 || up == 'y') return fit;
  const auto& r = up_rotation(up).rotation;  // the fitted box is centred: turning it keeps it so
  std::array<double, 16> turned = identity;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t c = 0; c < 4; ++c) {
      double v = 0;
      for (std::size_t k = 0; k < 3; ++k) v += r[3 * i + k] * fit[4 * k + c];
      turned[4 * i + c] = v;
    }
  return turned;
}

SceneModel make_scene_model(const codec::DecodedModel& model, char up) {
  check_model(model, "make_scene_model");
  SceneModel s;
  fill_common(model, up, s);
  s.bands = 1;
  const Affine xf(view_transform(model, up));
  for (const auto& g : model.geometry) {
    const std::size_t base = s.positions.size();
    s.positions.resize(base + g.values.size());
    for (std::size_t k = 0; k < g.values.size(); k += 3) xf.point(&g.values[k], &s.positions[base + k]);
  }
  return s;
}

SceneModel make_banded_scene_model(const std::vector<codec::DecodedModel>& by_drop, char up) {
  if (by_drop.empty()) throw std::invalid_argument("make_banded_scene_model: no decodes");
  for (const auto& m : by_drop) check_model(m, "make_banded_scene_model");
  const auto& full = by_drop[0];
  for (const auto& m : by_drop)
    if (m.geometry.size() != full.geometry.size() || m.geometry[0].level != full.geometry[0].level)
      throw std::invalid_argument("make_banded_scene_model: decodes of different layouts");
  SceneModel s;
  fill_common(full, up, s);
  const int bands = static_cast<int>(by_drop.size());
  s.bands = bands;
  const Affine xf(view_transform(full, up));
  const std::size_t per = 3u * s.size() * s.size();
  s.positions.resize(per * s.num_patches * bands);
  for (int p = 0; p < s.num_patches; ++p)
    for (int b = 0; b < bands; ++b) {
      float* out = &s.positions[(static_cast<std::size_t>(p) * bands + b) * per];
      if (b == 0) {  // base: the coarsest reconstruction
        const auto& g = by_drop[bands - 1].geometry[p].values;
        for (std::size_t k = 0; k < per; k += 3) xf.point(&g[k], out + k);
      } else {  // band b: R(drop = B−1−b) − R(drop = B−b)
        const auto& fine = by_drop[bands - 1 - b].geometry[p].values;
        const auto& coarse = by_drop[bands - b].geometry[p].values;
        for (std::size_t k = 0; k < per; k += 3) {
          const float d[3] = {fine[k] - coarse[k], fine[k + 1] - coarse[k + 1], fine[k + 2] - coarse[k + 2]};
          xf.vector(d, out + k);
        }
      }
    }
  return s;
}

BandWeights band_weights(float t, int bands, MorphSchedule schedule) {
  BandWeights w;
  w.source.resize(bands);
  w.target.resize(bands);
  t = std::clamp(t, 0.0f, 1.0f);
  for (int b = 0; b < bands; ++b) {
    if (schedule == MorphSchedule::kLinear || bands == 1) {
      w.source[b] = 1 - t;
      w.target[b] = t;
      continue;
    }
    const float f = static_cast<float>(b) / static_cast<float>(bands - 1);  // 0 coarse … 1 finest
    const float span = 1.0f - 0.5f * f;
    w.source[b] = std::clamp(1.0f - t / span, 0.0f, 1.0f);
    w.target[b] = std::clamp((t - 0.5f * f) / span, 0.0f, 1.0f);
  }
  return w;
}

bool same_layout(const SceneModel& a, const SceneModel& b) {
  return a.level == b.level && a.num_patches == b.num_patches && a.bands == b.bands;
}

std::vector<std::vector<float>> evaluate_morph(const SceneModel& source, const SceneModel& target, float t,
                                               MorphSchedule schedule) {
  if (!same_layout(source, target))
    throw std::invalid_argument("evaluate_morph: models of different layouts");
  const auto w = band_weights(t, source.bands, schedule);
  const std::size_t per = 3u * source.size() * source.size();
  std::vector<std::vector<float>> out(source.num_patches, std::vector<float>(per, 0.0f));
  for (int p = 0; p < source.num_patches; ++p)
    for (int b = 0; b < source.bands; ++b) {
      const std::size_t off = (static_cast<std::size_t>(p) * source.bands + b) * per;
      for (std::size_t k = 0; k < per; ++k)
        out[p][k] += w.source[b] * source.positions[off + k] + w.target[b] * target.positions[off + k];
    }
  return out;
}

Similarity best_alignment(const SceneModel& model, const SceneModel& reference) {
  if (!same_layout(model, reference))
    throw std::invalid_argument("best_alignment: models of different layouts");
  const std::size_t per = 3u * model.size() * model.size();
  const std::size_t samples = per / 3 * static_cast<std::size_t>(model.num_patches);
  Eigen::Matrix3Xd from(3, samples), to(3, samples);
  from.setZero();
  to.setZero();
  for (int p = 0; p < model.num_patches; ++p)
    for (int b = 0; b < model.bands; ++b) {
      const std::size_t off = (static_cast<std::size_t>(p) * model.bands + b) * per;
      for (std::size_t k = 0; k < per; ++k) {
        const auto col = static_cast<Eigen::Index>(static_cast<std::size_t>(p) * (per / 3) + k / 3);
        from(static_cast<Eigen::Index>(k % 3), col) += model.positions[off + k];
        to(static_cast<Eigen::Index>(k % 3), col) += reference.positions[off + k];
      }
    }
  // Non-finite samples (none in decoded packs) would poison the fit: leave such models as they are.
  if (!from.allFinite() || !to.allFinite()) return {};
  const Eigen::Matrix4d m = Eigen::umeyama(from, to, true);
  if (!m.allFinite()) return {};
  Similarity xf;
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  xf.scale = std::cbrt(linear.determinant());
  if (!(xf.scale > 0)) return {};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) xf.rotation[static_cast<std::size_t>(3 * r + c)] = linear(r, c) / xf.scale;
    xf.translation[static_cast<std::size_t>(r)] = m(r, 3);
  }
  return xf;
}

void apply_similarity(const Similarity& xf, SceneModel& model) {
  const auto& r = xf.rotation;
  const auto rotate = [&](float* v, double s) {
    const double x = v[0], y = v[1], z = v[2];
    for (int i = 0; i < 3; ++i)
      v[i] = static_cast<float>(s * (r[static_cast<std::size_t>(3 * i)] * x +
                                     r[static_cast<std::size_t>(3 * i + 1)] * y +
                                     r[static_cast<std::size_t>(3 * i + 2)] * z));
  };
  const std::size_t per = 3u * model.size() * model.size();
  for (int p = 0; p < model.num_patches; ++p)
    for (int b = 0; b < model.bands; ++b) {
      float* layer = &model.positions[(static_cast<std::size_t>(p) * model.bands + b) * per];
      for (std::size_t k = 0; k < per; k += 3) {
        rotate(layer + k, xf.scale);
        if (b == 0)
          for (int c = 0; c < 3; ++c)
            layer[k + c] += static_cast<float>(xf.translation[static_cast<std::size_t>(c)]);
      }
    }
  for (std::size_t k = 0; k + 2 < model.normals.size(); k += 3) rotate(&model.normals[k], 1.0);
}

Similarity up_rotation(char up) {
  Similarity xf;
  if (up == 'z') xf.rotation = {1, 0, 0, 0, 0, 1, 0, -1, 0};  // −90° about x: +z → +y, +y → −z
  if (up == 'x') xf.rotation = {0, -1, 0, 1, 0, 0, 0, 0, 1};  // +90° about z: +x → +y, +y → −x
  return xf;
}

std::vector<SceneModel> decode_scene(std::span<const std::uint8_t> bytes, const DecodeSettings& settings,
                                     codec::Status& status, std::size_t& bytes_used) {
  return SceneDecoder(settings).update(bytes, status, bytes_used);
}

// Only complete, CRC-checked chunks: the last complete level stays.
SceneDecoder::SceneDecoder(const DecodeSettings& settings)
    : settings_(settings), decoder_({.partial_chunks = false}) {}

std::vector<SceneModel> SceneDecoder::update(std::span<const std::uint8_t> bytes, codec::Status& status,
                                             std::size_t& bytes_used) {
  if (!settings_.incremental) decoder_ = codec::PackDecoder({.partial_chunks = false});
  decoder_.update(bytes);
  codec::PackDecodeResult full = decoder_.result();
  status = full.status;
  bytes_used = full.bytes_used;
  if (full.models.empty() || full.models[0].geometry_passes == 0 || full.models[0].geometry.empty())
    return {};
  std::vector<SceneModel> out;
  const int bands = std::max(1, std::min(settings_.bands, full.models[0].geometry[0].level + 1));
  const auto align = [&] {
    if (!settings_.align) return;
    for (std::size_t m = 1; m < out.size(); ++m)
      if (same_layout(out[m], out[0])) apply_similarity(best_alignment(out[m], out[0]), out[m]);
  };
  if (bands == 1) {
    for (const auto& m : full.models) out.push_back(make_scene_model(m, settings_.up));
    align();
    return out;
  }
  std::vector<std::vector<codec::DecodedModel>> by_model(full.models.size());
  for (std::size_t m = 0; m < full.models.size(); ++m) by_model[m].push_back(std::move(full.models[m]));
  for (int d = 1; d < bands; ++d) {
    codec::PackDecodeResult r = decoder_.result(d, false);  // the same decode, finest d steps dropped
    for (std::size_t m = 0; m < by_model.size() && m < r.models.size(); ++m)
      by_model[m].push_back(std::move(r.models[m]));
  }
  for (const auto& decodes : by_model) out.push_back(make_banded_scene_model(decodes, settings_.up));
  align();
  return out;
}

}  // namespace geomip::morph
