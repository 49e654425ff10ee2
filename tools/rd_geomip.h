// Rate–distortion of geomip pack prefixes: decode the first N bytes of a pack, as a streaming client would
// have them, and measure the decoded mesh against the original with `geomip eval`'s Metro-style distance.
#pragma once

#include "codec/pack.h"
#include "param/mesh.h"

#include <cstdint>
#include <vector>

namespace geomip::tools {

struct PrefixRdOptions {
  /// Prefix sizes in bytes; empty = 24 sizes spaced geometrically from the manifest's end to the whole pack.
  std::vector<std::size_t> sizes;
  /// Grid level of the measured mesh; -1 = the pack's level (the wavelet's own subdivision fills what the
  /// prefix lacks).
  int output_level = -1;
  /// Decode timing: best of this many decodes of each prefix.
  int decode_repeats = 3;
};

struct PrefixRdPoint {
  std::size_t bytes = 0;
  double psnr_db = 0, hausdorff_pct = 0, rms_pct = 0;
  double decode_ms = 0;  ///< in-process decode_pack() of the prefix (mesh building not included)
  int detail_level = 0;
  std::size_t faces = 0;
};

/// One point per prefix size (model 0 of the pack against `original`). Prefixes ending inside the manifest are
/// skipped. \throw InvalidInput when the pack itself does not decode.
std::vector<PrefixRdPoint> prefix_rate_distortion(const std::vector<std::uint8_t>& pack, const TriMesh& original,
                                                  const PrefixRdOptions& options = {});

}  // namespace geomip::tools
