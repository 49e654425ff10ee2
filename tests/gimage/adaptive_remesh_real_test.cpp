// Real meshes (../shared/meshes): adaptive remeshes at ε = 0.002, N = 8 are watertight, oriented and
// restricted (no T-vertices), far smaller than M8; the animals consistent set (tests/data/animals.corr.json)
// shares one adaptive face list.
#include "gimage/adaptive_remesh.h"
#include "gimage/uniform_remesh.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/gimage/remesh_checks.h"
#include "tools/model_inputs.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

TEST(RealAdaptiveRemesh, BunnyIsWatertightAndSmallerForLargerEpsilon) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "bunny.obj");
  TriMesh mesh = read_mesh(path);
  mesh = repair_mesh(mesh).mesh;
  const auto model =
      parameterize_consistently({test::automatic_input(mesh, "bunny")}, test::quick_options())[0];
  const GeometryImages g = resample_geometry(model, 8, {false, -1});
  const AdaptiveQuadErrors e = adaptive_quad_errors(model, g);
  std::size_t previous = std::size_t{2} * 2 * (1u << 16);  // uniform M8: 2 patches · 4^8 quads · 2
  for (double eps : {0.001, 0.002, 0.004}) {
    AdaptiveRemeshOptions options;
    options.epsilon = eps;
    const TriMesh remesh = adaptive_remesh(g, adaptive_quadtree({e}, g.adjacency, options));
    EXPECT_LT(remesh.triangles.size(), previous) << "eps " << eps;
    previous = remesh.triangles.size();
    test::expect_watertight_oriented(remesh, 0, "bunny eps " + std::to_string(eps));
  }
}

TEST(RealAdaptiveRemesh, AnimalsShareOneAdaptiveFaceList) {
  GEOMIP_REQUIRE_SHARED_MESH(horse, "horse.obj");
  const auto models =
      tools::prepare_models({}, std::string(GEOMIP_SOURCE_DIR) + "/tests/data/animals.corr.json",
                            "adaptive_remesh_real_test", true);
  ASSERT_EQ(models.inputs.size(), 4u);
  const auto params = parameterize_consistently(models.inputs, test::quick_options());
  std::vector<GeometryImages> images;
  std::vector<AdaptiveQuadErrors> errors;
  for (const auto& m : params) {
    images.push_back(resample_geometry(m, 7, {false, -1}));
    errors.push_back(adaptive_quad_errors(m, images.back()));
  }
  AdaptiveRemeshOptions options;
  options.epsilon = 0.002;
  const AdaptiveQuadtree tree = adaptive_quadtree(errors, images[0].adjacency, options);
  const TriMesh first = adaptive_remesh(images[0], tree);
  for (std::size_t k = 0; k < images.size(); ++k) {
    const TriMesh r = k == 0 ? first : adaptive_remesh(images[k], tree);
    EXPECT_EQ(r.triangles, first.triangles) << models.inputs[k].name;
    test::expect_watertight_oriented(r, 0, models.inputs[k].name + " adaptive");
  }
}

}  // namespace
}  // namespace geomip
