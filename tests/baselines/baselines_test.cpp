// Property tests of the baseline codecs (codec/draco_baseline.h, codec/meshopt_baseline.h) and of the QEM
// decimation (codec/mesh_decimation.h) on synthetic meshes.
#include "baselines/draco_baseline.h"
#include "baselines/mesh_decimation.h"
#include "baselines/meshopt_baseline.h"
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace geomip {
namespace {

// Largest distance from a vertex of `a` to the nearest vertex of `b` (brute force; small meshes only).
double max_nearest_vertex_distance(const TriMesh& a, const TriMesh& b) {
  double worst = 0;
  for (const auto& p : a.positions) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& q : b.positions) best = std::min(best, (p - q).squaredNorm());
    worst = std::max(worst, std::sqrt(best));
  }
  return worst;
}

double largest_extent(const TriMesh& mesh) {
  const BoundingBox box = referenced_bounding_box(mesh);
  return (box.max - box.min).maxCoeff();
}

TEST(DracoBaseline, RoundTripKeepsFacesAndPositionsWithinTheQuantizationBound) {
  const TriMesh mesh = test::sphere(3);  // 768 faces
  for (int bits : {6, 10, 14}) {
    DracoOptions options;
    options.quantization_bits = bits;
    const DracoResult r = draco_encode(mesh, options);
    EXPECT_GT(r.bytes.size(), 0u);
    EXPECT_EQ(r.decoded.num_triangles(), mesh.num_triangles()) << "Q" << bits;
    EXPECT_EQ(r.decoded.num_vertices(), mesh.num_vertices()) << "Q" << bits;
    EXPECT_GT(r.decode_ms, 0.0);
    // Each coordinate within half a step of the uniform grid (step = extent / (2^Q - 1)), plus float
    // rounding.
    const double step = largest_extent(mesh) / (std::ldexp(1.0, bits) - 1);
    const double bound = std::sqrt(3.0) * (step / 2) * 1.0001 + 1e-6;
    EXPECT_LE(max_nearest_vertex_distance(r.decoded, mesh), bound) << "Q" << bits;
    EXPECT_LE(max_nearest_vertex_distance(mesh, r.decoded), bound) << "Q" << bits;

    TriMesh again;
    ASSERT_TRUE(draco_decode(r.bytes.data(), r.bytes.size(), again));
    EXPECT_EQ(again.num_triangles(), r.decoded.num_triangles());
  }
}

TEST(DracoBaseline, MoreBitsNeverFewerBytesNorLowerPsnr) {
  const TriMesh mesh = test::sphere(4);  // 3072 faces
  SurfaceDistanceOptions eval;
  eval.face_samples = 20000;
  std::size_t previous_bytes = 0;
  double previous_psnr = -std::numeric_limits<double>::infinity();
  for (int bits = 6; bits <= 16; ++bits) {
    DracoOptions options;
    options.quantization_bits = bits;
    const DracoResult r = draco_encode(mesh, options);
    const double psnr = measure_surface_distance(mesh, r.decoded, eval).psnr_db;
    EXPECT_GE(r.bytes.size(), previous_bytes) << "Q" << bits;
    EXPECT_GE(psnr, previous_psnr - 0.05) << "Q" << bits;  // sampling noise only
    previous_bytes = r.bytes.size();
    previous_psnr = psnr;
  }
  EXPECT_GT(previous_psnr, 80.0);
}

TEST(DracoBaseline, RejectsBadInputAndBadBytes) {
  DracoOptions options;
  options.quantization_bits = 0;
  EXPECT_THROW(draco_encode(test::cube(), options), InvalidInput);
  EXPECT_THROW(draco_encode(TriMesh{}, {}), InvalidInput);
  TriMesh bad = test::cube();
  bad.triangles[0][0] = 99;
  EXPECT_THROW(draco_encode(bad, {}), InvalidInput);

  TriMesh huge = test::sphere(2);  // finite coordinates, extent 6e38 beyond float range: Draco crashed
  for (auto& p : huge.positions) p *= 3e38;
  EXPECT_THROW(draco_encode(huge, {}), InvalidInput);

  const DracoResult r = draco_encode(test::sphere(2), {});
  TriMesh out;
  EXPECT_FALSE(draco_decode(nullptr, 0, out));
  const std::vector<std::uint8_t> junk(64, 0xAB);
  EXPECT_FALSE(draco_decode(junk.data(), junk.size(), out));
  EXPECT_TRUE(out.positions.empty());
  for (std::size_t n : {std::size_t{1}, r.bytes.size() / 4, r.bytes.size() / 2})
    EXPECT_FALSE(draco_decode(r.bytes.data(), n, out)) << n << " of " << r.bytes.size() << " bytes";
}

