// Properties of resample_geometry(): exact reproduction of planar patches, every sample located exactly once,
// bit-identical seams and corners, normals.
#include "gimage/resample.h"
#include "mesh/errors.h"
#include "tests/gimage/gimage_fixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace geomip {
namespace {

// One disk patch over the unit square: the flat grid test::grid(cells), (u,v) = (x,y), interior vertices
// jittered in both (u,v) and 3D (so the surface stays the plane), positions mapped by `affine`.
ModelParameterization planar_patch(int cells, const Eigen::Matrix<double, 3, 2>& linear,
                                   const Eigen::Vector3d& offset, double jitter) {
  ModelParameterization m;
  TriMesh grid = test::grid(cells);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-jitter, jitter);
  PatchParameterization p;
  for (std::size_t v = 0; v < grid.positions.size(); ++v) {
    Eigen::Vector2d uv = grid.positions[v].head<2>();
    const bool interior = uv.x() > 0 && uv.x() < 1 && uv.y() > 0 && uv.y() < 1;
    if (interior) uv += Eigen::Vector2d(d(rng), d(rng)) / cells;
    p.vertices.push_back(static_cast<int>(v));
    p.uv.push_back(uv);
    m.mesh.positions.push_back(linear * uv + offset);
  }
  m.mesh.triangles = grid.triangles;
  p.triangles = grid.triangles;
  auto id = [&](int i, int j) { return j * (cells + 1) + i; };
  p.corners = {id(0, 0), id(cells, 0), id(cells, cells), id(0, cells)};
  for (int k = 0; k <= cells; ++k) {
    p.sides[0].push_back(id(k, 0));
    p.sides[1].push_back(id(cells, k));
    p.sides[2].push_back(id(cells - k, cells));
    p.sides[3].push_back(id(0, cells - k));
  }
  m.patches.push_back(p);
  return m;
}

TEST(Resample, AxisAlignedPlanarPatchReproducesItselfExactly) {
  Eigen::Matrix<double, 3, 2> identity = Eigen::Matrix<double, 3, 2>::Zero();
  identity(0, 0) = identity(1, 1) = 1;
  for (double jitter : {0.0, 0.3}) {
    const ModelParameterization m = planar_patch(8, identity, Eigen::Vector3d::Zero(), jitter);
    for (int level = 0; level <= 7; ++level) {
      const GeometryImages g = resample_geometry(m, level);
      EXPECT_EQ(g.uncovered_samples, 0u);
      const GeometryImage& img = g.geometry[0];
      const int n = img.size();
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const float expected[3] = {static_cast<float>(std::ldexp(i, -level)),
                                     static_cast<float>(std::ldexp(j, -level)), 0.0f};
          ASSERT_TRUE(test::same_bits(img.at(i, j), expected))
              << "level " << level << " jitter " << jitter << " sample " << i << "," << j << ": "
              << img.sample(i, j).transpose();
        }
      }
      for (int j = 0; j < g.normals[0].size(); ++j) {
        for (int i = 0; i < g.normals[0].size(); ++i) {
          ASSERT_EQ(g.normals[0].sample(i, j), Eigen::Vector3f(0, 0, 1)) << i << "," << j;
        }
      }
    }
  }
}

TEST(Resample, TiltedPlanarPatchReproducesThePlane) {
  Eigen::Matrix<double, 3, 2> linear;
  linear << 2.0, 0.5, -1.0, 3.0, 0.7, -0.4;
  const Eigen::Vector3d offset(10, -5, 2);
  const ModelParameterization m = planar_patch(16, linear, offset, 0.35);
  for (int level : {2, 5, 8}) {
    const GeometryImages g = resample_geometry(m, level);
    const GeometryImage& img = g.geometry[0];
    for (int j = 0; j < img.size(); ++j) {
      for (int i = 0; i < img.size(); ++i) {
        const Eigen::Vector3d expected =
            linear * Eigen::Vector2d(std::ldexp(i, -level), std::ldexp(j, -level)) + offset;
        ASSERT_LE((img.sample(i, j).cast<double>() - expected).norm(), 4e-6 * expected.norm())
            << i << "," << j;
      }
    }
    const Eigen::Vector3d normal = linear.col(0).cross(linear.col(1)).normalized();
    for (int j = 0; j < g.normals[0].size(); ++j) {
      for (int i = 0; i < g.normals[0].size(); ++i) {
        ASSERT_GE(g.normals[0].sample(i, j).cast<double>().dot(normal), 1.0 - 1e-6);
      }
    }
  }
}

// Samples on grid vertices and edges (grid(8) at level ≥ 3) and on the square's boundary are each claimed
// once.
TEST(Resample, EverySampleIsClaimedExactlyOnce) {
  Eigen::Matrix<double, 3, 2> identity = Eigen::Matrix<double, 3, 2>::Zero();
  identity(0, 0) = identity(1, 1) = 1;
  const ModelParameterization flat = planar_patch(8, identity, Eigen::Vector3d::Zero(), 0.0);
  for (int level = 0; level <= 6; ++level) {
    const GridLocation loc = locate_grid_samples(flat.patches[0], level);
    EXPECT_TRUE(std::all_of(loc.claims.begin(), loc.claims.end(), [](std::uint8_t c) { return c == 1; }))
        << level;
  }
  for (const char* which : {"sphere", "torus"}) {
    const ModelParameterization& m = test::parameterized(which);
    for (const auto& patch : m.patches) {
      for (int level : {0, 1, 4, 7}) {
        const GridLocation loc = locate_grid_samples(patch, level);
        const auto bad =
            std::count_if(loc.claims.begin(), loc.claims.end(), [](std::uint8_t c) { return c != 1; });
        EXPECT_EQ(bad, 0) << which << " level " << level;
      }
    }
  }
}

