// The correspondence file of `geomip param --points CORR.json`:
//   {"models": [{"mesh": "horse.obj", "partition_points": [P,P,P,P], "auxiliary_points": [P,...],
//                "features": [P,...]}, ...]}
// Mesh paths are relative to the JSON file. A point P is a 0-based vertex index of the mesh file as written,
// or [x,y,z], snapped to the nearest vertex. Features correspond by order across models.
#pragma once

#include <Eigen/Core>

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
};

/// Parses CORR.json. \throw InvalidInput with the file name and the offending entry for a missing file,
/// malformed JSON, wrong types, or differing feature counts.
std::vector<ModelSpec> read_correspondence(const std::string& path);

}  // namespace geomip::tools
