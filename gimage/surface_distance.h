// Metro-style surface distance between two triangle meshes: sampled one-sided distances both ways, symmetric
// Hausdorff and RMS, and the PSNR used by the consistent mesh parameterization paper (§5) to judge remeshes.
//
// Cignoni, Rocchini, Scopigno, "Metro: measuring error on simplified surfaces", Computer Graphics Forum
// 17(2), 1998. Each surface is sampled (all its vertices plus area-uniform random points on its faces,
// optionally points along its edges); for every sample the exact distance to the closest point of the OTHER
// surface is taken (an AABB tree over its triangles). Like Metro and MeshLab's "Hausdorff Distance" filter
// (Metro's code), the mean and RMS are plain averages over all samples: the face samples are area-uniform, so
// their average estimates the area integral, and the vertex (and edge) samples enter with the same weight as
// any other sample (a slight bias that Metro accepts for finding the maxima, which sit on vertices and
// edges).
#pragma once

#include "mesh/mesh.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace geomip {

struct SurfaceDistanceOptions {
  /// Area-uniform random samples on the faces of EACH surface. 0 (default) = automatic: 10 per face of the
  /// sampled surface, at least 10,000 and at most 1,000,000 (Metro takes 10·max(#faces) for both surfaces;
  /// 10 per own face keeps a coarse approximation cheap, and its RMS within about ±2% over seeds).
  std::size_t face_samples = 0;
  /// Sample every referenced vertex of each surface (Metro -v; on by default, as in MeshLab's filter).
  bool sample_vertices = true;
  /// Points spaced uniformly by length along the unique edges of each surface (Metro -e); 0 (default) = none.
  std::size_t edge_samples = 0;
  /// Seed of the random face samples: the same seed gives bit-identical results, whatever `threads` is.
  std::uint64_t seed = 0x5eed;
  /// Worker threads for the distance queries; 0 = std::thread::hardware_concurrency().
  unsigned threads = 0;
  /// Also return where the error is (OneSidedDistance::vertex_distance and face_rms): Metro's error
  /// colouring. Costs one float per sample while measuring.
  bool error_maps = false;
};

/// One-sided distance from the samples of surface `from` to the surface `to`, in the meshes' units.
struct OneSidedDistance {
  double max = 0;   ///< largest sample distance (one-sided Hausdorff distance, as sampled)
  double mean = 0;  ///< average sample distance
  double rms = 0;   ///< sqrt of the average squared sample distance
  std::size_t vertex_samples = 0;
  std::size_t edge_samples = 0;
  std::size_t face_samples = 0;
  std::size_t samples() const { return vertex_samples + edge_samples + face_samples; }
  /// The sample where `max` is attained (first such sample in sampling order), on the `from` surface.
  Eigen::Vector3d max_at = Eigen::Vector3d::Zero();

  /// Only with SurfaceDistanceOptions::error_maps, indexed like the `from` mesh:
  /// distance of each vertex to `to` (NaN: not sampled — unreferenced, or vertex sampling off) and the RMS
  /// distance of the face samples that fell in each triangle (NaN: no sample fell in it).
  std::vector<float> vertex_distance;
  std::vector<float> face_rms;
};

/// Result of `measure_surface_distance()`. Distances in the meshes' units; "_pct" in percent of
/// `bbox_diagonal`.
struct SurfaceDistance {
  OneSidedDistance original_to_approx;  ///< samples on the original, distances to the approximation
  OneSidedDistance approx_to_original;  ///< samples on the approximation, distances to the original
  double hausdorff = 0;                 ///< symmetric Hausdorff distance: max of the two one-sided maxima
  double rms = 0;            ///< symmetric RMS distance: the larger of the two one-sided RMS (Metro)
  double bbox_diagonal = 0;  ///< diagonal of the ORIGINAL's bounding box (its referenced vertices)
  double hausdorff_pct = 0;  ///< 100·hausdorff / bbox_diagonal
  double rms_pct = 0;        ///< 100·rms / bbox_diagonal
  /// 20·log10(bbox_diagonal / rms) in dB; +infinity when rms == 0 (identical surfaces).
  double psnr_db = 0;
};

