// geomip-view end to end on real .gip packs (written here with codec::write_pack from synthetic consistent
// models): screenshots cover the decoded model's silhouette, morph end points equal the models alone, the
// wavelet schedule's midpoint differs from the linear one's; streaming over HTTP from a local Range-capable
// server (range_server.py) with a bandwidth limit shows a coarse model early, survives the server dying
// mid-stream, and reports 404 / non-pack URLs. A fetcher that trusts nothing: crafted manifests (valid CRC,
// lying chunk table), endless bodies, redirects, stalls and --limit-rate on files end cleanly and promptly with
// one line. Runs under xvfb-run (CTest); skips without a display.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>

#include "mesh/mesh_io.h"
#include "mesh/view_frame.h"
#include "stream_viewer/pack_source.h"
#include "stream_viewer/png_write.h"
#include "tests/param/test_meshes.h"
#include "tests/viewer/crafted_pack.h"
#include "tests/viewer/viewer_fixtures.h"

extern char** environ;

namespace geomip::viewer {
namespace {

namespace fs = std::filesystem;
using namespace testing;

constexpr int kW = 320, kH = 240;

fs::path work_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("geomip_view_test_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

/// A two-model pack (ellipsoid, bumpy body) of grid level `level`, written once per level.
fs::path pack_file(int level) {
  const fs::path path = work_dir() / ("two_models_" + std::to_string(level) + ".gip");
  if (!fs::exists(path)) {
    const auto bytes = codec::write_pack({pack_input(level, 0), pack_input(level, 1)});
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                static_cast<std::streamsize>(bytes.size()));
  }
  return path;
}

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

struct ViewRun {
  int code = -1;
  std::string out, err;
  bool signaled = false;  // killed by a signal (abort, segfault): never acceptable
  long max_rss_kb = 0;    // peak resident memory of geomip-view (measured runs)
};

/// The captured standard output and error of a run.
void read_outputs(ViewRun& r, const fs::path& out, const fs::path& err) {
  std::stringstream so, se;
  so << std::ifstream(out).rdbuf();
  se << std::ifstream(err).rdbuf();
  r.out = so.str();
  r.err = se.str();
}

ViewRun view(const std::string& args) {
  static int counter = 0;
  const fs::path out = work_dir() / ("out" + std::to_string(counter) + ".txt");
  const fs::path err = work_dir() / ("err" + std::to_string(counter++) + ".txt");
  const std::string cmd = std::string(GEOMIP_VIEW_BINARY) + " " + args + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  ViewRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  read_outputs(r, out, err);
  return r;
}

/// Like view(), but spawned directly (sh exec's geomip-view) and waited for with wait4: peak RSS and whether
/// a signal ended it. No wall time: a run that must end is bounded by its own --timeout (its exit code says
/// which way it ended) or, where a wait that ignored a cancel would never end, by ctest's TIMEOUT.
ViewRun view_measured(const std::string& args) {
  static int counter = 0;
  const fs::path out = work_dir() / ("mout" + std::to_string(counter) + ".txt");
  const fs::path err = work_dir() / ("merr" + std::to_string(counter++) + ".txt");
  std::string cmd = "exec " + std::string(GEOMIP_VIEW_BINARY) + " " + args + " > " + out.string() + " 2> " +
                    err.string();
  std::vector<char*> argv = {const_cast<char*>("/bin/sh"), const_cast<char*>("-c"), cmd.data(), nullptr};
  ViewRun r;
  pid_t pid = -1;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv.data(), environ) != 0) return r;
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  r.max_rss_kb = usage.ru_maxrss;
  r.signaled = WIFSIGNALED(status);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  read_outputs(r, out, err);
  return r;
}

/// The "(R of T bytes received)" of a "timed out" line: {R, T}; T = 0 where it is "?" (the manifest had not
/// arrived), R = T = 0 without such a line.
std::pair<std::uint64_t, std::uint64_t> received_at_timeout(const std::string& err) {
  const auto at = err.find("timed out after ");
  const auto open = at == std::string::npos ? at : err.find('(', at);
  std::uint64_t received = 0, total = 0;
  std::string of;
  if (open != std::string::npos) std::istringstream(err.substr(open + 1)) >> received >> of >> total;
  return {received, total};
}

std::size_t lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

std::string size_args() { return "--frames 2 --width " + std::to_string(kW) + " --height " + std::to_string(kH); }

std::vector<std::uint8_t> load(const fs::path& png) {
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgb;
  EXPECT_TRUE(read_png(png.string(), w, h, rgb)) << png;
  EXPECT_EQ(w, kW);
  EXPECT_EQ(h, kH);
  return rgb;
}

/// The range server on a free port; killed on destruction.
class Server {
 public:
  explicit Server(const std::vector<std::string>& extra) {
    const fs::path log = work_dir() / ("server" + std::to_string(++count_) + ".txt");
    std::vector<std::string> args = {GEOMIP_PYTHON, std::string(GEOMIP_SOURCE_DIR) + "/tests/viewer/range_server.py",
                                     "--root", work_dir().string()};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    for (int i = 0; i < 200 && pid_ > 0 && port_ == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::ifstream in(log);
      std::string word;
      if (in >> word >> port_ && word == "PORT") break;
      port_ = 0;
    }
  }
  ~Server() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  int port() const { return port_; }
  std::string url(const std::string& name) const { return "http://127.0.0.1:" + std::to_string(port_) + "/" + name; }

 private:
  static inline int count_ = 0;
  pid_t pid_ = -1;
  int port_ = 0;
};

class ViewPackTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = new GlContext(64, 64);  // only to learn whether a display is there
  }
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
    std::error_code ignored;
    if (!std::getenv("GEOMIP_VIEW_TEST_KEEP")) fs::remove_all(work_dir(), ignored);  // keep: for debugging
  }
  void SetUp() override {
    if (!context_->ok()) GTEST_SKIP() << "no OpenGL 3.3 display (run under xvfb-run)";
  }
  static GlContext* context_;
};
GlContext* ViewPackTest::context_ = nullptr;

/// The viewer's default camera for a pack's decoded models (one band each): all of them framed together to
/// about 70 % of the height (framing_distance).
Camera framed(const std::vector<morph::SceneModel>& models) {
  std::vector<float> xyz;
  for (const auto& m : models) xyz.insert(xyz.end(), m.positions.begin(), m.positions.end());
  Camera camera;
  camera.distance = framing_distance(camera, xyz, kW, kH);
  return camera;
}

std::vector<morph::SceneModel> decode_file(const fs::path& path) {
  const auto bytes = read_bytes(path);
  codec::Status status;
  std::size_t used = 0;
  auto models = morph::decode_scene(bytes, {}, status, used);
  EXPECT_EQ(status, codec::Status::kOk);
  EXPECT_EQ(used, bytes.size());
  return models;
}

/// Rows [y0, y1] and columns [x0, x1] of a coverage mask's set pixels (y1 < y0 when none is set).
struct Box {
  int x0 = kW, x1 = -1, y0 = kH, y1 = -1;
};
Box bounding_box(const std::vector<std::uint8_t>& mask) {
  Box b;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (mask[static_cast<std::size_t>(y) * kW + x])
        b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x), b.y0 = std::min(b.y0, y),
        b.y1 = std::max(b.y1, y);
  return b;
}

