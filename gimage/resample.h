// Geometry images (Gu, Gortler, Hoppe 2002) from a consistent parameterization: each quad patch's
// parameterization resampled on a regular (2^n+1)² grid over its unit square — the uniform remeshing of §4 of
// ../shared/seed/consistent-mesh-parameterizations.txt ("samples in the parameterized domain and derives
// inverse mapped 3D vertices ... by a point location algorithm ... using the barycentric coordinates") — plus
// a normal map of the original surface for shading coarse levels (the paper's Figure 7).
//
// Point location rasterizes each (u,v) triangle onto the grid: linear in triangles + samples. The inside test
// is exact (adaptive orientation predicate) with a symbolic-perturbation tie rule, so every grid sample gets
// exactly one triangle, also samples on edges, on vertices and on the square's boundary.
//
// Seams: a sample on a side shared by two patches (SideLink) is computed once, from the patch of the link
// whose (patch, side) is smaller, by walking that side's polyline in its one varying (u,v) coordinate, and
// copied, reversed as the link says, into the other patch. Corners are the corner vertices' exact positions.
// So shared samples are bit-identical in every image that holds them, whatever the layout (genus 0 by
// default: 2 patches, the second mirrored; genus 1: 4 patches glued periodically; a quad layout: any number
// of patches, any genus).
#pragma once

#include "param/consistent_parameterization.h"
#include "mesh/mesh.h"
#include "param/mesh_partition.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace geomip {

/// Largest supported grid level: 2^10+1 = 1025 samples per side.
constexpr int kMaxGeometryImageLevel = 10;

/// One patch's grid of 3-vectors (positions or unit normals), float32.
/// `values` holds size()² · 3 floats, row-major: sample (i, j) — column i, row j — is at (u, v) = (i, j) /
/// 2^level and its x, y, z are values[3·(j·size() + i) + 0..2]. So a row is a line of constant v, as in an
/// image whose x axis is u and whose y axis is v.
struct GeometryImage {
  int level = 0;
  std::vector<float> values;

  /// Samples per side, 2^level + 1.
  int size() const { return (1 << level) + 1; }
  const float* at(int i, int j) const {
    return values.data() + 3 * (static_cast<std::size_t>(j) * size() + i);
  }
  float* at(int i, int j) { return values.data() + 3 * (static_cast<std::size_t>(j) * size() + i); }
  Eigen::Vector3f sample(int i, int j) const {
    const float* p = at(i, j);
    return {p[0], p[1], p[2]};
  }
};

/// Every patch of one model, resampled.
struct GeometryImages {
  std::vector<GeometryImage> geometry;  ///< per patch, positions in the mesh's units (not normalized)
  std::vector<GeometryImage> normals;   ///< per patch, unit normals (empty when not asked for)
  std::vector<SideLink>
      adjacency;  ///< copied from the parameterization: adjacency[4·p + s] is side s of patch p
  /// Geometry samples no triangle claimed (only possible when the parameterization has flipped or degenerate
  /// (u,v) triangles, i.e. PatchParameterization::flipped > 0): they, and such normal-map texels, take the
  /// value of the nearest claimed sample on the grid (breadth-first). 0 for every valid parameterization.
  std::size_t uncovered_samples = 0;
};

struct ResampleOptions {
  /// Also resample the surface normals (area-weighted vertex normals of the mesh, interpolated
  /// barycentrically and renormalized).
  bool normals = true;
  /// Grid level of the normal maps; -1 = the geometry's level + 1, capped at kMaxGeometryImageLevel. Must be
  /// in [level, kMaxGeometryImageLevel] otherwise.
  int normal_level = -1;
};

/// Resamples every patch of `model` on the (2^level + 1)² grid of its unit square (Gu et al. 2002, §4 of the
/// paper): each sample's 3D position is the barycentric interpolation (in double, stored as float) of the
/// positions of the (u,v) triangle that contains it. Normal maps likewise at ResampleOptions::normal_level.
///
/// \param model  a result of parameterize_consistently(): patches with (u,v) in [0,1]², corners at (0,0),
///   (1,0), (1,1), (0,1), sides monotone along the square's sides, adjacency with one SideLink per (patch,
///   side) (a side without a link, e.g. on a disk-shaped test patch, is resampled from its own patch).
/// \param level  n in [0, kMaxGeometryImageLevel].
/// Linear in triangles + samples.
/// \throw InvalidInput for a level out of range, a model without patches, a patch whose arrays disagree (ids
///   out of range, corners or sides missing from the patch, a side not monotone in (u,v)), an adjacency that
///   links sides of different lengths in the mesh (different vertex sequences).
GeometryImages resample_geometry(const ModelParameterization& model, int level,
                                 const ResampleOptions& options = {});

/// Point location of the grid samples of one patch, as resample_geometry() does it.
struct GridLocation {
  int level = 0;
  /// Per sample (j·(2^level+1) + i): the claiming triangle, -1 for none.
  std::vector<int> triangle;
  /// Per sample: how many triangles claim it (1 for a valid patch; saturates at 255).
  std::vector<std::uint8_t> claims;
};

/// Which (u,v) triangle of `patch` contains each sample (i, j) = (u, v)·2^level. Exact orientation tests; a
/// sample on an edge or a vertex goes to the triangle that contains the sample moved infinitesimally toward
/// the square's centre (by (±ε, ±ε·η), ε ≫ η), so on a patch without flipped triangles that tiles the unit
/// square every sample, boundary included, is claimed exactly once. Triangles with (u,v) area <= 0 claim
/// nothing. \throw InvalidInput for a level outside [0, kMaxGeometryImageLevel] or triangle indices out of
/// range.
GridLocation locate_grid_samples(const PatchParameterization& patch, int level);

/// Area-weighted vertex normals of `mesh` (sum of the incident triangles' cross products, normalized); a
/// vertex of no or only degenerate triangles gets (0, 0, 1).
std::vector<Eigen::Vector3d> area_weighted_vertex_normals(const TriMesh& mesh);

}  // namespace geomip
