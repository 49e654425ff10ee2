// Real meshes (../shared/meshes): point location exactly once, bit-identical seams, and uniform remeshes that
// are watertight, oriented, outward and of the input's genus at M1..M6.
#include "gimage/uniform_remesh.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/gimage/remesh_checks.h"
#include "tools/model_inputs.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace geomip {
namespace {

class RealRemesh : public ::testing::TestWithParam<const char*> {};

TEST_P(RealRemesh, WatertightOrientedAtLevels1To6) {
  GEOMIP_REQUIRE_SHARED_MESH(path, GetParam());
  TriMesh mesh = read_mesh(path);
  const TopologyReport r = analyze_topology(mesh);
  if (r.boundary_loops > 0 || !r.manifold) mesh = repair_mesh(mesh).mesh;
  const auto model =
      parameterize_consistently({test::automatic_input(mesh, GetParam())}, test::quick_options())[0];
  const int genus = r.genus.value_or(-1);
  // Point location at M8: every sample of every patch claimed by exactly one (u,v) triangle.
  for (const auto& patch : model.patches) {
    const GridLocation loc = locate_grid_samples(patch, 8);
    EXPECT_EQ(std::count(loc.claims.begin(), loc.claims.end(), std::uint8_t{1}),
              static_cast<std::ptrdiff_t>(loc.claims.size()));
  }
  const GeometryImages g = resample_geometry(model, 6);
  EXPECT_EQ(g.uncovered_samples, 0u);
  test::expect_seams_bit_identical(model, g);
  for (int level = 1; level <= 6; ++level) {
    const UniformRemeshResult remesh = uniform_remesh(g, level);
    EXPECT_EQ(remesh.mesh.triangles.size(), 2 * model.patches.size() << (2 * level));
    test::expect_watertight_oriented(remesh.mesh, genus,
                                     std::string(GetParam()) + " M" + std::to_string(level));
  }
  // M6 keeps the volume of the original within a few percent.
  EXPECT_NEAR(test::signed_volume(uniform_remesh(g, 6).mesh) / test::signed_volume(mesh), 1.0, 0.05);
}

INSTANTIATE_TEST_SUITE_P(
    Shared, RealRemesh, ::testing::Values("spot.obj", "bunny.obj", "bob.obj"),
    [](const ::testing::TestParamInfo<const char*>& param_info) {
      return std::string(param_info.param).substr(0, std::string(param_info.param).find('.'));
    });

// Automatic K-quad layouts (--patches K, issue 15): 0 flips, bit-identical seams, uniform remeshes watertight
// with the input's genus and V − E + F = 2 − 2g at every level (V = K·4^L + 2 − 2g).
TEST(RealRemeshLayouts, KPatchLayoutsAreFlipFreeWatertightAndOfTheRightEulerCharacteristic) {
  for (const auto& [name, patches] : {std::pair<const char*, int>{"spot.obj", 8}, {"bob.obj", 10}}) {
    GEOMIP_REQUIRE_SHARED_MESH(path, name);
    SCOPED_TRACE(std::string(name) + ", " + std::to_string(patches) + " patches");
    const auto prepared = tools::prepare_models({path}, "", "uniform_remesh_real_test", true, patches);
    const auto model = parameterize_consistently(prepared.inputs, test::quick_options())[0];
    ASSERT_EQ(model.patches.size(), static_cast<std::size_t>(patches));
    for (const auto& patch : model.patches) EXPECT_EQ(patch.flipped, 0u);
    const int genus = analyze_topology(prepared.inputs[0].mesh).genus.value_or(-1);
    const GeometryImages g = resample_geometry(model, 5);
    EXPECT_EQ(g.uncovered_samples, 0u);
    test::expect_seams_bit_identical(model, g);
    for (int level = 1; level <= 5; ++level) {
      const UniformRemeshResult remesh = uniform_remesh(g, level);
      const std::size_t quads = static_cast<std::size_t>(patches) << (2 * level);
      EXPECT_EQ(remesh.mesh.triangles.size(), 2 * quads);
      EXPECT_EQ(static_cast<long long>(remesh.mesh.positions.size()),
                static_cast<long long>(quads) + 2 - 2 * genus);
      test::expect_watertight_oriented(remesh.mesh, genus, std::string(name) + " M" + std::to_string(level));
    }
  }
}

// The consistent set of issue #3 (horse, cow, pig, spot; tests/data/animals.corr.json), prepared as the
// commands do: one face list at every level M1..M8, each remesh watertight, oriented and genus 0.
TEST(RealRemeshConsistentSet, AnimalsShareOneFaceListAtEveryLevel) {
  GEOMIP_REQUIRE_SHARED_MESH(horse, "horse.obj");
  const auto models = tools::prepare_models(
      {}, std::string(GEOMIP_SOURCE_DIR) + "/tests/data/animals.corr.json", "uniform_remesh_real_test", true);
  ASSERT_EQ(models.inputs.size(), 4u);
  const auto params = parameterize_consistently(models.inputs, test::quick_options());
  std::vector<GeometryImages> images;
  for (const auto& m : params) images.push_back(resample_geometry(m, 8, {false, -1}));
  for (int level = 1; level <= 8; ++level) {
    const UniformRemeshResult first = uniform_remesh(images[0], level);
    for (std::size_t k = 0; k < images.size(); ++k) {
      const UniformRemeshResult r = k == 0 ? first : uniform_remesh(images[k], level);
      EXPECT_EQ(r.mesh.triangles, first.mesh.triangles) << models.inputs[k].name << " M" << level;
      if (level <= 6)
        test::expect_watertight_oriented(r.mesh, 0, models.inputs[k].name + " M" + std::to_string(level));
    }
  }
}

}  // namespace
}  // namespace geomip