/// Measures the distance between the surface `original` and its approximation `approx` as Metro does
/// (see the top of this file), both ways, and the PSNR of the consistent-parameterization paper (§5):
/// PSNR = 20·log10(peak / d), peak = `original`'s bounding-box diagonal, d = symmetric RMS distance.
///
/// Distances are exact point-to-triangle distances (CGAL AABB tree, double precision, one tree per mesh
/// built once). Triangles of zero area are not searched (their points lie on their edges, which other
/// triangles normally share) and get no face samples; their vertices are still sampled. Distances below the
/// floating-point resolution of the coordinates (64 ulps of the largest |coordinate| of both meshes) are
/// reported as 0, so identical meshes measure exactly 0 and a PSNR of +infinity.
///
/// Cost: O((F₀ + F₁) log F) for the trees plus one closest-point query (O(log F)) per sample, spread over
/// `options.threads` threads (timings: README, `geomip eval`).
///
/// \param original the reference surface (#V×3 positions, #F triangles); its bounding box gives the peak.
/// \param approx the approximation (remesh, decoded mesh), in the same coordinate frame.
/// \pre both meshes have at least one triangle of nonzero area, indices in range, finite coordinates.
/// \throw InvalidInput naming `measure_surface_distance` and the mesh when a precondition fails.
SurfaceDistance measure_surface_distance(const TriMesh& original, const TriMesh& approx,
                                         const SurfaceDistanceOptions& options = {});

/// Distance from each point to the closest point of `surface` (exact point–triangle distance through the same
/// AABB tree as measure_surface_distance()), in the mesh's units.
/// \throw InvalidInput as measure_surface_distance() for a bad `surface`.
std::vector<double> distances_to_surface(const TriMesh& surface, const std::vector<Eigen::Vector3d>& points);

/// The samples measure_surface_distance() takes on a surface (first stream): every referenced vertex, then
/// `face_samples` area-uniform random points on the faces (face by face), no edge samples. The same seed gives
/// the same points. \pre face_samples > 0. \throw InvalidInput as measure_surface_distance() for a bad mesh.
std::vector<Eigen::Vector3d> sample_surface_points(const TriMesh& mesh, std::size_t face_samples,
                                                   std::uint64_t seed);

/// Line and closest-point queries against one surface: its nonzero-area triangles in the same kind of AABB
/// tree as measure_surface_distance(), built once. Queries are const and may run concurrently. Used by the
/// encoder's normal-mesh resampling (codec/normal_mesh.h), which asks where a line along a predicted normal
/// crosses the surface, and then for the normals at the moved samples (the normal maps).
class SurfaceQuery {
 public:
  /// \throw InvalidInput as measure_surface_distance() for a bad `surface` (named "surface").
  explicit SurfaceQuery(const TriMesh& surface);
  ~SurfaceQuery();
  SurfaceQuery(const SurfaceQuery&) = delete;
  SurfaceQuery& operator=(const SurfaceQuery&) = delete;

  /// Of the points where the line {origin + t·direction} meets the surface, the one closest to `hint`,
  /// provided it lies within `radius` of `hint`; std::nullopt when there is none (or `direction` is zero or
  /// an argument is not finite). Where the line lies in a triangle's plane, the ends of its overlap count.
  std::optional<Eigen::Vector3d> crossing_near(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                               const Eigen::Vector3d& hint, double radius) const;

  /// The unit normal at the surface point closest to `p`: the area-weighted vertex normals (vertex_normals())
  /// interpolated barycentrically in the closest triangle and renormalized (as resample_geometry()'s normal
  /// maps); the triangle's own normal where that sum vanishes.
  Eigen::Vector3d normal_near(const Eigen::Vector3d& p) const;

  /// A closest point of the surface to `p` (exact point–triangle distance) and the triangle that holds it, as
  /// an index into the constructor's mesh (never a zero-area triangle). `p` must be finite.
  struct Closest {
    Eigen::Vector3d point;
    std::size_t triangle = 0;
  };
  Closest closest(const Eigen::Vector3d& p) const;

  /// closest() started from `p`'s projection onto the constructor's triangle `hint_triangle` (as unhinted
  /// where that triangle has zero area or is out of range): the same distance, faster when the hint is near
  /// the answer (a triangle the previous query of a nearby point returned). Where several triangles are
  /// equally close (at a shared edge or vertex) the one returned may differ from the unhinted query's.
  Closest closest(const Eigen::Vector3d& p, std::size_t hint_triangle) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace geomip
