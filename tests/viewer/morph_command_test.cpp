// `geomip morph` end to end: N OBJ frames with identical connectivity, the first and last frames are the two
// models (in the normalized frame), the linear midpoint is the vertex-wise average, the wavelet one is not.
#include <gtest/gtest.h>

#include <vector>

#include <sys/wait.h>
#include <unistd.h>
#include <iterator>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/viewer/viewer_fixtures.h"

namespace geomip::viewer {
namespace {

namespace fs = std::filesystem;

struct Obj {
  std::vector<std::array<double, 3>> v;
  std::vector<std::string> faces;
};

Obj read_obj(const fs::path& path) {
  Obj o;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) {
      std::array<double, 3> p{};
      std::istringstream(line.substr(2)) >> p[0] >> p[1] >> p[2];
      o.v.push_back(p);
    } else if (line.rfind("f ", 0) == 0) {
      // The vertex indices alone ("f 1//1 2//2 3//3" from decode's normals reads as "f 1 2 3").
      std::istringstream corners(line.substr(2));
      std::string corner, face = "f";
      while (corners >> corner) face.append(" ").append(corner, 0, corner.find('/'));
      o.faces.push_back(face);
    }
  }
  return o;
}

class MorphCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("geomip_morph_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    pack_file("two", codec::write_pack({testing::pack_input(5, 0), testing::pack_input(5, 1)}));
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  // `geomip ARGS` (output to log.txt): its exit code.
  int geomip(const std::string& args) {
    const int status = std::system(
        (std::string(GEOMIP_BINARY) + " " + args + " > " + (dir_ / "log.txt").string() + " 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // Writes `bytes` as DIR/NAME.gip; its path.
  std::string pack_file(const std::string& name, const std::vector<std::uint8_t>& bytes) {
    const fs::path path = dir_ / (name + ".gip");
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return path.string();
  }
  int morph(const std::string& args) {
    const std::string cmd = std::string(GEOMIP_BINARY) + " morph " + (dir_ / "two.gip").string() + " " + args +
                            " > " + (dir_ / "log.txt").string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  fs::path dir_;
};

double extent(const Obj& o) {
  double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (const auto& p : o.v)
    for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], p[c]), hi[c] = std::max(hi[c], p[c]);
  return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

TEST_F(MorphCommandTest, FramesShareConnectivityAndInterpolateTheModels) {
  ASSERT_EQ(morph("--frames 5 -o " + (dir_ / "linear").string()), 0);
  ASSERT_EQ(morph("--frames 5 --schedule wavelet -o " + (dir_ / "wavelet").string()), 0);
  std::vector<Obj> linear, wavelet;
  for (int k = 0; k < 5; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "morph_%04d.obj", k);
    linear.push_back(read_obj(dir_ / "linear" / name));
    wavelet.push_back(read_obj(dir_ / "wavelet" / name));
  }
  ASSERT_FALSE(linear[0].faces.empty());
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(linear[k].faces, linear[0].faces) << "frame " << k;
    EXPECT_EQ(wavelet[k].faces, linear[0].faces) << "frame " << k;
    ASSERT_EQ(linear[k].v.size(), linear[0].v.size());
  }
  EXPECT_NEAR(extent(linear[0]), 1.0, 1e-3) << "frames are in the normalized frame";
  // The target is aligned to the source by a similarity: the last frame is the target in its own normalized
  // frame (--no-align) up to one scale, a rotation and a translation — every distance scaled alike.
  ASSERT_EQ(morph("--frames 2 --no-align -o " + (dir_ / "own").string()), 0);
  const Obj own = read_obj(dir_ / "own" / "morph_0001.obj");
  EXPECT_NEAR(extent(own), 1.0, 1e-3);
  ASSERT_EQ(own.v.size(), linear[4].v.size());
  auto dist = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  const std::size_t n = own.v.size();
  const double scale = dist(linear[4].v[0], linear[4].v[n / 2]) / dist(own.v[0], own.v[n / 2]);
  for (std::size_t i = 1; i < n; i += 97) {
    const std::size_t j = (i * 7919) % n;
    if (dist(own.v[i], own.v[j]) < 1e-3) continue;
    EXPECT_NEAR(dist(linear[4].v[i], linear[4].v[j]), scale * dist(own.v[i], own.v[j]), 1e-4) << i << " " << j;
  }
  double mid_err = 0, wavelet_gap = 0, ends = 0;
  for (std::size_t i = 0; i < linear[0].v.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double avg = 0.5 * (linear[0].v[i][c] + linear[4].v[i][c]);
      mid_err = std::max(mid_err, std::abs(linear[2].v[i][c] - avg));
      wavelet_gap = std::max(wavelet_gap, std::abs(wavelet[2].v[i][c] - linear[2].v[i][c]));
      ends = std::max({ends, std::abs(wavelet[0].v[i][c] - linear[0].v[i][c]),
                       std::abs(wavelet[4].v[i][c] - linear[4].v[i][c])});
    }
  EXPECT_LT(mid_err, 1e-4) << "linear midpoint = vertex-wise average";
  EXPECT_LT(ends, 1e-4) << "both schedules start and end at the models";
  EXPECT_GT(wavelet_gap, 1e-3) << "the wavelet schedule's midpoint differs";
}

// A morph's frames carry `geomip decode`'s face list for the same pack, also when the pack holds models
// besides the morph's two ends (the quad split is chosen by every model of the layout, as decode chooses it;
// it used to be chosen by the two ends alone, so faces differed and attributes could not carry over by
// index).
TEST_F(MorphCommandTest, FramesHaveDecodesFaceListInAPackOfThree) {
  codec::PackModelInput stretched = testing::pack_input(5, 1);
  stretched.name = "stretched";
  for (auto& patch : stretched.geometry)
    for (std::size_t i = 0; i < patch.values.size(); i += 3) patch.values[i] *= 4.0f;
  const std::string pack = pack_file(
      "three",
      codec::write_pack({testing::pack_input(5, 0), testing::pack_input(5, 1), std::move(stretched)}));
  fs::create_directories(dir_ / "d3");
  ASSERT_EQ(geomip("morph " + pack + " --frames 2 --from 0 --to 1 -o " + (dir_ / "m3").string()), 0);
  ASSERT_EQ(geomip("decode " + pack + " -o " + (dir_ / "d3" / "x.obj").string()), 0);
  const Obj frame = read_obj(dir_ / "m3" / "morph_0000.obj");
  const Obj decoded = read_obj(dir_ / "d3" / "x.ellipsoid.obj");
  ASSERT_FALSE(frame.faces.empty());
  EXPECT_EQ(frame.faces, decoded.faces);
  EXPECT_EQ(read_obj(dir_ / "d3" / "x.stretched.obj").faces, decoded.faces) << "decode: one face list";
}

// A morph from a closed model to one with holes leaves the holes out of every frame, as decode leaves them
// out of that model (the mask used to be taken without its level when the first end had none, so the hole
// came back filled at t = 1).
TEST_F(MorphCommandTest, FramesLeaveOutTheHolesOfEitherEnd) {
  codec::PackModelInput holed = testing::pack_input(5, 0);
  holed.name = "holed";
  holed.hole_mask.assign(holed.geometry.size(), std::vector<std::uint8_t>(32 * 32, 0));
  for (int j = 10; j < 14; ++j)
    for (int i = 8; i < 16; ++i) holed.hole_mask[0][static_cast<std::size_t>(j) * 32 + i] = 1;  // 32 quads
  const std::string pack =
      pack_file("holed", codec::write_pack({testing::pack_input(5, 1), std::move(holed)}));
  fs::create_directories(dir_ / "dh");
  ASSERT_EQ(geomip("morph " + pack + " --frames 2 --from 0 --to 1 -o " + (dir_ / "mh").string()), 0);
  ASSERT_EQ(geomip("decode " + pack + " -o " + (dir_ / "dh" / "x.obj").string()), 0);
  const Obj decoded = read_obj(dir_ / "dh" / "x.holed.obj");
  EXPECT_EQ(decoded.faces.size(), 2u * 2 * 32 * 32 - 2 * 32) << "32 quads left out";
  for (const char* name : {"morph_0000.obj", "morph_0001.obj"}) {
    const Obj frame = read_obj(dir_ / "mh" / name);
    EXPECT_EQ(frame.faces.size(), decoded.faces.size()) << name;
    EXPECT_EQ(frame.v.size(), decoded.v.size()) << name;
  }
}

TEST_F(MorphCommandTest, BadModelIndexIsBadInput) {
  EXPECT_EQ(morph("--frames 2 --to 7 -o " + (dir_ / "x").string()), 2);
  EXPECT_EQ(morph("--frames 2 --from 1 --to 1 -o " + (dir_ / "x").string()), 2) << "one model is no morph";
  EXPECT_EQ(morph("--frames 2 --bands 4 -o " + (dir_ / "x").string()), 2)
      << "--bands without the wavelet schedule";
  EXPECT_FALSE(fs::exists(dir_ / "x" / "morph_0000.obj"));
}

// A shorter run into the same directory leaves only its own frames (a sequence loaded as morph_*.obj would
// mix two runs); files of other names stay.
TEST_F(MorphCommandTest, AShorterRunRemovesTheEarlierRunsExtraFrames) {
  const fs::path out = dir_ / "seq";
  ASSERT_EQ(morph("--frames 6 -o " + out.string()), 0);
  std::ofstream(out / "notes.txt") << "mine";
  std::ofstream(out / "morph_0004.obj.bak") << "mine";
  ASSERT_EQ(morph("--frames 3 -o " + out.string()), 0);
  for (int k = 0; k < 6; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "morph_%04d.obj", k);
    EXPECT_EQ(fs::exists(out / name), k < 3) << name;
  }
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
  EXPECT_TRUE(fs::exists(out / "morph_0004.obj.bak"));
}

