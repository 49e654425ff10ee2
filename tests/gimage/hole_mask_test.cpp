// hole_mask(): quads over a filled hole are found, and only those.
#include "gimage/hole_mask.h"

#include "gimage/resample.h"
#include "gimage/surface_distance.h"
#include "mesh/mesh_repair.h"
#include "tests/gimage/gimage_fixtures.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

// A sphere with the faces around its north pole removed (an open mesh), and its repair.
struct HoledSphere {
  TriMesh open, repaired;
};
HoledSphere holed_sphere() {
  HoledSphere h;
  const TriMesh full = test::sphere(4);
  h.open.positions = full.positions;
  for (const auto& t : full.triangles) {
    const Eigen::Vector3d c = (full.positions[t[0]] + full.positions[t[1]] + full.positions[t[2]]) / 3;
    if (c.z() < 0.85) h.open.triangles.push_back(t);
  }
  h.repaired = repair_mesh(h.open).mesh;
  return h;
}

TEST(HoleMask, MasksOnlyQuadsOverTheFill) {
  const HoledSphere h = holed_sphere();
  ASSERT_GT(h.repaired.triangles.size(), h.open.triangles.size());
  const ModelParameterization model =
      parameterize_consistently({test::automatic_input(h.repaired, "holed")}, test::quick_options())[0];
  const int level = 6;
  const HoleMaskResult mask = hole_mask(model, h.open, level);
  ASSERT_EQ(mask.quads.size(), model.patches.size());
  EXPECT_GT(mask.fill_triangles, 0u);
  EXPECT_GT(mask.masked_quads, 0u);

  // Every masked quad's corners lie in or at the hole (z near or above the cut); every quad whose four corners
  // are well below the cut is kept.
  ResampleOptions no_normals;
  no_normals.normals = false;
  const GeometryImages images = resample_geometry(model, level, no_normals);
  const int q = 1 << level;
  std::vector<Eigen::Vector3d> masked_corners;
  std::size_t kept_low = 0, low = 0;
  for (std::size_t p = 0; p < images.geometry.size(); ++p) {
    for (int j = 0; j < q; ++j) {
      for (int i = 0; i < q; ++i) {
        const bool masked = mask.quads[p][static_cast<std::size_t>(j) * q + i] != 0;
        double max_z = -1;
        for (int c = 0; c < 4; ++c) {
          const Eigen::Vector3d v = images.geometry[p].sample(i + (c & 1), j + (c >> 1)).cast<double>();
          max_z = std::max(max_z, v.z());
          if (masked) masked_corners.push_back(v);
        }
        if (max_z < 0.6) {
          ++low;
          kept_low += !masked;
        }
      }
    }
  }
  EXPECT_EQ(kept_low, low);
  for (const Eigen::Vector3d& v : masked_corners) EXPECT_GT(v.z(), 0.7);
}

TEST(HoleMask, ClosedMeshHasNoMask) {
  const ModelParameterization& model = test::parameterized("sphere");
  const HoleMaskResult mask = hole_mask(model, model.mesh, 5);
  EXPECT_EQ(mask.fill_triangles, 0u);
  EXPECT_TRUE(mask.quads.empty());
}

}  // namespace
}  // namespace geomip