/// Separate runs of set pixels in row y (gaps of at least 2 pixels).
int runs_in_row(const std::vector<std::uint8_t>& mask, int y) {
  int runs = 0, gap = 2;
  for (int x = 0; x < kW; ++x) {
    if (mask[static_cast<std::size_t>(y) * kW + x]) {
      if (gap >= 2) ++runs;
      gap = 0;
    } else {
      ++gap;
    }
  }
  return runs;
}

TEST_F(ViewPackTest, ScreenshotCoversTheDecodedModelsSilhouette) {
  const fs::path pack = pack_file(6);
  const auto models = decode_file(pack);
  ASSERT_EQ(models.size(), 2u);
  for (int m = 0; m < 2; ++m)
    for (int level : {6, 3}) {
      const fs::path png = work_dir() / ("model" + std::to_string(m) + "_" + std::to_string(level) + ".png");
      const ViewRun r = view(pack.string() + " " + size_args() + " --model " + std::to_string(m) + " --level " +
                         std::to_string(level) + " --screenshot " + png.string());
      ASSERT_EQ(r.code, 0) << r.err;
      const auto image = image_coverage(load(png));
      const auto reference = cpu_coverage(models[m], level, framed(models), kW, kH);
      EXPECT_GT(count(reference), std::size_t(kW * kH / 20));
      EXPECT_GT(iou(image, reference), 0.95) << "model " << m << " level " << level;
      EXPECT_EQ(interior_misses(image, reference, kW, kH), 0u) << "no cracks: model " << m << " level " << level;
    }
}

