// Properties of uniform_remesh(): watertight, oriented, genus preserved, Euler counts, one face list for a
// consistent set, positions from the nested grids; split_along_shorter_diagonals() keeps all of them and
// splits every quad but the corner ones along its shorter diagonal.
#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/gimage/remesh_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

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

/// Checks `split` (split_along_shorter_diagonals of `fixed`, with the positions `models`) quad by quad: the
/// same four corners in the same cyclic order, corner quads as fixed, every other quad along the shorter
/// diagonal summed over the models (ties as fixed). Returns how many quads changed.
std::size_t expect_shorter_split(const UniformRemeshResult& fixed, const UniformRemeshResult& split, int level,
                                 const std::vector<const std::vector<Eigen::Vector3d>*>& models) {
  const int intervals = 1 << level, n = intervals + 1;
  std::size_t changed = 0, t = 0;
  for (std::size_t p = 0; p < fixed.grid_vertex.size(); ++p) {
    const auto& g = fixed.grid_vertex[p];
    for (int j = 0; j < intervals; ++j) {
      for (int i = 0; i < intervals; ++i, t += 2) {
        const int a = g[j * n + i], b = g[j * n + i + 1], c = g[(j + 1) * n + i + 1], d = g[(j + 1) * n + i];
        const std::array<int, 3> t0 = split.mesh.triangles[t], t1 = split.mesh.triangles[t + 1];
        const bool along_ac = t0 == std::array<int, 3>{a, b, c} && t1 == std::array<int, 3>{a, c, d};
        const bool along_bd = t0 == std::array<int, 3>{a, b, d} && t1 == std::array<int, 3>{b, c, d};
        EXPECT_TRUE(along_ac || along_bd) << "quad " << p << " " << i << " " << j;
        const bool same = t0 == fixed.mesh.triangles[t] && t1 == fixed.mesh.triangles[t + 1];
        changed += same ? 0 : 1;
        const bool corner = (i == 0 || i == intervals - 1) && (j == 0 || j == intervals - 1);
        double ac_minus_bd = 0;
        for (const auto* x : models) ac_minus_bd += ((*x)[a] - (*x)[c]).squaredNorm() - ((*x)[b] - (*x)[d]).squaredNorm();
        if (corner || ac_minus_bd == 0) {
          EXPECT_TRUE(same) << "corner or tie quad " << p << " " << i << " " << j;
        } else {
          EXPECT_EQ(along_ac, ac_minus_bd < 0) << "quad " << p << " " << i << " " << j;
        }
      }
    }
  }
  return changed;
}

TEST(UniformRemesh, ShorterDiagonalsKeepTheRemeshWatertightOrientedAndShareOneFaceList) {
  struct Case {
    std::vector<GeometryImages> images;
    int genus, min_level, max_level;
  };
  std::vector<Case> cases;
  {
    const auto& pair = test::deformed_sphere_pair();
    cases.push_back({{resample_geometry(pair[0], 6, {false, -1}), resample_geometry(pair[1], 6, {false, -1})},
                     0, 0, 6});
  }
  cases.push_back({{resample_geometry(test::parameterized("torus"), 6, {false, -1})}, 1, 1, 6});
  {
    const auto& pair = test::cube_layout_pair();
    cases.push_back({{resample_geometry(pair[0], 5), resample_geometry(pair[1], 5)}, 0, 0, 5});
  }
  for (const Case& c : cases) {
    for (int level = c.min_level; level <= c.max_level; ++level) {
      SCOPED_TRACE("patches " + std::to_string(c.images[0].geometry.size()) + ", M" + std::to_string(level));
      // Each model alone, then the whole set choosing together.
      std::vector<UniformRemeshResult> fixed;
      for (const auto& g : c.images) fixed.push_back(uniform_remesh(g, level));
      std::vector<const std::vector<Eigen::Vector3d>*> all;
      for (const auto& f : fixed) all.push_back(&f.mesh.positions);
      for (std::size_t m = 0; m < fixed.size(); ++m) {
        UniformRemeshResult split = fixed[m];
        split_along_shorter_diagonals(split, level, {&fixed[m].mesh.positions});
        const std::size_t changed = expect_shorter_split(fixed[m], split, level, {&fixed[m].mesh.positions});
        test::expect_watertight_oriented(split.mesh, c.genus, "alone", level > 0);
        if (level >= 3) {
          EXPECT_GT(changed, 0u);  // not the fixed split in disguise
        }
        if (level < 2) {
          EXPECT_EQ(changed, 0u);  // every quad touches a corner
        }
      }
      std::vector<UniformRemeshResult> joint = fixed;
      for (auto& r : joint) split_along_shorter_diagonals(r, level, all);
      for (std::size_t m = 0; m < joint.size(); ++m) {
        expect_shorter_split(fixed[m], joint[m], level, all);
        test::expect_watertight_oriented(joint[m].mesh, c.genus, "joint", level > 0);
        EXPECT_EQ(joint[m].mesh.triangles, joint[0].mesh.triangles);
      }
    }
  }
  UniformRemeshResult r = uniform_remesh(cases[0].images[0], 3);
  EXPECT_THROW(split_along_shorter_diagonals(r, 3, {}), InvalidInput);
  const std::vector<Eigen::Vector3d> short_positions(3);
  EXPECT_THROW(split_along_shorter_diagonals(r, 3, {&short_positions}), InvalidInput);
  EXPECT_THROW(split_along_shorter_diagonals(r, 4, {&r.mesh.positions}), InvalidInput);
}

}  // namespace
}  // namespace geomip
