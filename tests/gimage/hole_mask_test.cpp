// hole_mask(): quads over a filled hole are found, and only those; snap_hole_borders(): kept quads end on the
// original surface.
#include "gimage/hole_mask.h"

#include "gimage/resample.h"
#include "gimage/surface_distance.h"
#include "gimage/uniform_remesh.h"
#include "mesh/mesh_repair.h"
#include "tests/gimage/gimage_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <map>

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

// The quads a decoder keeps: the level-N uniform remesh (seams welded) without the masked quads' triangles.
TriMesh kept_quads(const GeometryImages& images, const HoleMaskResult& mask) {
  const int level = images.geometry.front().level, q = 1 << level;
  const TriMesh remesh = uniform_remesh(images, level).mesh;
  TriMesh mesh;
  mesh.positions = remesh.positions;
  for (std::size_t p = 0; p < mask.quads.size(); ++p) {
    for (std::size_t k = 0; k < mask.quads[p].size(); ++k) {
      if (mask.quads[p][k]) continue;
      const std::size_t quad = p * static_cast<std::size_t>(q) * q + k;  // triangles 2·quad and 2·quad + 1
      mesh.triangles.push_back(remesh.triangles[2 * quad]);
      mesh.triangles.push_back(remesh.triangles[2 * quad + 1]);
    }
  }
  return mesh;
}

// snap_hole_borders(): the kept quads' corners all lie on the open surface afterwards (before, the fill's
// corners stood off it, so the decoded border hung over the hole), nothing but fill samples moves, copies of
// one sample (seams) move alike, and the kept surface's largest distance to the open mesh shrinks. With the
// mask at the grid's level, and with a mask one level coarser (what `convert --hole-mask-level` stores),
// whose quads a decoder applies to the finer grid (refine_hole_quads()).
class SnapHoleBorders : public ::testing::TestWithParam<int> {};

TEST_P(SnapHoleBorders, KeptQuadsEndOnTheOriginalSurface) {
  const HoledSphere h = holed_sphere();
  const ModelParameterization model =
      parameterize_consistently({test::automatic_input(h.repaired, "holed")}, test::quick_options())[0];
  const int level = 6, mask_level = GetParam();
  HoleMaskResult mask = hole_mask(model, h.open, level);
  ASSERT_EQ(mask.fill_samples.size(), model.patches.size());
  if (mask_level < level) {
    const HoleMaskResult coarse = hole_mask(model, h.open, mask_level);
    mask.quads = refine_hole_quads(coarse.quads, mask_level, level);
    for (std::size_t p = 0; p < mask.quads.size(); ++p) {  // each fine quad carries its coarse quad's flag
      for (int j = 0; j < (1 << level); ++j) {
        for (int i = 0; i < (1 << level); ++i) {
          ASSERT_EQ(mask.quads[p][static_cast<std::size_t>(j) * (1 << level) + i],
                    coarse.quads[p][static_cast<std::size_t>(j >> (level - mask_level)) * (1 << mask_level) +
                                    (i >> (level - mask_level))]);
        }
      }
    }
  }
  ResampleOptions no_normals;
  no_normals.normals = false;
  const GeometryImages before = resample_geometry(model, level, no_normals);
  GeometryImages after = before;
  const std::size_t moved = snap_hole_borders(after, mask, h.open);
  EXPECT_GT(moved, 0u);

  const int n = (1 << level) + 1, q = n - 1;
  std::vector<Eigen::Vector3d> corners_before, corners_after;
  std::map<std::array<float, 3>, std::array<float, 3>> image_of;
  for (std::size_t p = 0; p < before.geometry.size(); ++p) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3f b = before.geometry[p].sample(i, j), a = after.geometry[p].sample(i, j);
        if (!mask.fill_samples[p][static_cast<std::size_t>(j) * n + i]) {
          EXPECT_EQ(a, b) << "a surface sample moved";
        }
        const auto [it, fresh] =
            image_of.emplace(std::array{b.x(), b.y(), b.z()}, std::array{a.x(), a.y(), a.z()});
        EXPECT_TRUE(fresh || it->second == (std::array{a.x(), a.y(), a.z()}))
            << "copies of a sample moved apart";
        bool kept_corner = false;
        for (int dj = -1; dj <= 0; ++dj) {
          for (int di = -1; di <= 0; ++di) {
            const int qi = i + di, qj = j + dj;
            if (qi >= 0 && qj >= 0 && qi < q && qj < q &&
                !mask.quads[p][static_cast<std::size_t>(qj) * q + qi])
              kept_corner = true;
          }
        }
        if (!kept_corner) continue;
        corners_before.push_back(b.cast<double>());
        corners_after.push_back(a.cast<double>());
      }
    }
  }
  const std::vector<double> off_before = distances_to_surface(h.open, corners_before);
  const std::vector<double> off_after = distances_to_surface(h.open, corners_after);
  EXPECT_GT(*std::max_element(off_before.begin(), off_before.end()), 1e-3);  // the fill stood off the surface
  EXPECT_LT(*std::max_element(off_after.begin(), off_after.end()), 1e-6);    // float rounding only

  SurfaceDistanceOptions options;
  options.face_samples = 200000;
  const double hanging_before =
      measure_surface_distance(h.open, kept_quads(before, mask), options).approx_to_original.max;
  const double hanging_after =
      measure_surface_distance(h.open, kept_quads(after, mask), options).approx_to_original.max;
  std::cout << "[ figures  ] kept surface's largest distance to the open sphere " << hanging_before << " -> "
            << hanging_after << " (" << moved << " border samples moved)\n";
  EXPECT_LT(hanging_after, 0.5 * hanging_before);
}

INSTANTIATE_TEST_SUITE_P(MaskLevels, SnapHoleBorders, ::testing::Values(6, 5));

TEST(HoleMask, ClosedMeshHasNoMask) {
  const ModelParameterization& model = test::parameterized("sphere");
  const HoleMaskResult mask = hole_mask(model, model.mesh, 5);
  EXPECT_EQ(mask.fill_triangles, 0u);
  EXPECT_TRUE(mask.quads.empty());
}

}  // namespace
}  // namespace geomip