// The default camera frames the models: the larger silhouette's bounding box spans 60–80 % of the frame's
// height (or 90 % of its width, for models wider than the frame's aspect), and neither model is cut off.
// (Both models of a pack are framed together, so a morph between them keeps one camera.)
TEST_F(ViewPackTest, DefaultCameraFramesTheModels) {
  const fs::path pack = pack_file(6);
  double largest = 0;
  for (int m = 0; m < 2; ++m) {
    const fs::path png = work_dir() / ("framed" + std::to_string(m) + ".png");
    const ViewRun r = view(pack.string() + " " + size_args() + " --model " + std::to_string(m) + " --screenshot " +
                           png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const Box b = bounding_box(image_coverage(load(png)));
    ASSERT_GE(b.y1, b.y0) << "nothing drawn";
    const double height = static_cast<double>(b.y1 - b.y0 + 1) / kH,
                 width = static_cast<double>(b.x1 - b.x0 + 1) / kW;
    std::cout << "model " << m << ": silhouette spans " << height << " of the height, " << width << " of the width\n";
    largest = std::max(largest, height);
    EXPECT_LE(width, 0.9) << "model " << m;
    EXPECT_TRUE(b.x0 > 0 && b.x1 < kW - 1 && b.y0 > 0 && b.y1 < kH - 1) << "model " << m << " cut off";
  }
  EXPECT_GE(largest, 0.6);
  EXPECT_LE(largest, 0.8);
}

#ifdef GEOMIP_BINARY
// A real model: data/spot.obj through `geomip convert` (partition, parameterization, geometry images, normal
// maps, codec). Its many patches meet along seams the codec keeps bit-identical: no cracks at any level.
// `geomip convert MESH --level top` → pack; the viewer's frame at each of `levels` covers the CPU reference's
// silhouette (IoU > 0.95) with no crack inside it. Returns the pack's patch count.
int expect_converted_mesh_renders(const fs::path& mesh, const std::string& stem, int top, std::initializer_list<int> levels) {
  const fs::path pack = work_dir() / (stem + ".gip");
  const std::string convert = std::string(GEOMIP_BINARY) + " convert -q " + mesh.string() + " --level " +
                              std::to_string(top) + " -o " + pack.string();
  EXPECT_EQ(std::system(convert.c_str()), 0) << convert;
  const auto models = decode_file(pack);
  if (models.size() != 1u) {
    ADD_FAILURE() << stem << ": " << models.size() << " models";
    return 0;
  }
  for (int level : levels) {
    const fs::path png = work_dir() / (stem + "_" + std::to_string(level) + ".png");
    const ViewRun r = view(pack.string() + " " + size_args() + " --level " + std::to_string(level) +
                           " --screenshot " + png.string());
    EXPECT_EQ(r.code, 0) << r.err;
    if (r.code != 0) continue;
    const auto image = image_coverage(load(png));
    const auto reference = cpu_coverage(models[0], level, framed(models), kW, kH);
    EXPECT_GT(count(reference), std::size_t(kW * kH / 20));
    EXPECT_GT(iou(image, reference), 0.95) << stem << " level " << level;
    EXPECT_EQ(interior_misses(image, reference, kW, kH), 0u) << stem << ": no cracks at level " << level;
  }
  return models[0].num_patches;
}

TEST_F(ViewPackTest, ConvertedMeshCoversItsSilhouetteWithoutCracks) {
  EXPECT_GE(expect_converted_mesh_renders(fs::path(GEOMIP_SOURCE_DIR) / "data/spot.obj", "spot", 6, {6, 4, 2}), 2);
}

// Genus 2 (test::double_torus()): convert picks a quad layout of more than 2 patches itself; the viewer draws
// every level watertight over the same silhouette as the CPU reference.
TEST_F(ViewPackTest, GenusTwoPackRendersWithoutCracks) {
  const fs::path mesh = work_dir() / "double_torus.obj";
  {
    std::ofstream out(mesh);
    write_mesh(test::double_torus(), out, MeshFormat::kObj);
  }
  EXPECT_GT(expect_converted_mesh_renders(mesh, "double_torus", 5, {5, 3}), 2);
}

// An open real mesh (the camel head, cut at the neck): `geomip convert` fills the hole and the pack marks the
// fill in its hole masks; the viewer leaves those quads out, exactly as the CPU reference does.
TEST_F(ViewPackTest, RepairedMeshLeavesItsHoleMaskedQuadsOut) {
  const fs::path mesh = fs::path(GEOMIP_SHARED_MESHES) / "camelhead.obj";
  if (!fs::exists(mesh)) GTEST_SKIP() << mesh << " not found (../shared/meshes)";
  const fs::path pack = work_dir() / "camelhead.gip";
  const std::string convert =
      std::string(GEOMIP_BINARY) + " convert -q " + mesh.string() + " --level 6 -o " + pack.string();
  ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
  const auto models = decode_file(pack);
  ASSERT_EQ(models.size(), 1u);
  ASSERT_FALSE(models[0].holes.empty()) << "the repaired camel head should carry a hole mask";
  EXPECT_GT(count(models[0].holes), 0u);
  morph::SceneModel unmasked = models[0];
  unmasked.holes.clear();
  for (float yaw : {0.6f, 2.5f, 4.0f}) {
    Camera camera;
    camera.yaw = yaw;
    camera.distance = 2.0f;
    const fs::path png = work_dir() / ("camel_" + std::to_string(int(yaw * 10)) + ".png");
    std::ostringstream args;
    args << pack.string() << " " << size_args() << " --yaw " << yaw << " --distance 2 --screenshot " << png.string();
    const ViewRun r = view(args.str());
    ASSERT_EQ(r.code, 0) << r.err;
    const auto image = image_coverage(load(png));
    const auto reference = cpu_coverage(models[0], models[0].level, camera, kW, kH);
    EXPECT_GT(iou(image, reference), 0.95) << "yaw " << yaw;
    EXPECT_EQ(interior_misses(image, reference, kW, kH), 0u) << "yaw " << yaw;
    EXPECT_LT(count(image), count(cpu_coverage(unmasked, unmasked.level, camera, kW, kH)))
        << "the filled hole is not drawn (yaw " << yaw << ")";
    std::cout << "yaw " << yaw << ": " << count(image) << " pixels drawn, "
              << count(cpu_coverage(unmasked, unmasked.level, camera, kW, kH)) << " with the fill\n";
  }
}
struct Animal {
  const char* mesh;
  std::array<double, 3> up;    // the data's up axis, seen in the mesh (model units)
  std::array<double, 3> head;  // where its head points (model units; tests/data/make_animals_corr.py)
  bool legs;                   // stands on legs that show apart at the bottom of a side view
};

// Issue 16: `geomip convert` stores the viewer's frame (up from the shape, the front by three cues:
// mesh/view_frame.h), and the default camera shows the animals of ../shared/meshes upright, head towards the
// camera, at 60–80 % of the frame's height. Upright is checked on the pack (its frame turns the data's up
// axis, known for each mesh, into the viewer's +y), on the screenshot (it is the CPU projection of that
// frame; the legs of horse and cow are apart in the silhouette's lowest rows) and the height by the
// silhouette's bounding box. The front likewise on the pack (the head's axis becomes +x) and on the
// screenshot: the head (the mean of the mesh's vertices in the tenth of its length at the head's end, through
// the pack's frame and the default camera) is drawn, in the silhouette's right half (the camera looks from
// positive yaw, so +x, the front, is to the right) — the pig's head rests lower than its rump and faces the
// camera too.
TEST_F(ViewPackTest, AnimalsStandUprightFacingTheCameraAt60To80PercentOfTheHeight) {
  const Animal animals[] = {{"horse.obj", {0, 0, 1}, {0, 1, 0}, true},
                            {"cow.obj", {0, 1, 0}, {1, 0, 0}, true},
                            {"pig.obj", {0, -1, 0}, {0, 0, -1}, false},
                            {"bunny.obj", {0, 1, 0}, {-1, 0, 0}, false}};
  for (const Animal& a : animals) {
    const fs::path mesh = fs::path(GEOMIP_SHARED_MESHES) / a.mesh;
    if (!fs::exists(mesh)) GTEST_SKIP() << mesh << " not found (../shared/meshes)";
    const std::string name = fs::path(a.mesh).stem().string();
    const fs::path pack = work_dir() / (name + ".gip");
    const std::string convert =
        std::string(GEOMIP_BINARY) + " convert -q " + mesh.string() + " --level 4 -o " + pack.string();
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    const auto bytes = read_bytes(pack);
    codec::PackInfo info;
    ASSERT_EQ(codec::read_pack_info(bytes, info), codec::Status::kOk);
    ASSERT_EQ(info.models.size(), 1u);
    // Rows 0 and 1 of the frame's linear part: the model directions shown as +x (front) and +y (up).
    const auto& n = info.models[0].normalization;
    const double scale = std::sqrt(n[4] * n[4] + n[5] * n[5] + n[6] * n[6]);
    ASSERT_GT(scale, 0) << name;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(n[static_cast<std::size_t>(4 + c)] / scale, a.up[static_cast<std::size_t>(c)], 1e-12)
          << name << ": the pack's up";
      EXPECT_NEAR(n[static_cast<std::size_t>(c)] / scale, a.head[static_cast<std::size_t>(c)], 1e-12)
          << name << ": the pack's front";
    }

    const fs::path png = work_dir() / (name + "_default.png");
    const ViewRun r = view(pack.string() + " " + size_args() + " --screenshot " + png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const auto image = image_coverage(load(png));
    const auto models = decode_file(pack);
    ASSERT_EQ(models.size(), 1u);
    EXPECT_GT(iou(image, cpu_coverage(models[0], models[0].level, framed(models), kW, kH)), 0.95)
        << name << ": the screenshot is the pack's frame seen by the default camera";
    const Box b = bounding_box(image);
    ASSERT_GE(b.y1, b.y0) << name << ": nothing drawn";
    const double height = static_cast<double>(b.y1 - b.y0 + 1) / kH;
    const double width = static_cast<double>(b.x1 - b.x0 + 1) / kW;
    EXPECT_GE(height, 0.6) << name;
    EXPECT_LE(height, 0.8) << name;
    EXPECT_TRUE(b.x0 > 0 && b.x1 < kW - 1 && b.y0 > 0 && b.y1 < kH - 1) << name << " cut off";
    // Legs at the bottom: in the lowest fifth of the silhouette, a row crosses two or more legs.
    int most_runs = 0;
    for (int y = b.y1 - (b.y1 - b.y0) / 5; y <= b.y1; ++y)
      most_runs = std::max(most_runs, runs_in_row(image, y));
    if (a.legs) {
      EXPECT_GE(most_runs, 2) << name << ": the lowest rows should cross the legs";
    }
    // The head on the screen: the mean of the mesh's referenced vertices within a tenth of its length from
    // the head's end (inside the head, at the coarse level too), drawn (within 2 px) and right of the
    // silhouette's middle.
    const TriMesh data = read_mesh(mesh.string());
    const Eigen::Vector3d head(a.head[0], a.head[1], a.head[2]);
    std::vector<char> used(data.positions.size(), 0);
    for (const auto& t : data.triangles)
      for (int v : t) used[static_cast<std::size_t>(v)] = 1;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (std::size_t v = 0; v < used.size(); ++v)
      if (used[v])
        lo = std::min(lo, data.positions[v].dot(head)), hi = std::max(hi, data.positions[v].dot(head));
    Eigen::Vector3d tip = Eigen::Vector3d::Zero();
    int in_tip = 0;
    for (std::size_t v = 0; v < used.size(); ++v)
      if (used[v] && data.positions[v].dot(head) >= hi - 0.1 * (hi - lo)) tip += data.positions[v], ++in_tip;
    tip /= std::max(in_tip, 1);
    // A frame that is the identity is not stored (the cow's): the viewer fits the box, as view_normalization.
    const std::array<double, 16> frame =
        n == std::array<double, 16>{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}
            ? view_normalization(data, Eigen::Matrix3d::Identity())
            : n;
    const auto vp = view_projection(framed(models), kW, kH);
    float q[3], clip[4];
    for (std::size_t k = 0; k < 3; ++k)
      q[k] = static_cast<float>(frame[4 * k] * tip.x() + frame[4 * k + 1] * tip.y() +
                                frame[4 * k + 2] * tip.z() + frame[4 * k + 3]);
    for (std::size_t k = 0; k < 4; ++k)
      clip[k] = vp[k] * q[0] + vp[4 + k] * q[1] + vp[8 + k] * q[2] + vp[12 + k];
    const int hx = static_cast<int>((clip[0] / clip[3] * 0.5f + 0.5f) * kW);
    const int hy = static_cast<int>((0.5f - clip[1] / clip[3] * 0.5f) * kH);
    bool drawn = false;
    for (int y = std::max(0, hy - 2); y <= std::min(kH - 1, hy + 2); ++y)
      for (int x = std::max(0, hx - 2); x <= std::min(kW - 1, hx + 2); ++x)
        drawn = drawn || image[static_cast<std::size_t>(y) * kW + x] != 0;
    EXPECT_TRUE(drawn) << name << ": the head at pixel (" << hx << ", " << hy << ") is not drawn";
    EXPECT_GT(2 * hx, b.x0 + b.x1) << name << ": the head (x " << hx
                                   << ") should be right of the silhouette's "
                                   << "middle (" << b.x0 << "–" << b.x1 << "): the head faces the camera";
    std::cout << name << ": silhouette " << height << " of the height, " << width << " of the width; "
              << most_runs << " runs in its lowest rows; head at x " << hx << " of " << b.x0 << "–" << b.x1
              << "\n";
  }
}

// Issue 15: the four animals with a user layout (tests/data/animals-layout.corr.json: 64 quads, each leg, the
// head and the tail with patches of their own) through `geomip convert`: one pack of 4 models with 64
// patches each, and the viewer morphs them. Horse → cow and pig → spot at t = 0, 0.5, 1 (linear schedule):
// each frame covers the CPU-evaluated morph's silhouette (IoU > 0.95) with no crack inside it, the end frames
// are the models alone, and the three frames differ from each other.
TEST_F(ViewPackTest, AnimalsWithAUserLayoutMorphWithoutCracks) {
  const fs::path horse = fs::path(GEOMIP_SHARED_MESHES) / "horse.obj";
  if (!fs::exists(horse)) GTEST_SKIP() << horse << " not found (../shared/meshes)";
  const fs::path pack = work_dir() / "animals-layout.gip";
  const std::string convert = std::string(GEOMIP_BINARY) + " convert -q --points " + GEOMIP_SOURCE_DIR +
                              "/tests/data/animals-layout.corr.json --level 4 -o " + pack.string();
  ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
  const auto models = decode_file(pack);
  ASSERT_EQ(models.size(), 4u);
  for (const auto& m : models) EXPECT_EQ(m.num_patches, 64);
  const Camera camera = framed(models);
  for (int source : {0, 2}) {
    std::vector<std::vector<std::uint8_t>> frames;
    for (float t : {0.0f, 0.5f, 1.0f}) {
      const std::string tag = std::to_string(source) + "_" + std::to_string(int(t * 10));
      const fs::path png = work_dir() / ("animals_layout_" + tag + ".png");
      std::ostringstream args;
      args << pack.string() << " " << size_args() << " --model " << source << " --morph " << t
           << " --schedule linear --screenshot " << png.string();
      const ViewRun r = view(args.str());
      ASSERT_EQ(r.code, 0) << r.err;
      frames.push_back(load(png));
      const auto image = image_coverage(frames.back());
      const auto geometry = morph::evaluate_morph(models[source], models[source + 1], t, morph::MorphSchedule::kLinear);
      const auto reference = cpu_coverage(models[source], models[source].level, camera, kW, kH, &geometry);
      EXPECT_GT(count(reference), std::size_t(kW * kH / 20)) << tag;
      EXPECT_GT(iou(image, reference), 0.95) << "model " << source << " t " << t;
      EXPECT_EQ(interior_misses(image, reference, kW, kH), 0u) << "no cracks: model " << source << " t " << t;
    }
    for (int end = 0; end < 2; ++end) {
      const fs::path png = work_dir() / ("animals_layout_alone_" + std::to_string(source + end) + ".png");
      const ViewRun r = view(pack.string() + " " + size_args() + " --model " + std::to_string(source + end) +
                             " --screenshot " + png.string());
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_LT(differing(frames[static_cast<std::size_t>(2 * end)], load(png), 2), 0.001)
          << "model " << source << ": the morph ends at the model alone (t = " << end << ")";
    }
    EXPECT_GT(differing(frames[0], frames[1], 2), 0.02) << "model " << source;
    EXPECT_GT(differing(frames[1], frames[2], 2), 0.02) << "model " << source;
    EXPECT_GT(differing(frames[0], frames[2], 2), 0.02) << "model " << source;
  }
}
#endif

// The committed golden pack (format version 1, two pillows, level 5): the viewer reads the codec's own
// reference stream, each model covers its silhouette, and the morph ends at each model.
TEST_F(ViewPackTest, GoldenPackRendersBothModelsAndTheirMorph) {
  const fs::path pack = fs::path(GEOMIP_SOURCE_DIR) / "tests/data/golden-pillow.gip";
  const auto models = decode_file(pack);
  ASSERT_EQ(models.size(), 2u);
  std::vector<std::vector<std::uint8_t>> alone;
  for (int m = 0; m < 2; ++m) {
    const fs::path png = work_dir() / ("golden_" + std::to_string(m) + ".png");
    const ViewRun r = view(pack.string() + " " + size_args() + " --model " + std::to_string(m) + " --screenshot " +
                           png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    alone.push_back(load(png));
    const auto reference = cpu_coverage(models[m], models[m].level, framed(models), kW, kH);
    EXPECT_GT(iou(image_coverage(alone.back()), reference), 0.95) << "model " << m;
    EXPECT_EQ(interior_misses(image_coverage(alone.back()), reference, kW, kH), 0u) << "model " << m;
  }
  for (int end = 0; end < 2; ++end) {
    const fs::path png = work_dir() / ("golden_t" + std::to_string(end) + ".png");
    const ViewRun r = view(pack.string() + " " + size_args() + " --morph " + std::to_string(end) + " --screenshot " +
                           png.string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_LT(differing(load(png), alone[end], 2), 0.001) << "t = " << end;
  }
}

TEST_F(ViewPackTest, MorphEndPointsAndWaveletMidpoint) {
  const fs::path pack = pack_file(6);
  auto shot = [&](const std::string& name, const std::string& args) {
    const fs::path png = work_dir() / (name + ".png");
    const ViewRun r = view(pack.string() + " " + size_args() + " " + args + " --screenshot " + png.string());
    EXPECT_EQ(r.code, 0) << r.err;
    return load(png);
  };
  for (std::string schedule : {"linear", "wavelet"}) {
    const auto a = shot("a_" + schedule, "--model 0 --schedule " + schedule);
    const auto b = shot("b_" + schedule, "--model 1 --schedule " + schedule);
    const auto t0 = shot("t0_" + schedule, "--morph 0 --schedule " + schedule);
    const auto t1 = shot("t1_" + schedule, "--morph 1 --schedule " + schedule);
    EXPECT_LT(differing(t0, a, 2), 0.001) << schedule;
    EXPECT_LT(differing(t1, b, 2), 0.001) << schedule;
    EXPECT_GT(differing(a, b, 2), 0.05);
  }
  // The schedule does not move the camera: a model alone is framed alike by both (the bands summed).
  EXPECT_LT(differing(load(work_dir() / "a_linear.png"), load(work_dir() / "a_wavelet.png"), 2), 0.001);
  const auto linear = shot("mid_linear", "--morph 0.5 --schedule linear");
  const auto wavelet = shot("mid_wavelet", "--morph 0.5 --schedule wavelet");
  EXPECT_GT(differing(linear, wavelet, 8), 0.02);
}

TEST_F(ViewPackTest, StreamingShowsACoarseModelFromTheFirstFewPercent) {
  const fs::path pack = pack_file(7);
  const auto total = fs::file_size(pack);
  const auto full_models = decode_file(pack);
  // ~10 s for the whole pack: the first decodable prefix arrives long before the rest
  Server server({"--rate", std::to_string(std::max<std::uintmax_t>(total / 10, 1000))});
  ASSERT_GT(server.port(), 0);
  const fs::path first = work_dir() / "stream_first.png", last = work_dir() / "stream_last.png";
  const ViewRun r = view(server.url(pack.filename().string()) + " " + size_args() + " --first-screenshot " +
                     first.string() + " --screenshot " + last.string());
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  // "geomip-view: first screenshot from B of T bytes"
  const auto at = r.out.find("first screenshot from ");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::uint64_t shown = 0, of = 0;
  std::string word;
  std::istringstream(r.out.substr(at + 22)) >> shown >> word >> of;
  EXPECT_EQ(of, total);
  EXPECT_LE(shown, total / 20) << "first model should come from at most 5% of the pack";
  const auto coarse = image_coverage(load(first));
  const auto full = cpu_coverage(full_models[0], full_models[0].level, framed(full_models), kW, kH);
  EXPECT_GT(count(coarse), count(full) / 4) << "the coarse model should be visible";
  EXPECT_GT(iou(coarse, full), 0.6) << "and overlap the full model";
  EXPECT_GT(iou(image_coverage(load(last)), full), 0.95) << "the final frame is the full model";
}

TEST_F(ViewPackTest, ServerWithoutRangeSupportStreamsTheWholeFile) {
  const fs::path pack = pack_file(7);
  const auto total = fs::file_size(pack);
  Server server({"--no-ranges", "--rate", std::to_string(total / 4)});
  ASSERT_GT(server.port(), 0);
  const fs::path first = work_dir() / "noranges_first.png", last = work_dir() / "noranges_last.png";
  const ViewRun r = view(server.url(pack.filename().string()) + " " + size_args() + " --first-screenshot " +
                         first.string() + " --screenshot " + last.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const auto at = r.out.find("first screenshot from ");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::uint64_t shown = 0;
  std::istringstream(r.out.substr(at + 22)) >> shown;
  EXPECT_LT(shown, total / 2) << "one plain GET still shows coarse levels before the end";
  const auto models = decode_file(pack);
  EXPECT_GT(iou(image_coverage(load(last)), cpu_coverage(models[0], models[0].level, framed(models), kW, kH)), 0.95);
}

TEST_F(ViewPackTest, ServerKilledMidStreamKeepsTheLastCompleteLevel) {
  const fs::path pack = pack_file(7);
  const auto total = fs::file_size(pack);
  Server server({"--rate", std::to_string(total / 4), "--die-after", std::to_string(total / 3)});
  ASSERT_GT(server.port(), 0);
  const fs::path last = work_dir() / "killed_last.png";
  const ViewRun r = view(server.url(pack.filename().string()) + " " + size_args() + " --screenshot " + last.string());
  EXPECT_EQ(r.code, 3) << "3 = the stream failed part-way\n" << r.err;
  EXPECT_NE(r.err.find("connection"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("kept the level"), std::string::npos) << r.err;
  const auto models = decode_file(pack);
  EXPECT_GT(iou(image_coverage(load(last)), cpu_coverage(models[0], models[0].level, framed(models), kW, kH)), 0.8)
      << "the last complete level is still shown";
}

// No clock here: the server sends its first 4 KiB block and then waits 4096 s for the next one, so a viewer
// whose cancel waited for the connection would run past ctest's TIMEOUT (900 s) and fail there.
// scripts/bench-view-cancel measures how long after --timeout the viewer really exits.
TEST_F(ViewPackTest, SlowServerTimesOutWithoutWaitingForTheConnection) {
  const fs::path pack = pack_file(6);
  Server server({"--rate", "1"});
  ASSERT_GT(server.port(), 0);
  const ViewRun r = view(server.url(pack.filename().string()) + " " + size_args() + " --timeout 2");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("timed out"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" of ? bytes received"), std::string::npos) << "the manifest never arrived: " << r.err;
}

TEST_F(ViewPackTest, MissingOrNonPackSourcesGiveAClearMessage) {
  Server server({});
  ASSERT_GT(server.port(), 0);
  std::ofstream(work_dir() / "readme.txt") << "this is not a pack, just some text long enough to have a header\n";
  ViewRun r = view(server.url("nothing_here.gip") + " " + size_args());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("404"), std::string::npos) << r.err;
  r = view(server.url("readme.txt") + " " + size_args());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not a .gip pack"), std::string::npos) << r.err;
  r = view((work_dir() / "readme.txt").string() + " " + size_args());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not a .gip pack"), std::string::npos) << r.err;
  r = view((work_dir() / "missing.gip").string() + " " + size_args());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cannot open"), std::string::npos) << r.err;
}

// Found by a review on 2026-12-06: --screenshot (or --first-screenshot) naming the pack replaced the pack by
// a PNG, exit 0. Refused before any window, exit 2, one line; the pack stays as it was.
TEST_F(ViewPackTest, AScreenshotNeverReplacesThePack) {
  const fs::path pack = work_dir() / "own.gip";
  fs::copy_file(pack_file(4), pack, fs::copy_options::overwrite_existing);
  const std::string before = [&] {
    std::ifstream in(pack, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  fs::create_hard_link(pack, work_dir() / "own-link.gip");
  for (const std::string flag : {"--screenshot", "--first-screenshot"}) {
    for (const fs::path& target : {pack, work_dir() / "own-link.gip"}) {
      const ViewRun r = view(pack.string() + " " + size_args() + " " + flag + " " + target.string());
      EXPECT_EQ(r.code, 2) << flag << ": " << r.err;
      EXPECT_NE(r.err.find("would destroy the pack"), std::string::npos) << r.err;
      EXPECT_EQ(lines(r.err), 1u) << r.err;
    }
  }
  std::ifstream in(pack, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), before);
  fs::remove(work_dir() / "own-link.gip");
}

// NaN and infinities are not numbers for the camera and the timeout (a NaN camera drew a blank frame and
// exited 0; --timeout nan said "nan is negative"): exit 2, one line, before any window.
TEST_F(ViewPackTest, NanCameraAndTimeoutAreRefused) {
  const fs::path pack = pack_file(4);
  for (const std::string option :
       {"--yaw nan", "--pitch inf", "--distance nan", "--distance inf", "--timeout nan"}) {
    const ViewRun r = view(pack.string() + " " + size_args() + " " + option);
    EXPECT_EQ(r.code, 2) << option << ": " << r.err;
    EXPECT_NE(r.err.find("not a number"), std::string::npos) << option << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
  }
}

// A negative rate was taken (as a huge unsigned number: no limit at all).
TEST_F(ViewPackTest, ANegativeRateLimitIsRefused) {
  const ViewRun r = view(pack_file(4).string() + " " + size_args() + " --limit-rate -5");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("negative"), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
}

TEST_F(ViewPackTest, AStallTimeoutOutsideOneSecondToADayIsRefused) {
  for (const std::string value : {"0", "-1", "86401", "x"}) {
    const ViewRun r = view(pack_file(4).string() + " " + size_args() + " --stall-timeout " + value);
    EXPECT_EQ(r.code, 2) << value << ": " << r.err;
    EXPECT_NE(r.err.find("--stall-timeout"), std::string::npos) << value << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
  }
}

TEST_F(ViewPackTest, BenchTwoModelLevel8MorphAt1280x720) {
  const fs::path pack = pack_file(8);
  for (std::string schedule : {"linear", "wavelet"}) {
    const ViewRun r = view(pack.string() + " --frames 30 --width 1280 --height 720 --animate --bench --schedule " + schedule);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto at = r.out.find("bench ");
    ASSERT_NE(at, std::string::npos) << r.out;
    std::cout << r.out.substr(at);  // the figure for the report
  }
}


// ---- a fetcher that trusts nothing (issue 16, item 3) --------------------------------------------------------

fs::path write_file(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path path = work_dir() / name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  return path;
}

/// Packs whose manifest passes its CRC but lies about the chunks (from the committed golden pack), and the exit
/// codes allowed: 2 when nothing can be shown, 3 when a coarser level was kept.
struct Crafted {
  std::string name;
  std::vector<std::uint8_t> bytes;
  std::vector<int> codes;
};

std::vector<Crafted> crafted_packs() {
  const auto golden = read_bytes(fs::path(GEOMIP_SOURCE_DIR) / "tests/data/golden-pillow-v2.gip");
  std::vector<Crafted> out;
  auto add = [&](std::string name, std::vector<std::uint8_t> bytes, std::vector<int> codes) {
    EXPECT_FALSE(bytes.empty()) << name;
    out.push_back({std::move(name), std::move(bytes), std::move(codes)});
  };
  // every chunk 2 GiB − 1 (the codec's per-chunk bound): ~150 GB laid out in a 5 KB file
  add("crafted_huge_chunks.gip", craft_pack(golden, [](auto& s) { for (auto& v : s) v = 0x7fffffff; }), {2});
  // 4 GiB in all, spread over the chunks after the first
  add("crafted_4gib.gip", craft_pack(golden, [](auto& s) {
        for (std::size_t c = 1; c < s.size(); ++c) s[c] = (std::uint64_t{4} << 30) / (s.size() - 1);
      }), {2});
  // the last chunk runs 1 MB past the end of the file: the prefix is still a coarser level
  add("crafted_past_end.gip", craft_pack(golden, [](auto& s) { s.back() += 1 << 20; }), {3});
  // the first chunk claims 100 MB (under the 1 GiB cap, far past the file): nothing decodable arrives
  add("crafted_first_past_end.gip", craft_pack(golden, [](auto& s) { s.front() = 100u << 20; }), {2});
  // every chunk zero-length: the bytes after the manifest belong to no chunk
  add("crafted_zero_chunks.gip", craft_pack(golden, [](auto& s) { for (auto& v : s) v = 0; }), {2});
  // one chunk shortened to zero, its bytes moved into the next: the CRCs fail from there on
  add("crafted_zero_one.gip", craft_pack(golden, [](auto& s) { s[2] += s[1], s[1] = 0; }), {3});
  // a chunk count that does not match the models' passes (huge count, table as long as it says is not there)
  add("crafted_huge_count.gip", craft_pack(golden, [](auto&) {}, 1'000'000), {2});
  // the manifest itself cut short: the file ends inside it
  auto cut = golden;
  cut.resize(200);
  add("crafted_cut_manifest.gip", cut, {2});
  return out;
}

// One clean line, no signal, the allowed code, and a peak RSS far below what the lie claims (the viewer's own
// baseline under llvmpipe is ~100 MB; before the fix the 4 GiB claim zero-filled 4 GiB and the 150 GB one
// aborted with std::bad_alloc).
void expect_clean_failure(const ViewRun& r, const Crafted& c, const std::string& how) {
  const std::string what = c.name + " " + how + ": " + r.err;
  EXPECT_FALSE(r.signaled) << what;
  EXPECT_NE(std::find(c.codes.begin(), c.codes.end(), r.code), c.codes.end()) << "exit " << r.code << ", " << what;
  EXPECT_EQ(lines(r.err), 1u) << "exactly one line: " << what;
  EXPECT_EQ(r.err.rfind("geomip-view: ", 0), 0u) << what;
  EXPECT_LT(r.max_rss_kb, 600L * 1024) << "allocation bounded: " << what;
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << what;
}

TEST_F(ViewPackTest, CraftedManifestsFailCleanlyFromAFile) {
  for (const Crafted& c : crafted_packs()) {
    const fs::path path = write_file(c.name, c.bytes);
    expect_clean_failure(view_measured(path.string() + " " + size_args() + " --timeout 20"), c, "file");
  }
}

TEST_F(ViewPackTest, CraftedManifestsFailCleanlyOverHttp) {
  const auto packs = crafted_packs();
  for (const Crafted& c : packs) write_file(c.name, c.bytes);
  for (const std::vector<std::string>& mode : {std::vector<std::string>{}, {"--no-ranges"}, {"--no-ranges", "--no-length"}}) {
    Server server(mode);
    ASSERT_GT(server.port(), 0);
    const std::string how = "http" + (mode.empty() ? std::string() : " " + mode[0] + (mode.size() > 1 ? " " + mode[1] : ""));
    for (const Crafted& c : packs) {
      Crafted expected = c;
      // with no Content-Length the source's size is unknown: a 100 MB first chunk is waited for (and the
      // connection then closes early) — still one clean line
      if (mode.size() > 1) expected.codes = {2, 3};
      expect_clean_failure(view_measured(server.url(c.name) + " " + size_args() + " --timeout 20"), expected, how);
    }
  }
}

// The status lines tell what was really shown: after a chunk that fails its CRC the last "showing N of M"
// and the exit line agree on N < M.
TEST_F(ViewPackTest, StatusLinesSayWhatWasReallyShown) {
  auto bytes = read_bytes(fs::path(GEOMIP_SOURCE_DIR) / "tests/data/golden-pillow-v2.gip");
  codec::PackInfo info;
  ASSERT_EQ(codec::read_pack_info(bytes, info), codec::Status::kOk);
  const auto& bad = info.chunks[info.chunks.size() / 2];
  ASSERT_GT(bad.size, 0u);
  bytes[bad.offset] ^= 0xff;  // fails its CRC
  const fs::path path = write_file("bad_chunk.gip", bytes);
  const ViewRun r = view_measured(path.string() + " " + size_args());
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  const auto at = r.out.rfind("showing ");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::uint64_t shown = 0, total = 0;
  std::string of;
  std::istringstream(r.out.substr(at + 8)) >> shown >> of >> total;
  EXPECT_EQ(total, bytes.size());
  EXPECT_LE(shown, bad.offset) << "nothing from the bad chunk on is shown: " << r.out;
  EXPECT_NE(r.err.find("kept the level from " + std::to_string(shown) + " of " + std::to_string(total)),
            std::string::npos) << r.err;
}

TEST_F(ViewPackTest, EndlessBodiesAreCutAtThePacksSize) {
  const fs::path pack = pack_file(6);
  for (const std::vector<std::string>& mode : {std::vector<std::string>{"--endless"}, {"--endless", "--no-ranges"}}) {
    Server server(mode);
    ASSERT_GT(server.port(), 0);
    const ViewRun r = view_measured(server.url(pack.filename().string()) + " " + size_args() + " --timeout 20");
    // Exit 0, not the timeout's 2 or 3: the body was cut at the manifest's size, not read for ever.
    EXPECT_EQ(r.code, 0) << mode.size() << ": " << r.err;
    EXPECT_NE(r.out.find("showing " + std::to_string(fs::file_size(pack)) + " of "), std::string::npos)
        << r.out;
  }
}

TEST_F(ViewPackTest, RedirectsAreFollowedAndRedirectLoopsEnd) {
  const fs::path pack = pack_file(6);
  Server server({});
  ASSERT_GT(server.port(), 0);
  ViewRun r = view_measured(server.url("redirect/3/" + pack.filename().string()) + " " + size_args());
  EXPECT_EQ(r.code, 0) << r.err;
  r = view_measured(server.url("loop/" + pack.filename().string()) + " " + size_args() + " --timeout 20");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("redirects"), std::string::npos) << r.err << " (the loop ended, not the --timeout)";
}

TEST_F(ViewPackTest, ServerIgnoringRangeGetsOneRequest) {
  const fs::path pack = pack_file(6);
  const fs::path log = work_dir() / "requests.txt";
  fs::remove(log);
  {
    Server server({"--no-ranges", "--request-log", log.string()});
    ASSERT_GT(server.port(), 0);
    const ViewRun r = view_measured(server.url(pack.filename().string()) + " " + size_args());
    EXPECT_EQ(r.code, 0) << r.err;
  }
  std::stringstream requests;
  requests << std::ifstream(log).rdbuf();
  EXPECT_EQ(lines(requests.str()), 1u) << requests.str();
}

// Clock-free: each source below would take longer than ctest's TIMEOUT (900 s) to deliver the pack, so a
// viewer that waited for the stall, the rate limit or the file read (the file case once took 17.6 s instead
// of 2) instead of cancelling them fails there; what it says at the timeout must add up.
// scripts/bench-view-cancel measures how long after --timeout the viewer really exits.
TEST_F(ViewPackTest, StallsAndRateLimitsAreCancelledAtTheTimeout) {
  const fs::path pack = pack_file(6);
  const std::uint64_t size = fs::file_size(pack);
  auto expect_timed_out = [&](const ViewRun& r, const std::string& what) {
    EXPECT_TRUE(r.code == 2 || r.code == 3) << what << ": " << r.err;
    EXPECT_FALSE(r.signaled) << what;
    EXPECT_EQ(lines(r.err), 1u) << what << ": " << r.err;
    EXPECT_NE(r.err.find("timed out"), std::string::npos) << what << ": " << r.err;
    const auto [received, total] = received_at_timeout(r.err);
    if (total != 0) {  // 0: "?", the manifest never came
      EXPECT_EQ(total, size) << what << ": " << r.err;
    }
    EXPECT_LT(received, size) << what << ": " << r.err;
  };
  {
    // headers and 2000 bytes, then silence on an open connection for an hour
    Server server({"--stall-after", "2000", "--stall-seconds", "3600"});
    ASSERT_GT(server.port(), 0);
    expect_timed_out(view_measured(server.url(pack.filename().string()) + " " + size_args() + " --timeout 2"),
                     "stalled server");
  }
  {
    Server server({});
    ASSERT_GT(server.port(), 0);
    expect_timed_out(view_measured(server.url(pack.filename().string()) + " " + size_args() +
                                   " --timeout 2 --limit-rate 1"),
                     "HTTP --limit-rate 1");
  }
  expect_timed_out(view_measured(pack.string() + " " + size_args() + " --timeout 2 --limit-rate 1"),
                   "file --limit-rate 1");
  // Exit 3 at the timeout keeps the last level shown, and --screenshot writes it (it used to write nothing).
  // A level-4 pack's first level is in its first few hundred bytes, ~1 s into the 8 s timeout at 250
  // bytes/s (slack for a loaded machine); the whole pack needs more than 20 s.
  const fs::path small = pack_file(4), png = work_dir() / "timed_out.png";
  ASSERT_GT(fs::file_size(small), 5000u);
  fs::remove(png);
  const ViewRun t = view_measured(small.string() + " " + size_args() +
                                  " --timeout 8 --limit-rate 250 --screenshot " + png.string());
  EXPECT_EQ(t.code, 3) << t.err;
  ASSERT_TRUE(fs::exists(png)) << t.err;
  const auto covered = image_coverage(load(png));
  EXPECT_GT(std::count(covered.begin(), covered.end(), 1), 100) << "the model is drawn";
}

TEST_F(ViewPackTest, OutOfRangeOptionsExitTwoWithOneLine) {
  const fs::path golden = fs::path(GEOMIP_SOURCE_DIR) / "tests/data/golden-pillow-v2.gip";  // 2 models, level 5
  const fs::path single = work_dir() / "one_model.gip";
  if (!fs::exists(single)) write_file(single.filename().string(), codec::write_pack({pack_input(4, 0)}));
  const fs::path mixed = work_dir() / "levels_4_and_5.gip";
  if (!fs::exists(mixed))
    write_file(mixed.filename().string(), codec::write_pack({pack_input(4, 0), pack_input(5, 1)}));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {golden.string() + " --morph 1.5", "--morph"},
      {golden.string() + " --morph -0.25", "--morph"},
      {golden.string() + " --model 2", "--model"},
      {golden.string() + " --model 7 --morph 0.5", "--model"},
      {golden.string() + " --level 6", "--level"},
      {golden.string() + " --level -1", "--level"},
      {single.string() + " --morph 0.5", "--morph"},
      {golden.string() + " --morph abc", "--morph"},
      // models of different layouts: the morph cannot be drawn (it used to show the first model, exit 0)
      {mixed.string() + " --morph 0.5", "--morph"},
      {mixed.string() + " --animate", "--animate"},
      // one model has nothing to cycle through (it used to exit 0), and --animate ignored --morph
      {single.string() + " --animate", "--animate"},
      {golden.string() + " --animate --morph 0.3", "--animate"},
  };
  for (const auto& [args, option] : cases) {
    const ViewRun r = view_measured(args + " " + size_args());
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_NE(r.err.find(option), std::string::npos) << args << ": " << r.err;
  }
  // Headless outputs without --frames: a window that stays open would never write them.
  for (const char* option : {" --screenshot x.png", " --bench"}) {
    const ViewRun r = view_measured(golden.string() + option);
    EXPECT_EQ(r.code, 2) << option << ": " << r.err;
    EXPECT_NE(r.err.find("--frames"), std::string::npos) << option << ": " << r.err;
  }
  // in range: fine
  const ViewRun ok = view_measured(golden.string() + " --model 1 --level 5 --morph 1 " + size_args());
  EXPECT_EQ(ok.code, 0) << ok.err;
}

// The screenshot outputs are checked before any work: a directory that does not exist is exit 2 with one
// line (--screenshot's was found after the rendering, exit 1; --first-screenshot's failure was printed and
// the run went on to exit 0 saying "first screenshot from N of N bytes"). A first screenshot that cannot be
// written (a full disk, simulated by a file-size limit of 0 with SIGXFSZ ignored) exits non-zero with one
// line, does not claim it was written, and leaves the file that was there intact.
TEST_F(ViewPackTest, ScreenshotOutputsAreCheckedFirstAndFailedWritesExitNonZero) {
  const fs::path pack = pack_file(4);
  for (const char* option : {"--screenshot", "--first-screenshot"}) {
    const fs::path png = work_dir() / "no-such-dir" / "x.png";
    const ViewRun r = view_measured(pack.string() + " " + size_args() + " " + option + " " + png.string());
    EXPECT_EQ(r.code, 2) << option << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << option << ": " << r.err;
    EXPECT_NE(r.err.find(option), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("first screenshot from"), std::string::npos) << r.out;
  }
  const fs::path first = work_dir() / "first_on_full_disk.png";
  std::ofstream(first) << "old";
  // Output through a pipe (a file-size limit does not apply to pipes): stdout and stderr together.
  const std::string cmd = "trap '' XFSZ; ulimit -f 0; exec " + std::string(GEOMIP_VIEW_BINARY) + " " +
                          pack.string() + " " + size_args() + " --first-screenshot " + first.string() +
                          " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string said;
  std::array<char, 4096> buffer{};
  for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), p)) > 0;)
    said.append(buffer.data(), n);
  const int status = ::pclose(p);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal: " << said;
  EXPECT_EQ(WEXITSTATUS(status), 1) << said;
  // Its one line (stdout's status line comes through the same pipe).
  const std::size_t at = said.find("geomip-view: --first-screenshot: cannot write");
  EXPECT_NE(at, std::string::npos) << said;
  EXPECT_EQ(said.find("--first-screenshot", said.find('\n', at)), std::string::npos) << said;
  EXPECT_EQ(said.find("libpng error"), std::string::npos) << "libpng's own message: " << said;
  EXPECT_EQ(said.find("first screenshot from"), std::string::npos) << said;
  std::ifstream in(first, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "old");
  for (const auto& entry : fs::directory_iterator(work_dir()))
    EXPECT_EQ(entry.path().filename().string().find(".first_on_full_disk.png.tmp"), std::string::npos)
        << "temporary file left: " << entry.path();
}