TEST(MeshoptBaseline, RoundTripWithinTheQuantizationBound) {
  const TriMesh mesh = test::sphere(3);
  for (int bits : {8, 12, 16}) {
    MeshoptCodecOptions options;
    options.quantization_bits = bits;
    const MeshoptCodecResult r = meshopt_encode(mesh, options);
    EXPECT_EQ(r.bytes, 28 + r.index_bytes + r.vertex_bytes);
    EXPECT_EQ(r.decoded.num_triangles(), mesh.num_triangles());
    EXPECT_EQ(r.decoded.num_vertices(), mesh.num_vertices());
    const double step = largest_extent(mesh) / (std::ldexp(1.0, bits) - 1);
    const double bound = std::sqrt(3.0) * (step / 2) * 1.001 + 1e-6;
    EXPECT_LE(max_nearest_vertex_distance(r.decoded, mesh), bound) << "Q" << bits;
    EXPECT_LE(max_nearest_vertex_distance(mesh, r.decoded), bound) << "Q" << bits;
  }
  MeshoptCodecOptions bad;
  bad.quantization_bits = 17;
  EXPECT_THROW(meshopt_encode(mesh, bad), InvalidInput);
}

TEST(MeshDecimation, HitsTheTargetWithoutDegenerateFaces) {
  const TriMesh mesh = test::sphere(5);  // 12,288 faces, closed
  for (std::size_t target : {std::size_t{200}, std::size_t{1000}, std::size_t{5000}}) {
    const DecimationResult r = decimate_mesh(mesh, target);
    const double faces = static_cast<double>(r.mesh.num_triangles());
    EXPECT_LE(faces, 1.05 * static_cast<double>(target)) << target;
    EXPECT_GE(faces, 0.9 * static_cast<double>(target)) << target;
    EXPECT_FALSE(r.used_sloppy) << target;  // a closed sphere never needs the fallback
    const TopologyReport topo = analyze_topology(r.mesh);
    EXPECT_EQ(topo.degenerate_faces, 0u) << target;
    EXPECT_EQ(topo.non_manifold_edges, 0u) << target;
    EXPECT_EQ(topo.unreferenced_vertices, 0u) << target;
    EXPECT_EQ(topo.boundary_edges, 0u) << target;
    // Half-edge collapses keep vertices in place: every output vertex is an input vertex.
    EXPECT_LT(max_nearest_vertex_distance(r.mesh, mesh), 1e-6) << target;
  }
}

TEST(MeshDecimation, LindstromTurkHitsTheTargetAndStaysManifold) {
  DecimationOptions options;
  options.method = DecimationMethod::kLindstromTurk;
  for (const TriMesh& mesh : {test::sphere(4), test::open_cylinder(48, 32)}) {
    const TopologyReport before = analyze_topology(mesh);
    for (std::size_t target : {std::size_t{300}, std::size_t{1000}}) {
      const DecimationResult r = decimate_mesh(mesh, target, options);
      const double faces = static_cast<double>(r.mesh.num_triangles());
      EXPECT_LE(faces, 1.02 * static_cast<double>(target)) << target;
      EXPECT_GE(faces, 0.9 * static_cast<double>(target)) << target;
      const TopologyReport topo = analyze_topology(r.mesh);
      EXPECT_EQ(topo.degenerate_faces, 0u) << target;
      EXPECT_TRUE(topo.manifold) << target;
      EXPECT_EQ(topo.unreferenced_vertices, 0u) << target;
      EXPECT_EQ(topo.boundary_loops, before.boundary_loops) << target;
      EXPECT_EQ(topo.genus, before.genus) << target;
    }
  }
  // Non-manifold input (a duplicated face: three faces on its edges) is refused, not mangled.
  TriMesh bad = test::tetrahedron();
  bad.triangles.push_back(bad.triangles[0]);
  EXPECT_THROW(decimate_mesh(bad, 2, options), InvalidInput);
}

TEST(MeshDecimation, TargetAboveTheFaceCountKeepsTheMesh) {
  const TriMesh mesh = test::sphere(2);
  const DecimationResult r = decimate_mesh(mesh, 10 * mesh.num_triangles());
  EXPECT_EQ(r.mesh.num_triangles(), mesh.num_triangles());
  EXPECT_EQ(r.mesh.num_vertices(), mesh.num_vertices());
  EXPECT_THROW(decimate_mesh(TriMesh{}, 10), InvalidInput);
  EXPECT_THROW(decimate_mesh(mesh, 0), InvalidInput);
}

}  // namespace
}  // namespace geomip
