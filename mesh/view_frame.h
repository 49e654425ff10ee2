// The frame a viewer shows a mesh in: which way is up and which way the model faces, as an axis-aligned
// rotation, and the transform of model units into the viewer's normalized frame (codec::PackModelInfo::
// normalization: y up, centred, largest extent 1). Used by `geomip convert --up, --front`.
#pragma once

#include "mesh/mesh.h"

#include <array>

namespace geomip {

/// The model's up axis: kAuto guesses it from the shape (ground_direction()); kX/kY/kZ take +x/+y/+z.
enum class UpAxis { kAuto, kX, kY, kZ };

/// The direction the model rests on, among ±x, ±y, ±z. The contact set of a face of the bounding box is the
/// referenced vertices within `band` × the box's extent of that face; its support polygon is the set's 2D
/// convex hull, relative to the box face's area.
///  1. The axis: that of the face with the largest support polygon (ties: the first of −y, +y, −x, +x,
///     −z, +z). A standing quadruped rests on its four feet (a hull over most of the footprint), while its
///     back, head or flank touch their box faces in a line or a patch; a head or a bust is longest from its
///     crown to its neck.
///  2. The end of that axis: the one whose support polygon grows less from `band` to 4 × `band` (the ratio of
///     the two hulls): legs, a neck or a flat cut keep their width there, a back or the crown of a head is a
///     dome and widens. A face with an empty (zero-area) support polygon is the top. When the two growths are
///     within 5 % of each other (or both faces are empty): the end with the larger support polygon (ties: −).
/// The meshes of ../shared/meshes and what each step measures on them are in docs/streaming.md ("Upright and
/// front"). Returns a unit axis vector (−y for an empty mesh). Cost: O(#V log #V).
Eigen::Vector3d ground_direction(const TriMesh& mesh, double band = 0.05);

/// The rotation (a signed permutation matrix, det +1) from model units to the viewer's axes: rows are the
/// model directions that become +x, +y, +z. +y = up (the opposite of ground_direction() for kAuto, else the
/// named axis). When `front` is a signed unit axis perpendicular to up, it becomes +x. Otherwise (zero, the
/// default, or along up) the front comes from the shape:
///  1. The front-back axis: of the two horizontal axes the one along which the box is longer (the length of
///     an animal; ties: the first in x, y, z order) — unless the body is clearly mirror-symmetric across it:
///     when the mean distance from its vertices (every ⌈#V / 4000⌉-th), reflected across the plane through
///     the area centroid normal to the length, to the nearest vertex (capped at 2 % of the box's diagonal) is
///     below 0.8 × that across the other axis, the length is a left-right span (a biped's arms) and the other
///     axis is the front-back one.
///  2. Upright or lying: upright when the vertices within 5 % of the height from the lowest span under 45 %
///     of the box along that axis (a neck, or two feet under the body); four legs or a lying body span more.
///  3. Its end: on an upright shape, the face — per end, among the vertices at least 40 % of the height above
///     the lowest, the 2D convex hull (across the axis: side × up) of those within 2 % of the axis's extent
///     from the extreme one; the end with the smaller hull (a nose, a muzzle, a snout; the back of a head is
///     a dome) when the other is at least 1.5 × as large. Otherwise (lying, or no clear tip) the end that
///     wins two of three cues, each a vote for the end where it is larger (ties: no vote; all three even: the
///     positive end):
///       reach — the largest up coordinate in the quarter of the axis at that end (a head above the tail);
///       width — the side extent (the third axis) of the tenth of the axis at that end (ears, horns, a
///               turned head; a tail is thin);
///       mass  — the distance of that end from the centroid of the enclosed volume (the body is behind the
///               head; signed tetrahedra from the box's centre, so an open mesh counts as closed by cones to
///               it; no vote when |volume| ≤ 1e-9 of the box's: a flat mesh).
///  4. A lying shape's front becomes +x and +z = x × y: a camera at positive yaw (in the xz plane from +z
///     towards +x) sees it from the side, its head turned towards the camera. An upright shape's front (its
///     face) becomes +z and +x = up × front: that camera sees the face, turned by its yaw.
/// The meshes of ../shared/meshes, each cue and the result are in docs/streaming.md ("Upright and front").
/// Cost: O(#V + #F) after ground_direction() (the mirror test looks at ≤ 4000 vertices against a grid).
Eigen::Matrix3d upright_rotation(const TriMesh& mesh, UpAxis up,
                                 const Eigen::Vector3d& front = Eigen::Vector3d::Zero());

/// Row-major 4×4 of x ↦ (R·x − c) / e: R = `rotation`, c and e the centre and the largest extent of the
/// rotated bounding box of the referenced vertices (the normalized frame: centred, largest extent 1; e = 1
/// for an empty or degenerate mesh).
std::array<double, 16> view_normalization(const TriMesh& mesh, const Eigen::Matrix3d& rotation);

/// True when row-major `r` is a rotation: orthonormal rows and determinant +1, each within `tolerance`.
bool is_rotation(const std::array<double, 9>& r, double tolerance = 1e-6);

/// The rotation R of a view_normalization() (its 3×3 is R / e), row-major; the identity when the 3×3 is not
/// a positively scaled rotation (no frame stored, or a hand-made matrix).
std::array<double, 9> frame_rotation(const std::array<double, 16>& normalization);

}  // namespace geomip
