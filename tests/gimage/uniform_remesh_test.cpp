// Properties of uniform_remesh(): watertight, oriented, genus preserved, Euler counts, one face list for a
// consistent set, positions from the nested grids.
#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/gimage/remesh_checks.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

TEST(UniformRemesh, SphereIsWatertightOrientedAndGenusZero) {
  const ModelParameterization& m = test::parameterized("sphere");
  const GeometryImages g = resample_geometry(m, 6, {false, -1});
  for (int level = 0; level <= 6; ++level) {
    const UniformRemeshResult r = uniform_remesh(g, level);
    const std::size_t quads = 2u << (2 * level);  // 2·4^K
    EXPECT_EQ(r.mesh.triangles.size(), 2 * quads);
    EXPECT_EQ(r.mesh.positions.size(), quads + 2);  // quad sphere: V − 2Q + Q = 2
    test::expect_watertight_oriented(r.mesh, 0, "sphere M" + std::to_string(level), level > 0);
  }
  // Fine levels approach the unit ball's volume from inside.
  const double v = test::signed_volume(uniform_remesh(g, 6).mesh);
  EXPECT_GT(v, 0.9 * test::signed_volume(m.mesh));
  EXPECT_LE(v, 4.0 / 3.0 * M_PI);
}

TEST(UniformRemesh, TorusIsWatertightOrientedAndGenusOne) {
  const ModelParameterization& m = test::parameterized("torus");
  const GeometryImages g = resample_geometry(m, 6, {false, -1});
  for (int level = 1; level <= 6; ++level) {
    const UniformRemeshResult r = uniform_remesh(g, level);
    EXPECT_EQ(r.mesh.positions.size(), 4u << (2 * level));  // V = F_quads on a torus
    test::expect_watertight_oriented(r.mesh, 1, "torus M" + std::to_string(level));
  }
}

TEST(UniformRemesh, PositionsAreTheNestedSamples) {
  const ModelParameterization& m = test::parameterized("sphere");
  const GeometryImages g = resample_geometry(m, 5, {false, -1});
  const UniformRemeshResult r = uniform_remesh(g, 3);
  for (std::size_t p = 0; p < 2; ++p) {
    for (int j = 0; j <= 8; ++j) {
      for (int i = 0; i <= 8; ++i) {
        EXPECT_EQ(r.mesh.positions[r.grid_vertex[p][j * 9 + i]],
                  g.geometry[p].sample(4 * i, 4 * j).cast<double>());
      }
    }
  }
  EXPECT_THROW(uniform_remesh(g, 6), InvalidInput);
  EXPECT_THROW(uniform_remesh(g, -1), InvalidInput);
  EXPECT_THROW(uniform_remesh(GeometryImages{}, 1), InvalidInput);
  GeometryImages bad = g;
  bad.adjacency.pop_back();
  EXPECT_THROW(uniform_remesh(bad, 2), InvalidInput);
}

TEST(UniformRemesh, ConsistentSetSharesOneFaceList) {
  const auto& pair = test::deformed_sphere_pair();
  ASSERT_EQ(pair.size(), 2u);
  const GeometryImages a = resample_geometry(pair[0], 6, {false, -1});
  const GeometryImages b = resample_geometry(pair[1], 6, {false, -1});
  for (int level = 1; level <= 6; ++level) {
    const UniformRemeshResult ra = uniform_remesh(a, level);
    const UniformRemeshResult rb = uniform_remesh(b, level);
    EXPECT_EQ(ra.mesh.triangles, rb.mesh.triangles) << "M" << level;
    EXPECT_EQ(ra.mesh.positions.size(), rb.mesh.positions.size());
    EXPECT_NE(ra.mesh.positions, rb.mesh.positions);  // different shapes, same connectivity
    test::expect_watertight_oriented(ra.mesh, 0, "a M" + std::to_string(level));
    test::expect_watertight_oriented(rb.mesh, 0, "b M" + std::to_string(level));
  }
}

TEST(UniformRemesh, CubeLayoutPairIsWatertightWithSixPatchesAndOneFaceList) {
  const auto& pair = test::cube_layout_pair();
  ASSERT_EQ(pair.size(), 2u);
  std::vector<GeometryImages> images;
  for (const auto& m : pair) {
    ASSERT_EQ(m.patches.size(), 6u);
    for (const auto& patch : m.patches) EXPECT_EQ(patch.flipped, 0u);
    images.push_back(resample_geometry(m, 5));
    EXPECT_EQ(images.back().uncovered_samples, 0u);
    test::expect_seams_bit_identical(m, images.back());
  }
  for (int level = 0; level <= 5; ++level) {
    const UniformRemeshResult a = uniform_remesh(images[0], level);
    const UniformRemeshResult b = uniform_remesh(images[1], level);
    const std::size_t quads = 6u << (2 * level);  // 6·4^K
    EXPECT_EQ(a.mesh.triangles.size(), 2 * quads);
    EXPECT_EQ(a.mesh.positions.size(), quads + 2);  // Euler characteristic 2: V − 2Q + Q = 2
    EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
    test::expect_watertight_oriented(a.mesh, 0, "a M" + std::to_string(level));
    test::expect_watertight_oriented(b.mesh, 0, "b M" + std::to_string(level));
  }
}

}  // namespace
}  // namespace geomip
