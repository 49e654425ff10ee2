// EXR geometry images: round trip through OpenEXR, MIP level sizes (2^(n−l)+1)² with the nested grids,
// header attributes, third-party readers, atomic writes.
#include "gimage/exr_io.h"
#include "mesh/errors.h"
#include "tests/gimage/gimage_fixtures.h"
#include "tests/param/test_meshes.h"

#include <Imath/half.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

namespace geomip {
namespace {

namespace fs = std::filesystem;

std::vector<GeometryImage> random_patches(int count, int level, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-100.f, 100.f);
  std::vector<GeometryImage> patches(count);
  for (auto& p : patches) {
    p.level = level;
    p.values.resize(3 * static_cast<std::size_t>(p.size()) * p.size());
    for (float& v : p.values) v = d(rng);
  }
  return patches;
}

GeometryImageFileInfo sample_info() {
  GeometryImageFileInfo info;
  info.source_mesh = "meshes/bunny.obj";
  info.adjacency = {{0, 0, 1, 3, true}, {0, 1, 1, 2, true}, {0, 2, 1, 1, true}, {0, 3, 1, 0, true},
                    {1, 0, 0, 3, true}, {1, 1, 0, 2, true}, {1, 2, 0, 1, true}, {1, 3, 0, 0, true}};
  info.normalization = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, -0.25, 0.125, 3.0, 1};
  return info;
}

class Exr : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("exr");
  void TearDown() override { fs::remove_all(dir_); }
};

TEST_F(Exr, FloatRoundTripWithNestedMipLevels) {
  for (int level : {0, 1, 5, 7}) {
    const auto patches = random_patches(2, level, 11 + level);
    const std::string path = dir_ + "/m.geometry.exr";
    write_geometry_image_exr(path, patches, sample_info());
    const GeometryImageFile file = read_geometry_image_exr(path);
    ASSERT_EQ(file.parts.size(), 2u);
    EXPECT_EQ(file.part_names[1], "patch1");
    EXPECT_EQ(file.info.kind, "geometry");
    EXPECT_EQ(file.info.source_mesh, "meshes/bunny.obj");
    EXPECT_EQ(file.info.level, level);
    EXPECT_EQ(adjacency_to_text(file.info.adjacency), adjacency_to_text(sample_info().adjacency));
    EXPECT_EQ(file.info.normalization, sample_info().normalization);
    for (std::size_t p = 0; p < 2; ++p) {
      // ROUND_UP pyramid: levels n, n−1, ..., 0 of the grid, then a 1×1 level.
      ASSERT_EQ(file.parts[p].size(), static_cast<std::size_t>(level + 2)) << "level " << level;
      for (int l = 0; l <= level + 1; ++l) {
        const ExrMipLevel& mip = file.parts[p][l];
        const int expected = l <= level ? (1 << (level - l)) + 1 : 1;
        ASSERT_EQ(mip.width, expected);
        ASSERT_EQ(mip.height, expected);
        const GeometryImage nested = nested_grid(patches[p], std::max(level - l, 0));
        for (int y = 0; y < expected; ++y) {
          for (int x = 0; x < expected; ++x) {
            for (int c = 0; c < 3; ++c) {
              ASSERT_EQ(mip.rgb[3 * (y * expected + x) + c], nested.at(x, y)[c])
                  << "mip " << l << " " << x << "," << y;
              // the nested grid is every 2^l-th sample of the original
              ASSERT_EQ(mip.rgb[3 * (y * expected + x) + c], patches[p].at(x << l, y << l)[c]);
            }
          }
        }
      }
    }
  }
}

