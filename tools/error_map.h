// Metro-style error colouring: a mesh written as binary PLY with the distance of each face and vertex to the
// other surface as `quality` and as a colour ramp (blue = 0 … red ≥ scale), for MeshLab, Blender,
// CloudCompare.
#pragma once

#include "gimage/surface_distance.h"
#include "mesh/mesh.h"

#include <array>
#include <iosfwd>
#include <string>

namespace geomip::tools {

struct ErrorMapOptions {
  /// Distance shown as full red, in the meshes' units (> 0).
  double scale = 1;
  /// Quality values are written in percent of this length (the original's bounding-box diagonal).
  double diagonal = 1;
  /// One line in the PLY header, e.g. which surface the distances are measured to.
  std::string comment;
};

/// The colour of distance `d` on a blue–cyan–green–yellow–red ramp over [0, scale]; NaN → grey.
std::array<unsigned char, 3> error_color(double d, double scale);

/// Writes `mesh` (the sampled side of `distance`, which must carry error maps) as binary little-endian PLY:
/// vertex x y z (float), quality (distance in % of the diagonal), red green blue; face vertex_indices,
/// quality (RMS of the face's samples, % of the diagonal), red green blue. A vertex's colour is the
/// area-weighted RMS of its faces (viewers that show vertex colours only see the face errors, smoothed);
/// its quality is its own sampled distance (NaN if it was not sampled).
/// \throw InvalidInput when `distance` has no error maps for `mesh`.
void write_error_map(const TriMesh& mesh, const OneSidedDistance& distance, const ErrorMapOptions& options,
                     std::ostream& out);

}  // namespace geomip::tools