// A run that cannot finish leaves an earlier run's frames as they were: a frame's place taken by a directory
// is refused before anything is written (it used to stop the run at that frame, after replacing the ones
// before it), and a write that fails (a file-size limit standing in for a full disk) leaves no staging
// directory and no frame of its own.
TEST_F(MorphCommandTest, AFailedRunLeavesTheEarlierRunsFrames) {
  const fs::path out = dir_ / "keep";
  ASSERT_EQ(morph("--frames 4 --level 2 -o " + out.string()), 0);
  const auto slurp = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  std::vector<std::string> before;
  for (const char* name : {"morph_0000.obj", "morph_0001.obj", "morph_0003.obj"})
    before.push_back(slurp(out / name));
  fs::remove(out / "morph_0002.obj");
  fs::create_directory(out / "morph_0002.obj");
  EXPECT_EQ(morph("--frames 4 -o " + out.string()), 2);
  std::vector<std::string> after;
  for (const char* name : {"morph_0000.obj", "morph_0001.obj", "morph_0003.obj"})
    after.push_back(slurp(out / name));
  EXPECT_EQ(after, before);
  fs::remove(out / "morph_0002.obj");
  ASSERT_EQ(morph("--frames 4 --level 2 -o " + out.string()), 0);
  const std::string cmd = "trap '' XFSZ; ulimit -f 4; " + std::string(GEOMIP_BINARY) + " morph " +
                          (dir_ / "two.gip").string() + " --frames 4 -o " + out.string() + " > " +
                          (dir_ / "log.txt").string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  after.clear();
  for (const char* name : {"morph_0000.obj", "morph_0001.obj", "morph_0003.obj"})
    after.push_back(slurp(out / name));
  EXPECT_EQ(after, before);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().filename().string().rfind(".morph-partial", 0), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace geomip::viewer