// Resampled sphere images survive the file exactly: same floats, so the seams stay bit-identical.
TEST_F(Exr, ResampledSphereRoundTripsBitExactly) {
  const ModelParameterization& m = test::parameterized("sphere");
  const GeometryImages g = resample_geometry(m, 5);
  GeometryImageFileInfo info;
  info.source_mesh = "sphere";
  info.adjacency = g.adjacency;
  const std::string path = dir_ + "/sphere.geometry.exr";
  write_geometry_image_exr(path, g.geometry, info);
  const GeometryImageFile file = read_geometry_image_exr(path);
  GeometryImages back;
  back.geometry = finest_grids(file);
  back.adjacency = file.info.adjacency;
  ASSERT_EQ(back.geometry.size(), 2u);
  for (std::size_t p = 0; p < 2; ++p) {
    EXPECT_EQ(back.geometry[p].level, 5);
    EXPECT_EQ(back.geometry[p].values, g.geometry[p].values);
  }
  back.normals = back.geometry;  // the seam check walks both arrays
  test::expect_seams_bit_identical(m, back);
  GeometryImageFile broken = file;
  broken.info.level = 4;
  EXPECT_THROW(finest_grids(broken), InvalidInput);
}

TEST_F(Exr, HalfNormalsRoundTripAsHalves) {
  auto patches = random_patches(4, 6, 3);
  for (auto& p : patches) {
    for (float& v : p.values) v /= 100.f;
  }
  GeometryImageFileInfo info = sample_info();
  info.kind = "normals";
  info.adjacency.clear();  // sample_info()'s links glue 2 patches, not 4
  const std::string path = dir_ + "/m.normals.exr";
  write_geometry_image_exr(path, patches, info, {true, 32});
  const GeometryImageFile file = read_geometry_image_exr(path);
  ASSERT_EQ(file.parts.size(), 4u);
  EXPECT_EQ(file.info.kind, "normals");
  for (std::size_t p = 0; p < 4; ++p) {
    for (std::size_t k = 0; k < patches[p].values.size(); ++k) {
      ASSERT_EQ(file.parts[p][0].rgb[k], static_cast<float>(half(patches[p].values[k])));
    }
  }
  // Half files are smaller than float ones.
  const std::string fpath = dir_ + "/m.geometry.exr";
  write_geometry_image_exr(fpath, patches, sample_info());
  EXPECT_LT(fs::file_size(path), fs::file_size(fpath));
}

TEST_F(Exr, ThirdPartyToolsReadTheFile) {
  const std::string path = dir_ + "/m.geometry.exr";
  write_geometry_image_exr(path, random_patches(2, 5, 1), sample_info());
  for (const std::string tool : {"oiiotool", "exrheader"}) {
    if (std::system(("command -v " + tool + " > /dev/null 2>&1").c_str()) != 0) {
      std::cout << tool << " not installed: skipped\n";
      continue;
    }
    const std::string args = tool == "oiiotool" ? " --info -v '" : " '";
    const std::string out = dir_ + "/" + tool + ".txt";
    const int status = std::system((tool + args + path + "' > '" + out + "' 2>&1").c_str());
    EXPECT_EQ(status, 0) << tool;
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(text.find("geomip:adjacency"), std::string::npos) << tool << ":\n" << text;
    EXPECT_NE(text.find("meshes/bunny.obj"), std::string::npos) << tool;
  }
}

TEST_F(Exr, FailedWriteLeavesNothing) {
  const std::string path = dir_ + "/missing-dir/m.geometry.exr";
  EXPECT_THROW(write_geometry_image_exr(path, random_patches(2, 3, 1), sample_info()), IoError);
  EXPECT_FALSE(fs::exists(dir_ + "/missing-dir"));
  // Bad images are rejected before anything is written, and an existing file is untouched.
  const std::string good = dir_ + "/g.exr";
  write_geometry_image_exr(good, random_patches(2, 3, 1), sample_info());
  const auto size = fs::file_size(good);
  auto mixed = random_patches(2, 3, 1);
  mixed[1] = random_patches(1, 4, 2)[0];
  EXPECT_THROW(write_geometry_image_exr(good, mixed, sample_info()), InvalidInput);
  EXPECT_THROW(write_geometry_image_exr(good, {}, sample_info()), InvalidInput);
  EXPECT_EQ(fs::file_size(good), size);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1u);  // no temporary left behind
  // The user's files, not the machine's failures (exit 2 in the tools): missing, truncated, garbage, empty.
  EXPECT_THROW(read_geometry_image_exr(dir_ + "/nope.exr"), InvalidInput);
  std::vector<char> bytes(size);
  std::ifstream(good, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(size));
  const std::string cut = dir_ + "/cut.exr", garbage = dir_ + "/garbage.exr", empty = dir_ + "/empty.exr";
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(size / 2));
  std::ofstream(garbage, std::ios::binary) << std::string(1000, '\x5a');
  std::ofstream(empty, std::ios::binary).flush();
  for (const std::string& bad : {cut, garbage, empty})
    EXPECT_THROW(read_geometry_image_exr(bad), InvalidInput) << bad;
}

