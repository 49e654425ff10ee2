// The plain mesh value type that flows between geomip's modules: indexed triangles, no half-edge structure.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace geomip {

/// An indexed triangle mesh as read from disk: `positions` (#V, any units) and `triangles` (#F, 0-based
/// indices into `positions`, counter-clockwise seen from outside). Nothing is assumed about manifoldness: that
/// is what `analyze_topology()` reports and `repair_mesh()` establishes.
struct TriMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<int, 3>> triangles;

  std::size_t num_vertices() const { return positions.size(); }
  std::size_t num_triangles() const { return triangles.size(); }
};

/// Axis-aligned bounding box of the vertices that triangles reference (unreferenced vertices are ignored,
/// as in Metro and in ../shared/meshes/README.md). Empty mesh → min = +inf, max = -inf.
struct BoundingBox {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
  double diagonal() const;
};
BoundingBox referenced_bounding_box(const TriMesh& mesh);

/// Per-vertex unit normals: the area-weighted sum of the incident triangles' normals (counter-clockwise
/// triangles give outward normals), normalized. A vertex without incident area (unreferenced, or only
/// degenerate triangles) gets (0, 0, 1). \pre every index is in range. Cost: O(#F + #V).
std::vector<Eigen::Vector3d> vertex_normals(const TriMesh& mesh);

/// Progress callback for long operations: `stage` is a short human-readable name, `fraction` ∈ [0,1] of that
/// stage. Called from the calling thread unless the operation's options say otherwise (parameterize_consistently
/// calls it from its worker threads, one call at a time); may be empty.
using ProgressCallback = std::function<void(const char* stage, double fraction)>;

}  // namespace geomip
