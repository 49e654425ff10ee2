// What the viewer draws: decoded models (codec::DecodedModel, a plain value) turned into GPU-ready layers in
// the normalized frame, and the morph schedules of the paper's §6 (Praun, Sweldens, Schröder 2001, §6.2 and
// Fig. 9). CPU only (no GL): the renderer uploads these, `geomip morph` and the tests evaluate them directly.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "codec/pack.h"

namespace geomip::morph {

/// One model, ready for upload. Positions are stored as `bands` layers per patch, each a (2^level+1)² grid of
/// xyz floats in the normalized frame (view_transform(): the pack's normalization — `geomip convert --up`
/// stores the viewer's frame there — or, for an identity one, the decode's bounding box fitted to the centred
/// unit box): with one band the
/// layer is the geometry image itself; with B > 1 bands, layer 0 is the coarse base (the wavelet
/// reconstruction with the finest B−1 steps dropped) and layer m ≥ 1 is the detail D added by step B−1−m+1
/// (so the layers sum to the full geometry, and layer B−1 is the finest band).
struct SceneModel {
  std::string name;
  int level = 0;  ///< geometry grid level n: (2^n+1)² samples per patch
  int num_patches = 0;
  int bands = 1;
  std::vector<float> positions;  ///< [(patch·bands + band) · size² + j·size + i] · 3 + c
  int normal_level = -1;         ///< −1: no normal map (the renderer shades with screen-space derivatives)
  std::vector<float> normals;  ///< [patch · nsize² + j·nsize + i] · 3 + c, unit length, normalized frame
  /// [patch · 4^L + j·2^L + i], L = hole_level: 1 = quad not drawn; empty = none
  std::vector<std::uint8_t> holes;
  int hole_level = 0;    ///< level L ≤ level of the hole mask's grid
  int detail_level = 0;  ///< finest level that received detail (codec::DecodedModel::detail_level)
  int size() const { return (1 << level) + 1; }
};

/// One band: the model as it is, in the frame of view_transform(model, up). Throws std::invalid_argument if
/// the model has no patches or grids of different levels.
SceneModel make_scene_model(const codec::DecodedModel& model, char up = 0);

/// Band-split model for the wavelet-domain morph. `by_drop[d]` is the same bytes decoded with
/// drop_finest_steps = d, d = 0 … B−1 (B = by_drop.size() ≥ 1).
SceneModel make_banded_scene_model(const std::vector<codec::DecodedModel>& by_drop, char up = 0);

/// Row-major 4×4 from the model's units to the normalized frame that make_scene_model() applies: the
/// model's normalization when it is not the identity (and `up` is 0), else the decode's bounding box fitted
/// to the centred unit box, turned by up_rotation(up) when `up` is 'x', 'y' or 'z'.
std::array<double, 16> view_transform(const codec::DecodedModel& model, char up = 0);

enum class MorphSchedule { kLinear, kWavelet };

/// Per-band weights of source and target at morph time t ∈ [0,1] for `bands` bands (band 0 coarsest).
/// Linear: every band (1 − t, t). Wavelet (§6.2, Fig. 9): a band of fineness f = m/(B−1) keeps the source
/// until it fades out by t = 1 − f/2 and brings the target in from t = f/2, so the source's fine bands leave
/// early, the coarse bands interpolate gradually and the target's fine bands arrive late. Both schedules give
/// exactly the source at t = 0 and the target at t = 1.
struct BandWeights {
  std::vector<float> source, target;
};
BandWeights band_weights(float t, int bands, MorphSchedule schedule);

/// CPU evaluation of the morph between two models of the same layout (and bands): per patch, the
/// (2^level+1)² xyz grid at time t. Used by `geomip morph` and the tests.
std::vector<std::vector<float>> evaluate_morph(const SceneModel& source, const SceneModel& target, float t,
                                               MorphSchedule schedule);

/// True when the models can be morphed (same level, patch count and bands).
bool same_layout(const SceneModel& a, const SceneModel& b);

/// x ↦ scale · R · x + translation (R a rotation, row-major).
struct Similarity {
  double scale = 1;
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> translation{0, 0, 0};
};

/// The similarity that maps `model`'s samples closest onto the corresponding samples of `reference`, in the
/// least-squares sense over every grid sample of every patch (Umeyama 1991, Eigen::umeyama; the full
/// geometry, all bands summed). Consistent models correspond sample by sample, so this puts them in one pose
/// and size before an image-space morph: models from different sources (the horse stands on y, the pig lies
/// on z) otherwise sweep through a rotation and collapse at mid-morph. A reflection is never chosen.
/// \throw std::invalid_argument when the layouts differ (same_layout() is false).
Similarity best_alignment(const SceneModel& model, const SceneModel& reference);

/// Applies `xf` to `model`: band 0 (or the single band) as points, detail bands as vectors (scale · R),
/// normals rotated by R.
void apply_similarity(const Similarity& xf, SceneModel& model);

/// The rotation that turns the model's axis `up` ('x', 'y' or 'z'; anything else: identity) into +y, the
/// viewer's up (a right-handed rotation by 90° about the third axis: z-up data such as the horse stands up).
Similarity up_rotation(char up);

struct DecodeSettings {
  /// Wavelet bands for the wavelet-domain morph (1 = geometry only; B > 1 reconstructs one decode B times,
  /// with drop_finest_steps = 0 … B−1).
  int bands = 1;
  /// Align models 1, 2, … to model 0 (best_alignment) so that morphs between them do not rotate or shrink.
  bool align = true;
  /// SceneDecoder: false decodes every prefix from scratch (the cost before incremental decoding; for
  /// measurements only).
  bool incremental = true;
  /// 0: the pack's normalization (`geomip convert --up` stores the viewer's frame there; an identity one gets
  /// the decode's box fitted to the centred unit box, y up). 'x', 'y' or 'z': that axis of the model's units
  /// is up whatever the pack says (the decode's box fitted, then up_rotation()).
  char up = 0;
};

/// Decodes a byte prefix of a pack into scene models. Returns an empty vector (status in `status`) when the
/// prefix holds no geometry pass of model 0 yet. One-shot: a SceneDecoder updated once.
std::vector<SceneModel> decode_scene(std::span<const std::uint8_t> bytes, const DecodeSettings& settings,
                                     codec::Status& status, std::size_t& bytes_used);

/// decode_scene() for a stream (a class because its decoder state is reused): each update() takes the longer
/// prefix received so far and decodes only its new bytes (codec::PackDecoder: complete chunks only, as
/// decode_scene()); a banded model takes its B bands from that one decode (per-level reconstructions,
/// codec::PackDecoder::result with drop_finest_steps = 0 … B−1), not from B decodes. Returns what
/// decode_scene() returns for the same bytes.
class SceneDecoder {
 public:
  explicit SceneDecoder(const DecodeSettings& settings);
  std::vector<SceneModel> update(std::span<const std::uint8_t> bytes, codec::Status& status,
                                 std::size_t& bytes_used);

 private:
  DecodeSettings settings_;
  codec::PackDecoder decoder_;
};

}  // namespace geomip::morph
