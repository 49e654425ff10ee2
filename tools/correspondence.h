// The correspondence file of `geomip param --points CORR.json`:
//   {"models": [{"mesh": "horse.obj", "partition_points": [P,P,P,P], "auxiliary_points": [P,...],
//                "features": [P,...]}, ...]}
// Mesh paths are relative to the JSON file. A point P is a 0-based vertex index of the mesh file as written,
// or [x,y,z], snapped to the nearest vertex. Features correspond by order across models.
// Optional, top level: "layout": {"quads": [[a,b,c,d], ...]}, a quad layout shared by all models (see
// QuadLayout in param/mesh_partition.h): each model's partition_points are then the layout's corners (any
// number, the same in every model; quads index them, counter-clockwise seen from outside) and
// auxiliary_points must be empty.
// Optional per model, genus 0: "side_guides": [[P,...],[P,...],[P,...],[P,...]], any number of guides for each
// of the 4 paths instead of auxiliary_points (partition_mesh_guided(); `geomip param` writes it for a loop
// through the shape's tips).
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace geomip::tools {

/// A point as given: a vertex index of the mesh file, or a position.
struct PointSpec {
  long long index = -1;            ///< >= 0 when given as an index
  Eigen::Vector3d position{0, 0, 0};  ///< when index < 0
};

struct ModelSpec {
  std::string mesh;  ///< resolved against the JSON file's directory
  std::vector<PointSpec> partition_points, auxiliary_points, features;
  std::vector<std::vector<PointSpec>> side_guides;  ///< genus 0: 4 lists, or empty
  std::vector<std::array<int, 4>> layout_quads;  ///< the file's "layout" quads (the same in every model), or empty
};

/// Parses CORR.json. \throw InvalidInput with the file name and the offending entry for a missing file,
/// malformed JSON, wrong types, differing feature or corner counts, or a malformed "layout".
std::vector<ModelSpec> read_correspondence(const std::string& path);

}  // namespace geomip::tools
