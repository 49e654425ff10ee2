// Parameterized synthetic models shared by the gimage tests (each computed once per test binary).
#pragma once

#include "gimage/resample.h"
#include "param/consistent_parameterization.h"
#include "param/partition_points.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>

namespace geomip::test {

inline ParameterizationOptions quick_options() {
  ParameterizationOptions options;
  options.measure_mvc_baseline = false;
  return options;
}

/// Unit sphere (test::sphere(3)) and torus (test::torus(32, 16)), parameterized with automatic points.
inline const ModelParameterization& parameterized(const std::string& which) {
  static std::map<std::string, ModelParameterization> cache;
  auto it = cache.find(which);
  if (it != cache.end()) return it->second;
  const TriMesh mesh = which == "sphere" ? sphere(3) : torus(32, 16);
  return cache[which] = parameterize_consistently({automatic_input(mesh, which)}, quick_options())[0];
}

/// test::sphere(3) and a differently deformed copy of it ("a", "b"), without points.
inline std::vector<ParameterizationInput> deformed_sphere_inputs() {
  std::vector<ParameterizationInput> models(2);
  models[0].mesh = sphere(3);
  models[1].mesh = models[0].mesh;
  for (auto& p : models[1].mesh.positions)
    p = Eigen::Vector3d(1.6 * p.x() + 0.2 * p.y() * p.y(), p.y(), 0.7 * p.z() + 0.3 * p.x() * p.y());
  models[0].name = "a";
  models[1].name = "b";
  return models;
}

/// Two differently deformed spheres with corresponding partition points (as in
/// tests/param/consistent_parameterization_test.cpp), parameterized consistently.
inline const std::vector<ModelParameterization>& deformed_sphere_pair() {
  static std::vector<ModelParameterization> pair;
  if (!pair.empty()) return pair;
  std::vector<ParameterizationInput> models = deformed_sphere_inputs();
  const Eigen::Vector3d corners[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  for (auto& m : models) {
    for (const auto& c : corners) m.partition_points.push_back(nearest_vertex(models[0].mesh, c));
  }
  pair = parameterize_consistently(models, quick_options());
  return pair;
}

/// The cube's 6 faces as a quad layout over its 8 corners (test::cube()'s vertex ids, which test::sphere()
/// keeps), counter-clockwise from outside: K = 6 patches on a sphere.
inline QuadLayout cube_layout() {
  return QuadLayout{{0, 1, 2, 3, 4, 5, 6, 7},
                    {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}};
}

/// Two differently deformed spheres (as in deformed_sphere_pair()) over the cube layout, parameterized
/// consistently: 6 patches each.
inline const std::vector<ModelParameterization>& cube_layout_pair() {
  static std::vector<ModelParameterization> pair;
  if (!pair.empty()) return pair;
  std::vector<ParameterizationInput> models = deformed_sphere_inputs();
  for (auto& m : models) {
    m.partition_points = cube_layout().corners;
    m.layout_quads = cube_layout().quads;
  }
  pair = parameterize_consistently(models, quick_options());
  return pair;
}

/// Bitwise equality of two float triples.
inline bool same_bits(const float* a, const float* b) {
  return std::memcmp(a, b, 3 * sizeof(float)) == 0;
}

// Shared sides (corners included): bit-identical floats in every patch that holds them, in geometry and normals.
inline void expect_shared_sides_bit_identical(const GeometryImages& g) {
  for (const auto* images : {&g.geometry, &g.normals}) {
    for (const SideLink& link : g.adjacency) {
      const GeometryImage& a = (*images)[link.patch];
      const GeometryImage& b = (*images)[link.other_patch];
      const int last = a.size() - 1;
      auto at = [last](const GeometryImage& img, int side, int k) {
        switch (side) {
          case 0:
            return img.at(k, 0);
          case 1:
            return img.at(last, k);
          case 2:
            return img.at(last - k, last);
          default:
            return img.at(0, last - k);
        }
      };
      for (int k = 0; k <= last; ++k) {
        ASSERT_TRUE(same_bits(at(a, link.side, k), at(b, link.other_side, link.reversed ? last - k : k)))
            << "patch " << link.patch << " side " << link.side << " sample " << k;
      }
    }
  }
}

// Shared sides and corners: bit-identical floats in every patch that holds them, in geometry and normals; and
// the corners are the corner vertices' exact positions.
inline void expect_seams_bit_identical(const ModelParameterization& m, const GeometryImages& g) {
  expect_shared_sides_bit_identical(g);
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    const int last = g.geometry[p].size() - 1;
    const int ij[4][2] = {{0, 0}, {last, 0}, {last, last}, {0, last}};
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3f exact = m.mesh.positions[m.patches[p].corners[c]].cast<float>();
      EXPECT_TRUE(same_bits(g.geometry[p].at(ij[c][0], ij[c][1]), exact.data()))
          << "patch " << p << " corner " << c;
    }
  }
}

}  // namespace geomip::test
