// Properties of choose_quad_layout() on synthetic meshes (label unit): the layout partitions the mesh into
// K glued disks that embed on the square, of any genus; bad requests fail with one line.
#include "param/quad_layout.h"

#include "mesh/errors.h"
#include "tests/param/partition_checks.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace geomip {
namespace {

void expect_valid_layout(const TriMesh& m, int patches, double min_balance) {
  SCOPED_TRACE(std::to_string(patches) + " patches");
  QuadLayoutOptions options;
  options.patches = patches;
  const QuadLayoutChoice choice = choose_quad_layout(m, options);
  ASSERT_EQ(choice.layout.quads.size(), static_cast<std::size_t>(patches));
  EXPECT_GE(choice.candidates, 1u);
  const PartitionResult r = partition_mesh_layout(m, choice.layout);
  EXPECT_EQ(test::check_partition(m, choice.layout.corners, r, &choice.layout), "");
  for (int p = 0; p < patches; ++p)
    EXPECT_EQ(test::tutte_square_embedding(r, p).flipped, 0u) << "patch " << p;
  const double balance = partition_stats(r).area_balance;
  EXPECT_DOUBLE_EQ(balance, choice.area_balance);
  EXPECT_GE(balance, min_balance);
  std::printf("%d patches: area balance %.3f, %zu pairings partition\n", patches, balance, choice.candidates);
}

TEST(QuadLayout, SphereLayoutsOfSeveralSizes) {
  const TriMesh m = test::sphere(4);
  for (int k : {2, 3, 6, 8, 12, 20}) expect_valid_layout(m, k, 0.15);
}

TEST(QuadLayout, TorusLayout) {
  expect_valid_layout(test::torus(32, 16), 12, 0.1);
}

TEST(QuadLayout, DoubleTorusLayout) {
  expect_valid_layout(test::subdivide(test::double_torus(), 1), 24, 0.02);
}

void expect_refused(const TriMesh& m, int patches, const std::string& fragment) {
  QuadLayoutOptions options;
  options.patches = patches;
  test::expect_invalid_input([&] { choose_quad_layout(m, options); }, "choose_quad_layout:", fragment);
}

TEST(QuadLayout, BadRequestsAreRefusedWithOneLine) {
  expect_refused(test::sphere(2), 1, "at least 2 patches");
  expect_refused(test::sphere(1), 1000, "the mesh has");
  expect_refused(test::torus(16, 8), 2, "too few for genus 1");
  expect_refused(test::grid(6), 6, "closed");
}

}  // namespace
}  // namespace geomip