TEST(ExrAdjacencyText, RoundTripsAndRejectsGarbage) {
  const auto links = sample_info().adjacency;
  const auto back = adjacency_from_text(adjacency_to_text(links));
  ASSERT_EQ(back.size(), links.size());
  for (std::size_t k = 0; k < links.size(); ++k) {
    EXPECT_EQ(back[k].patch, links[k].patch);
    EXPECT_EQ(back[k].side, links[k].side);
    EXPECT_EQ(back[k].other_patch, links[k].other_patch);
    EXPECT_EQ(back[k].other_side, links[k].other_side);
    EXPECT_EQ(back[k].reversed, links[k].reversed);
  }
  EXPECT_TRUE(adjacency_from_text("").empty());
  for (const char* bad : {"0.0-1", "0,0-1.3r", "0.0-1.3x", "a.b-c.d"}) {
    EXPECT_THROW(adjacency_from_text(bad), InvalidInput) << bad;
  }
}

// An edited or crafted adjacency attribute that does not glue the parts into a closed surface (a side glued
// to itself, to a side that is glued elsewhere, in the other direction, or to a patch that is not there) is
// refused by the reader, naming the file and the side: `geomip encode` coded such files (exit 0) or failed
// with "encode_geometry: seam references a bad patch or side", no file named.
TEST_F(Exr, AnAdjacencyThatDoesNotCloseTheSurfaceIsRefusedNamingTheFile) {
  const auto good = sample_info();
  ASSERT_NO_THROW(check_adjacency(good.adjacency, 2));
  auto edited = [&](int k, int other_patch, int other_side, bool reversed) {
    GeometryImageFileInfo info = good;
    info.adjacency[static_cast<std::size_t>(k)].other_patch = other_patch;
    info.adjacency[static_cast<std::size_t>(k)].other_side = other_side;
    info.adjacency[static_cast<std::size_t>(k)].reversed = reversed;
    return info;
  };
  const SideLink first = good.adjacency[0];
  const std::vector<std::pair<GeometryImageFileInfo, std::string>> cases = {
      {edited(0, 0, 0, first.reversed), "glued to itself"},
      {edited(0, first.other_patch, (first.other_side + 1) % 4, first.reversed), "which is glued to"},
      {edited(0, first.other_patch, first.other_side, !first.reversed), "in the other direction"},
      {edited(0, 7, 0, first.reversed), "not a side of one of the 2 patches"},
  };
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::string path = dir_ + "/edited" + std::to_string(c) + ".exr";
    write_geometry_image_exr(path, random_patches(2, 3, 1), cases[c].first);
    try {
      read_geometry_image_exr(path);
      ADD_FAILURE() << cases[c].second << ": read";
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path + ": geomip:adjacency: "), std::string::npos) << what;
      EXPECT_NE(what.find(cases[c].second), std::string::npos) << what;
    }
  }
  GeometryImageFileInfo three = good;  // the 2-patch links on a file of 3 parts
  const std::string path = dir_ + "/three.exr";
  write_geometry_image_exr(path, random_patches(3, 3, 1), three);
  EXPECT_THROW(read_geometry_image_exr(path), InvalidInput);
}

TEST(NestedGrid, TakesEveryStepthSample) {
  const auto p = random_patches(1, 4, 9)[0];
  const GeometryImage g = nested_grid(p, 2);
  ASSERT_EQ(g.size(), 5);
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 5; ++i) EXPECT_EQ(g.sample(i, j), p.sample(4 * i, 4 * j));
  }
  EXPECT_THROW(nested_grid(p, 5), InvalidInput);
  EXPECT_THROW(nested_grid(p, -1), InvalidInput);
}

}  // namespace
}  // namespace geomip
