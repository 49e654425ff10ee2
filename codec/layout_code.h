// A compact code for the seam table of a closed quad layout (pack format 9): the layout's quads are visited
// in a canonical order, and the table becomes a string of a few bits per quad instead of a partner index
// per side pair.
//
// The traversal is Isenburg & Snoeyink's Face Fixer (2000) restricted to quads without holes: a cycle of the
// open sides of the quads visited so far (each quad's sides 0–3 counter-clockwise, so the visited region
// lies on the cycle's left) and a gate, one side of that cycle, whose partner each step names:
//   F        a quad not visited yet: it becomes the next canonical patch, its side 0 glued to the gate (so
//   the
//            patch's rotation is fixed too), its sides 1–3 take the gate's place in the cycle; the new gate
//            is its side 3 (the one that meets the cycle's next side at a corner);
//   R / L    the cycle's next / previous side (the corner between them closes): both leave the cycle; the new
//            gate is the side before them (R) or after them (L);
//   S k      the side k places ahead in the cycle (k ≥ 2): the cycle splits in two; the part after that side
//            is pushed on a stack and the part between them continues (the gate: its first side).
// A cycle of two sides closes with R, and the next cycle comes from the stack; the code ends when the stack
// is empty. Bits, LSB first in each byte: F = 0, R = 10, L = 110, S = 111 then k − 1 in Elias gamma (as many
// zeros as its bit width minus one, then its bits from the top); zero bits pad the last byte.
// A layout of K quads takes about 4 bits per quad (the armadillo's 64 patches: 29 bytes against 139 for
// the side-pair form of format 7; the horse's 16: 8 against 27). Only genus 0 has a code here (a handle would
// need Face Fixer's merge step, a gluing across two cycles): other tables keep format 7's forms, as do tables
// whose sides are glued without reversal (not an oriented surface).
//
// A table has a code only in canonical order — patch c is the c-th quad the traversal visits from patch 0
// (starting at side 3) and its side 0 is the one it was reached by — so the pack writer reorders and rotates
// a layout's grids first (PackWriteOptions::canonical_layout); layout_order() gives that order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "codec/geometry_codec.h"  // PatchSeam, Grid3

namespace geomip::codec {

/// The canonical order of a layout: canonical patch c is input patch `patch[c]`, and canonical side s of
/// it is input side (s + rotation[c]) mod 4. `code` is the table's code (above) in that order.
struct LayoutOrder {
  std::vector<int> patch;
  std::vector<int> rotation;
  std::vector<std::uint8_t> code;
  bool identity() const;  ///< the input is in canonical order already (the table itself has this code)
};

/// The canonical order and code of `seams`, a table of `num_patches` patches as format 7's side-pair form
/// holds it (one seam per side in (patch, side) order, each its partner's mirror) of a closed oriented
/// genus-0 layout; nullopt for any other table (it then has no code). O(#seams) plus the splits' walks,
/// which are bounded (kMaxLayoutWalk; a table that needs more has no code).
std::optional<LayoutOrder> layout_order(const std::vector<PatchSeam>& seams, int num_patches);

/// Reads a code for `num_patches` patches from the start of `bytes`: on success `seams` is the table (in
/// canonical order, one seam per side in (patch, side) order, every seam reversed) and `used` the bytes the
/// code took. False on anything that is not such a code (a step that names no side, a cycle that cannot
/// close, quads left unvisited, non-zero padding, the bytes ending early, more than kMaxLayoutWalk steps of
/// walking). Never reads past `bytes`; O(num_patches) memory, allocated only when `bytes` can hold a code
/// of that many patches (a bit per patch at least).
bool read_layout_code(std::span<const std::uint8_t> bytes, int num_patches, std::vector<PatchSeam>& seams,
                      std::size_t& used);

/// The most sides the splits of one code may walk over in all (encoder and decoder alike).
inline constexpr std::size_t kMaxLayoutWalk = std::size_t{1} << 24;

/// `grid` turned so that its side (s + rotation) mod 4 becomes side s (the seam convention of PatchSeam).
Grid3 rotate_grid(const Grid3& grid, int rotation);

/// The same turn for a mask of 2^L × 2^L quads (row-major, as PackModelInfo::hole_mask).
std::vector<std::uint8_t> rotate_quad_mask(const std::vector<std::uint8_t>& mask, int rotation);

}  // namespace geomip::codec