// Cancelling (the destructor: Q in the window, the headless timeout) interrupts a --limit-rate pause on a
// file, a rate-limited transfer and a stalled server. Clock-free: at 1 byte/s the file's first pause lasts
// 256 s and ends in a progress call, so a pause that ignored the cancel shows up as a progress after it; the
// stalled server holds its connection for an hour and the rate-limited transfer needs hours, so a destructor
// that waited for either runs past ctest's TIMEOUT (900 s). The 0.7 s wait only lets each fetch reach its
// pause; under load it may cancel earlier, which must pass too. scripts/bench-view-cancel measures the delay.
TEST_F(ViewPackTest, FetcherCancelsPausesAndStalls) {
  const fs::path pack = pack_file(6);
  auto cancel_mid_fetch = [](const std::string& source, std::uint64_t rate) {
    // The last progress call (the fetch ended) comes after the cancel too; what must not change is
    // received().
    std::atomic<Fetcher*> self{nullptr};
    std::atomic<std::uint64_t> at_cancel{~std::uint64_t{0}};
    std::atomic<bool> grew{false};
    auto fetcher = std::make_unique<Fetcher>(source, FetchOptions{.limit_rate = rate}, [&] {
      if (const Fetcher* f = self.load(); f && f->received() > at_cancel.load()) grew = true;
    });
    self = fetcher.get();
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    EXPECT_FALSE(fetcher->finished()) << source;
    at_cancel = fetcher->received();
    fetcher.reset();
    EXPECT_FALSE(grew.load()) << source << ": bytes arrived after the cancel (the wait ran to its end)";
  };
  cancel_mid_fetch(pack.string(), 1);
  Server stalled({"--stall-after", "2000", "--stall-seconds", "3600"});
  ASSERT_GT(stalled.port(), 0);
  cancel_mid_fetch(stalled.url(pack.filename().string()), 0);
  Server plain({});
  ASSERT_GT(plain.port(), 0);
  cancel_mid_fetch(plain.url(pack.filename().string()), 1);
}