TEST(Resample, SeamsAndCornersAreBitIdentical) {
  for (const char* which : {"sphere", "torus"}) {
    SCOPED_TRACE(which);
    const ModelParameterization& m = test::parameterized(which);
    ModelParameterization unlinked = m;
    unlinked.adjacency.clear();
    for (int level : {0, 1, 3, 6}) {
      const GeometryImages g = resample_geometry(m, level);
      EXPECT_EQ(g.uncovered_samples, 0u);
      test::expect_seams_bit_identical(m, g);
      // Without the links every side is computed from its own patch: the copies must agree to rounding.
      const GeometryImages own = resample_geometry(unlinked, level, {false, -1});
      for (std::size_t p = 0; p < m.patches.size(); ++p) {
        for (std::size_t k = 0; k < g.geometry[p].values.size(); ++k) {
          ASSERT_NEAR(g.geometry[p].values[k], own.geometry[p].values[k], 1e-5) << which << " patch " << p;
        }
      }
    }
  }
}

TEST(Resample, SphereSamplesAndNormalsLieOnTheSphere) {
  const ModelParameterization& m = test::parameterized("sphere");
  const GeometryImages g = resample_geometry(m, 6);
  ASSERT_EQ(g.normals.size(), 2u);
  EXPECT_EQ(g.normals[0].level, 7);
  for (const auto& img : g.geometry) {
    for (int j = 0; j < img.size(); ++j) {
      for (int i = 0; i < img.size(); ++i) {
        const double r = img.sample(i, j).cast<double>().norm();
        ASSERT_TRUE(r > 0.97 && r <= 1.0 + 1e-6) << r;  // inside the chords of sphere(3), never outside
      }
    }
  }
  for (std::size_t p = 0; p < g.normals.size(); ++p) {
    const GeometryImage& n = g.normals[p];
    const GeometryImage& x = g.geometry[p];
    for (int j = 0; j < n.size(); ++j) {
      for (int i = 0; i < n.size(); ++i) {
        const Eigen::Vector3d normal = n.sample(i, j).cast<double>();
        ASSERT_NEAR(normal.norm(), 1.0, 1e-6);
        if (i % 2 == 0 && j % 2 == 0) {  // nested geometry sample
          ASSERT_GE(normal.dot(x.sample(i / 2, j / 2).cast<double>().normalized()), 0.97);
        }
      }
    }
  }
}

// A hole in the (u,v) tiling (a missing triangle, as a flipped one would leave) is reported and filled from
// the nearest claimed samples.
TEST(Resample, UnclaimedSamplesAreCountedAndFilled) {
  Eigen::Matrix<double, 3, 2> identity = Eigen::Matrix<double, 3, 2>::Zero();
  identity(0, 0) = identity(1, 1) = 1;
  ModelParameterization m = planar_patch(4, identity, Eigen::Vector3d::Zero(), 0.0);
  const auto removed = m.patches[0].triangles[10];
  m.patches[0].triangles.erase(m.patches[0].triangles.begin() + 10);
  const GeometryImages g = resample_geometry(m, 6);
  const GridLocation loc = locate_grid_samples(m.patches[0], 6);
  const auto unclaimed = std::count(loc.claims.begin(), loc.claims.end(), std::uint8_t{0});
  EXPECT_GT(unclaimed, 0);
  EXPECT_EQ(g.uncovered_samples, static_cast<std::size_t>(unclaimed));
  // Filled values stay near the hole: within the removed triangle's bounding box grown by one sample.
  Eigen::Vector2d lo(1, 1), hi(0, 0);
  for (int c : removed) {
    lo = lo.cwiseMin(m.patches[0].uv[c]);
    hi = hi.cwiseMax(m.patches[0].uv[c]);
  }
  const GeometryImage& img = g.geometry[0];
  for (int j = 0; j < img.size(); ++j) {
    for (int i = 0; i < img.size(); ++i) {
      if (loc.claims[j * img.size() + i] != 0) continue;
      const Eigen::Vector3f x = img.sample(i, j);
      EXPECT_TRUE(x.x() >= lo.x() - 1.0 / 64 && x.x() <= hi.x() + 1.0 / 64 && x.y() >= lo.y() - 1.0 / 64 &&
                  x.y() <= hi.y() + 1.0 / 64)
          << i << "," << j << ": " << x.transpose();
    }
  }
}

TEST(Resample, RejectsBadInput) {
  const ModelParameterization& m = test::parameterized("sphere");
  EXPECT_THROW(resample_geometry(m, -1), InvalidInput);
  EXPECT_THROW(resample_geometry(m, kMaxGeometryImageLevel + 1), InvalidInput);
  EXPECT_THROW(resample_geometry(m, 4, {true, 3}), InvalidInput);  // normals coarser than the geometry
  EXPECT_THROW(resample_geometry(ModelParameterization{}, 4), InvalidInput);
  ModelParameterization bad = m;
  bad.patches[0].triangles[0][1] = static_cast<int>(bad.patches[0].uv.size());
  EXPECT_THROW(resample_geometry(bad, 4), InvalidInput);
  bad = m;
  std::swap(bad.adjacency[0], bad.adjacency[1]);
  EXPECT_THROW(resample_geometry(bad, 4), InvalidInput);
  bad = m;
  bad.adjacency[0].reversed = !bad.adjacency[0].reversed;
  EXPECT_THROW(resample_geometry(bad, 4), InvalidInput);
}

}  // namespace
}  // namespace geomip