// --limit-rate lets the bytes in at the rate in blocks of rate_block(rate), over HTTP as from a file: no
// progress step larger than one block (libcurl's own limit let a 64 KiB range request in at once, and at
// 1000 bytes/s its catch-up wait tripped the stall guard), and the whole pack arrives. Clock-free: the steps
// are byte counts.
TEST_F(ViewPackTest, LimitRateLetsBytesInBlockByBlock) {
  const fs::path pack = pack_file(6);
  const std::uint64_t size = fs::file_size(pack), rate = 64000, block = rate_block(rate);
  ASSERT_GT(size, 4 * block);
  Server server({});
  ASSERT_GT(server.port(), 0);
  Server no_ranges({"--no-ranges"});
  ASSERT_GT(no_ranges.port(), 0);
  for (const std::string& source :
       {pack.string(), server.url(pack.filename().string()), no_ranges.url(pack.filename().string())}) {
    std::atomic<Fetcher*> self{nullptr};
    std::atomic<std::uint64_t> last{0}, largest_step{0}, steps{0};
    {
      Fetcher fetcher(source, FetchOptions{.limit_rate = rate}, [&] {
        const Fetcher* f = self.load();
        if (!f || f->total() == 0) return;  // before the manifest: nothing published yet
        const std::uint64_t now = f->received(), before = last.exchange(now);
        if (before > 0 && now > before) {
          largest_step = std::max(largest_step.load(), now - before);
          ++steps;
        }
      });
      self = &fetcher;
      while (!fetcher.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      EXPECT_EQ(fetcher.error(), "") << source;
      EXPECT_EQ(fetcher.received(), size) << source;
      self = nullptr;
    }
    EXPECT_LE(largest_step.load(), block) << source;
    EXPECT_GE(steps.load(), (size - 4096) / block) << source << ": the chunks came in blocks";
  }
}

}  // namespace
}  // namespace geomip::viewer
