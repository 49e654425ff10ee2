// End-to-end tests of the geomip program: exit codes, one-line errors, JSON keys, atomic outputs.
#include "codec/pack.h"
#include "gimage/exr_io.h"
#include "gimage/surface_distance.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

namespace geomip {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  int exit_code = -1;
  bool crashed = false;
  std::string out, err;
};

/// A spiked ellipsoid (protrusion tips for the tip and end loops) written as DIR/spiked.obj; its path.
/// `bytes` (a pack of format 4 or later) with its manifest's CRC32 computed anew: crafted manifests that the
/// readers take as intact.
std::string with_manifest_crc(std::string bytes) {
  std::size_t at = 10, manifest_size = 0;  // magic (8), version u16, varint size, CRC32 u32, manifest
  for (int shift = 0;; shift += 7) {
    const auto b = static_cast<unsigned char>(bytes[at++]);
    manifest_size |= static_cast<std::size_t>(b & 0x7f) << shift;
    if (!(b & 0x80)) break;
  }
  const std::uint16_t version = static_cast<std::uint16_t>(static_cast<unsigned char>(bytes[8]) |
                                                           static_cast<unsigned char>(bytes[9]) << 8);
  const std::uint32_t crc = codec::manifest_crc(
      version, {reinterpret_cast<const std::uint8_t*>(bytes.data()) + at + 4, manifest_size});
  for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<char>((crc >> (8 * k)) & 0xff);
  return bytes;
}

std::string write_spiked_ellipsoid(const std::string& dir) {
  const std::string mesh = dir + "/spiked.obj";
  std::ofstream out(mesh);
  write_mesh(test::spiked_ellipsoid(4, 0.15), out, MeshFormat::kObj);
  return mesh;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

/// The normalization (the viewer's frame) of the only model of the pack at `path`; a test failure and zeros
/// when the pack does not read or holds another number of models.
std::array<double, 16> sole_normalization(const std::string& path) {
  const std::string bytes = slurp(path);
  codec::PackInfo info;
  if (codec::read_pack_info({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, info) !=
          codec::Status::kOk ||
      info.models.size() != 1) {
    ADD_FAILURE() << path << ": not a one-model pack";
    return {};
  }
  return info.models[0].normalization;
}

class Cli : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("cli");
  void TearDown() override { fs::remove_all(dir_); }

  Outcome geomip(const std::string& args, int timeout_s = 300) {
    const std::string cmd = "timeout " + std::to_string(timeout_s) + " '" + GEOMIP_BINARY + "' " + args +
                            " > '" + dir_ + "/stdout' 2> '" + dir_ + "/stderr' < /dev/null";
    const int status = std::system(cmd.c_str());
    Outcome r;
    r.crashed = !WIFEXITED(status) || WEXITSTATUS(status) >= 124;  // signal, or timeout's 124/137
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(fs::path(dir_) / "stdout");
    r.err = slurp(fs::path(dir_) / "stderr");
    return r;
  }
  std::string file(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // Exit 2, exactly one line on stderr naming `path`.
  void expect_bad_input(const std::string& args, const std::string& path) {
    const Outcome r = geomip(args);
    EXPECT_FALSE(r.crashed) << args;
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected:\n" << r.err;
    // Printable: no control bytes (escape sequences from a file's garbage) and no byte that never occurs in
    // UTF-8 (the messages themselves may hold UTF-8 such as "≥").
    for (std::size_t i = 0; i + 1 < r.err.size(); ++i) {
      const auto c = static_cast<unsigned char>(r.err[i]);
      EXPECT_TRUE(c >= 0x20 && c != 0x7f && c != 0xc0 && c != 0xc1 && c < 0xf5)
          << "byte " << int(c) << " in " << r.err;
    }
  }
};

TEST_F(Cli, HelpOnEveryCommand) {
  for (const char* args : {"--help", "info --help", "repair --help"}) {
    const Outcome r = geomip(args);
    EXPECT_EQ(r.exit_code, 0) << args;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << args;
  }
  EXPECT_EQ(geomip("").exit_code, 2);             // no subcommand
  EXPECT_EQ(geomip("frobnicate x").exit_code, 2);  // unknown subcommand
  EXPECT_EQ(geomip("info").exit_code, 2);          // missing argument
}

// Every command's help names its options as a user types them: CLI11 printed negated flags with their value
// ("--fit,--no-fit{false}", "--untangle,--no-untangle{false}").
TEST_F(Cli, HelpNamesOptionsAsTheyAreTyped) {
  for (const char* command : {"info", "repair", "param", "gimage", "remesh", "eval", "convert", "encode",
                              "decode", "rd", "morph"}) {
    const Outcome r = geomip(std::string(command) + " --help");
    ASSERT_EQ(r.exit_code, 0) << command;
    for (std::size_t at = r.out.find("\n  -"); at != std::string::npos; at = r.out.find("\n  -", at + 1)) {
      const std::string names = r.out.substr(at + 1, r.out.find(' ', at + 4) - at - 1);
      EXPECT_EQ(names.find('{'), std::string::npos) << command << ": " << names;
    }
  }
  EXPECT_NE(geomip("decode --help").out.find("--untangle,--no-untangle "), std::string::npos);
  // eval was the one command without -q (scripts that pass -q everywhere failed on it).
  const std::string spot = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  const Outcome quiet =
      geomip("eval -q '" + spot + "' '" + spot + "' --samples 2000 --error-map '" + dir_ + "/map.ply'");
  EXPECT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.out, "");
  EXPECT_TRUE(fs::exists(dir_ + "/map.ply"));
}

TEST_F(Cli, InfoJsonHasTheDocumentedKeys) {
  const std::string mesh = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  const Outcome r = geomip("info --json '" + mesh + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"vertices", "faces", "components", "boundary_loops", "genus", "manifold",
                          "non_manifold_edges", "non_manifold_vertices", "degenerate_faces",
                          "unreferenced_vertices", "bbox_diagonal"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["vertices"], 2930);
  EXPECT_EQ(j["faces"], 5856);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["manifold"], true);
}

// `info --self-intersections`: the bundled mesh has none; two overlapping tetrahedra in one file cross; a
// non-manifold file is "not counted" (null), not a guess.
TEST_F(Cli, InfoCountsSelfIntersections) {
  const std::string mesh = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  Outcome r = geomip("info --json --self-intersections '" + mesh + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["self_intersections"]["pairs"], 0);
  EXPECT_FALSE(geomip("info --json '" + mesh + "'").out.find("self_intersections") != std::string::npos)
      << "counted only when asked (it costs seconds on large meshes)";
  const std::string tet = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  const std::string two = file("two.obj",
                               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                               "v 0.2 0.2 0.2\nv 1.2 0.2 0.2\nv 0.2 1.2 0.2\nv 0.2 0.2 1.2\n" +
                                   tet + "f 5 7 6\nf 5 6 8\nf 6 7 8\nf 7 5 8\n");
  r = geomip("info --json --self-intersections '" + two + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["self_intersections"]["pairs"].get<int>(), 0);
  EXPECT_GE(j["self_intersections"]["faces"].get<int>(), 4);
  r = geomip("info --self-intersections '" + two + "'");
  EXPECT_NE(r.out.find("self-intersections: "), std::string::npos) << r.out;
  const std::string pinch =
      file("pinch.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n" + tet +
                            "f 1 5 6\nf 1 6 7\nf 1 7 5\nf 5 7 6\n");
  r = geomip("info --json --self-intersections '" + pinch + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["self_intersections"].is_null()) << r.out;
  // A pack has no triangles until decoded: refused with the way to count them, before any output (it used to
  // print the pack's report as if the flag were not there).
  const std::string pack = dir_ + "/spot3.gip";
  ASSERT_EQ(geomip("convert -q '" + mesh + "' --level 3 --no-normals -o '" + pack + "'").exit_code, 0);
  ASSERT_EQ(geomip("info '" + pack + "'").exit_code, 0);
  expect_bad_input("info --self-intersections '" + mesh + "' '" + pack + "'", pack);
  r = geomip("info --json --self-intersections '" + mesh + "' '" + pack + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("geomip decode"), std::string::npos) << r.err;
}

TEST_F(Cli, BadInputsExitTwoWithOneLine) {
  const std::string missing = dir_ + "/missing.obj";
  expect_bad_input("info '" + missing + "'", missing);
  const std::string empty = file("empty.obj", "");
  expect_bad_input("info '" + empty + "'", empty);
  std::string noise(4096, '\0');
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<char>((i * 7919u) ^ (i >> 3));
  for (const char* ext : {"obj", "ply", "off", "stl"}) {
    const std::string garbage = file(std::string("garbage.") + ext, noise);
    expect_bad_input("info '" + garbage + "'", garbage);
  }
  for (const char* ext : {"gltf", "glb", "json"}) {  // JSON parsers quote the bytes they stopped at
    const std::string junk =
        file(std::string("junk.") + ext, std::string("n\xff\xfe\x01\x1b[31m") + std::string(400, 'x'));
    expect_bad_input(std::string(ext) == "json" ? "param --points '" + junk + "' -o '" + dir_ + "/p'"
                                                : "info '" + junk + "'",
                     junk);
  }
  const std::string nan = file("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  expect_bad_input("info '" + nan + "'", nan);
  const std::string oob = file("oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_bad_input("info '" + oob + "'", oob);
  const std::string ply = file("short.ply",
                               "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 10\n"
                               "property list uchar int vertex_indices\nend_header\n" +
                                   std::string(50, '\1'));
  expect_bad_input("info '" + ply + "'", ply);
  expect_bad_input("repair '" + nan + "' -o '" + dir_ + "/out.obj'", nan);
}

// Command-line mistakes: one line that says what is wrong, exit 2, before any work and with nothing written.
TEST_F(Cli, CommandLineMistakesSayWhatIsWrong) {
  const std::string spot = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  expect_bad_input("frob", "unknown command 'frob'");
  expect_bad_input("frob", "convert");  // the list of commands
  // Ranges say the bound, not 0.000000 to 1.79e308.
  expect_bad_input("decode x.gip --bytes -1 -o x.obj", "--bytes: must be >= 0, got -1");
  expect_bad_input("morph x.gip --frames 0 -o m", "--frames: must be > 0, got 0");
  expect_bad_input("eval '" + spot + "' '" + spot + "' --error-map x.ply --error-map-scale 0",
                   "--error-map-scale: must be > 0");
  // An output that cannot be a directory, found before the parameterization runs.
  const std::string a_file = file("a_file", "x");
  for (const std::string cmd : {"param", "gimage --level 3", "remesh --level 3"}) {
    expect_bad_input(cmd + " '" + spot + "' -o '" + a_file + "'", "exists and is not a directory");
    expect_bad_input(cmd + " '" + spot + "' -o '" + a_file + "/sub'", "exists and is not a directory");
  }
  expect_bad_input("rd --quick '" + spot + "' -o '" + a_file + "'", "exists and is not a directory");
  expect_bad_input("morph x.gip -o '" + a_file + "'", "exists and is not a directory");
  EXPECT_EQ(slurp(a_file), "x");
  expect_bad_input("convert '" + spot + "' -o '" + dir_ + "/no/dir/x.gip'", "does not exist");
  // A pack named like a mesh is refused (other tools would open it as one); a layout the mesh cannot hold
  // names the mesh.
  expect_bad_input("convert '" + spot + "' -o '" + dir_ + "/x.obj'", "name it .gip");
  EXPECT_FALSE(fs::exists(dir_ + "/x.obj"));
  expect_bad_input("convert '" + spot + "' --patches 100000 -o '" + dir_ + "/x.gip'", spot);
}

TEST_F(Cli, RepairWritesAtomicallyAndNeverLeavesPartialFiles) {
  const std::string out = dir_ + "/out.obj";
  // Failing run: no output file, no temporary left behind.
  const std::string nan = file("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  EXPECT_EQ(geomip("repair '" + nan + "' -o '" + out + "'").exit_code, 2);
  EXPECT_FALSE(fs::exists(out));
  // An existing output survives a failing run untouched.
  file("out.obj", "precious");
  EXPECT_EQ(geomip("repair '" + nan + "' -o '" + out + "'").exit_code, 2);
  EXPECT_EQ(slurp(out), "precious");
  // Output into a missing directory: a clear error, nothing written.
  const Outcome bad_dir = geomip("repair '" + std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj' -o '" + dir_ +
                             "/no/such/dir/x.obj'");
  EXPECT_EQ(bad_dir.exit_code, 2);  // the user's path: bad input, not a failure of the machine
  EXPECT_NE(bad_dir.err.find("does not exist"), std::string::npos) << bad_dir.err;
  // Unsupported output format is rejected before any work.
  EXPECT_EQ(geomip("repair '" + nan + "' -o '" + dir_ + "/x.stl'").exit_code, 2);
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

// Found by a review on 2026-12-06: an output that is an input of the same run is refused, whatever the
// command (repair's input, convert's --points file, under any name), and nothing is written.
TEST_F(Cli, AnOutputIsNeverAnInputOfTheSameRun) {
  const std::string mesh = dir_ + "/a.obj";
  fs::copy_file(std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj", mesh);
  const std::string before = slurp(mesh);
  fs::create_hard_link(mesh, dir_ + "/hard.obj");
  for (const std::string& out : {mesh, dir_ + "/./a.obj", dir_ + "/hard.obj"}) {
    expect_bad_input("repair '" + mesh + "' -q -o '" + out + "'", "would destroy the input");
    EXPECT_EQ(slurp(mesh), before) << out;
  }
  const std::string points = file("keep.json", "{\"models\": [{\"mesh\": \"a.obj\"}]}");
  expect_bad_input("convert --points '" + points + "' --level 3 -q -o '" + points + "'",
                   "would destroy the input");
  EXPECT_EQ(slurp(points), "{\"models\": [{\"mesh\": \"a.obj\"}]}");
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

// A report that cannot be written (a full disk) fails the run: exit 1 and one line, not exit 0 with a
// truncated JSON.
TEST_F(Cli, AReportThatCannotBeWrittenFailsTheRun) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string spot = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  const std::string cmd =
      "'" + std::string(GEOMIP_BINARY) + "' info --json '" + spot + "' > /dev/full 2> '" + dir_ + "/stderr'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = slurp(dir_ + "/stderr");
  EXPECT_NE(err.find("cannot write to standard output"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  // The same report to a file is written whole, exit 0.
  EXPECT_EQ(geomip("info --json '" + spot + "'").exit_code, 0);
}

// Inputs and outputs the review found handled badly: a directory as --points (an exception's text, exit 1),
// an unwritable morph directory (found only after the decode, exit 1), a UTF-8 byte-order mark before an
// OBJ's first vertex (the vertex lost, every index shifted), a PLY without coordinates (every point at the
// origin), out-of-range option values taken as "not given", and an output name of 255 bytes (its temporary
// name was too long: exit 1 after the work).
TEST_F(Cli, ReviewedInputsAndOptionsSayWhatIsWrong) {
  fs::create_directories(dir_ + "/pts");
  expect_bad_input("param --points '" + dir_ + "/pts' -o '" + dir_ + "/o'", "is a directory");
  expect_bad_input("convert --points '" + dir_ + "/pts' -o '" + dir_ + "/o.gip'", "is a directory");
  if (fs::is_directory("/proc/self")) {
    const std::string junk = file("junk.gip", "not a pack");
    expect_bad_input("morph '" + junk + "' -o /proc", "/proc");
  }
  const std::string plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 5\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n";
  const Outcome without = geomip("info --json '" + file("plain.obj", plain) + "'");
  const Outcome with = geomip("info --json '" + file("bom.obj", "\xEF\xBB\xBF" + plain) + "'");
  ASSERT_EQ(without.exit_code, 0) << without.err;
  ASSERT_EQ(with.exit_code, 0) << with.err;
  auto drop_input = [](nlohmann::json j) {
    j.erase("file");
    return j;
  };
  EXPECT_EQ(drop_input(nlohmann::json::parse(with.out)), drop_input(nlohmann::json::parse(without.out)));
  expect_bad_input("info '" +
                       file("noxyz.ply",
                            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float a\n"
                            "property float b\nproperty float c\nelement face 1\n"
                            "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
                            "0 1 0\n3 0 1 2\n") +
                       "'",
                   "no property 'x'");
  const std::string spot = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  for (const std::string& args :
       {"remesh '" + spot + "' --level -1 --adaptive 0.01 -o '" + dir_ + "/r'",
        "convert '" + spot + "' --level 3 --normal-level -1 -o '" + dir_ + "/n.gip'",
        "gimage '" + spot + "' --level 3 --normal-level -1 -o '" + dir_ + "/g'",
        "rd '" + spot + "' --samples 0 --no-geomip -o '" + dir_ + "/rd'",
        "rd '" + spot + "' --samples 150000000 --no-geomip -o '" + dir_ + "/rd'",
        "convert '" + spot + "' --level 3 --no-normals --normal-level 4 -o '" + dir_ + "/m.gip'"}) {
    const Outcome r = geomip(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ + "/r"));
  EXPECT_FALSE(fs::exists(dir_ + "/n.gip"));
  EXPECT_FALSE(fs::exists(dir_ + "/m.gip"));
  // repair's output formats: not the list of those geomip reads (STL among them, then refused).
  const Outcome xyz = geomip("repair '" + spot + "' -o '" + dir_ + "/out.xyz'");
  EXPECT_EQ(xyz.exit_code, 2);
  EXPECT_NE(xyz.err.find("geomip writes"), std::string::npos) << xyz.err;
  EXPECT_EQ(xyz.err.find(".stl"), std::string::npos) << xyz.err;
  // 255 bytes, the longest name most file systems take.
  const std::string longest = dir_ + "/" + std::string(251, 'b') + ".obj";
  const Outcome r = geomip("repair -q '" + spot + "' -o '" + longest + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(longest));
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST_F(Cli, RepairCowThenInfoSaysManifold) {
  GEOMIP_REQUIRE_SHARED_MESH(cow, "cow.obj");
  const std::string out = dir_ + "/cow.ply";
  const Outcome r = geomip("repair --json '" + cow + "' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["split_non_manifold_vertices"], 1);
  const Outcome info = geomip("info --json '" + out + "'");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["manifold"], true);
  EXPECT_EQ(j["genus"], 0);
}

// Issue #13: a device, FIFO or directory is refused before a byte is read (`info /dev/zero` used to grow to
// 4.3 GB in 60 s), for mesh and pack inputs alike.
TEST_F(Cli, NonRegularFilesAreRefusedUnread) {
  fs::create_symlink("/dev/zero", dir_ + "/zero.obj");
  ASSERT_EQ(::mkfifo((dir_ + "/pipe.ply").c_str(), 0600), 0);  // nobody writes: reading it would block
  fs::create_directory(dir_ + "/dir.off");
  const std::string out = dir_ + "/out.obj";
  for (const std::string& path :
       {std::string("/dev/zero"), dir_ + "/zero.obj", dir_ + "/pipe.ply", dir_ + "/dir.off"}) {
    expect_bad_input("info '" + path + "'", path);
    expect_bad_input("repair '" + path + "' -o '" + out + "'", path);
    expect_bad_input("decode '" + path + "' -o '" + out + "'", path);
  }
  const Outcome r = geomip("info /dev/zero");
  EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A .gltf's external buffer gets the same checks: its URI naming a FIFO blocked `info` forever (nobody
// writes), naming a directory ended in "std::bad_alloc". One line naming the URI, exit 2, at once.
TEST_F(Cli, GltfBufferUrisThatAreNoRegularFilesAreRefusedUnread) {
  ASSERT_EQ(::mkfifo((dir_ + "/pipe.bin").c_str(), 0600), 0);
  fs::create_directory(dir_ + "/dir.bin");
  const auto gltf = [&](const std::string& name, const std::string& uri) {
    return file(name,
                R"({"asset": {"version": "2.0"}, "buffers": [{"uri": ")" + uri + R"(", "byteLength": 96}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                    {"bufferView": 1, "componentType": 5125, "count": 12, "type": "SCALAR"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  };
  for (const auto& [name, uri, problem] :
       {std::tuple<std::string, std::string, std::string>{"fifo.gltf", "pipe.bin", "FIFO"},
        {"dir.gltf", "dir.bin", "is a directory"}}) {
    const std::string path = gltf(name, uri);
    const Outcome r = geomip("info '" + path + "'", 30);  // a blocked read ends in timeout's 124
    EXPECT_FALSE(r.crashed) << name;
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(uri), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// Issue #13: an index that does not fit an int used to drop the face silently (exit 0); a coordinate beyond
// float range used to surface as "face 0 references vertex 0, but the file has 0 vertices".
TEST_F(Cli, OverflowingIndicesAndCoordinatesNameTheLine) {
  const std::string index =
      file("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 99999999999999999999\n");
  expect_bad_input("info '" + index + "'", index);
  Outcome r = geomip("info '" + index + "'");
  EXPECT_NE(r.err.find("line 6: face vertex index '99999999999999999999' is out of range"), std::string::npos)
      << r.err;
  const std::string far = file("far.obj", "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_bad_input("info '" + far + "'", far);
  r = geomip("info '" + far + "'");
  EXPECT_NE(r.err.find("line 1: vertex coordinate 1e+39 is out of range"), std::string::npos) << r.err;
  expect_bad_input("repair '" + far + "' -o '" + dir_ + "/out.obj'", far);
  EXPECT_FALSE(fs::exists(dir_ + "/out.obj"));
}

// `repair --largest-component` keeps the largest piece, so the advice for multi-component meshes is no
// circle.
TEST_F(Cli, RepairLargestComponentMakesATwoComponentMeshUsable) {
  TriMesh small = test::tetrahedron();
  for (auto& p : small.positions) p = 0.2 * p + Eigen::Vector3d(4, 0, 0);
  const TriMesh big = test::sphere(2);
  const std::string two = dir_ + "/two.obj";
  {
    std::ofstream out(two);
    write_mesh(test::join(small, big), out, MeshFormat::kObj);
  }
  // param refuses it with one line that names the way out ...
  const std::string param_out = dir_ + "/param";
  expect_bad_input("param -q '" + two + "' -o '" + param_out + "'", two);
  const Outcome refused = geomip("param -q '" + two + "' -o '" + param_out + "'");
  EXPECT_NE(refused.err.find("2 connected components"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("geomip repair --largest-component"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(param_out));
  // ... which keeps the sphere, repaired as usual.
  const std::string one = dir_ + "/one.obj";
  const Outcome r = geomip("repair --json --largest-component '" + two + "' -o '" + one + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["removed_components"], 1);
  EXPECT_EQ(j["removed_component_faces"], 4);
  EXPECT_EQ(j["after"]["components"], 1);
  EXPECT_EQ(j["after"]["faces"], big.triangles.size());
  const TriMesh kept = read_mesh(one);
  EXPECT_EQ(kept.positions.size(), big.positions.size());
  EXPECT_EQ(analyze_topology(kept).genus, 0);
  // Without the flag the two components stay.
  ASSERT_EQ(geomip("repair -q '" + two + "' -o '" + one + "'").exit_code, 0);
  EXPECT_EQ(analyze_topology(read_mesh(one)).components, 2u);
}

TEST_F(Cli, RepairBunnyThenInfoSaysClosedGenusZero) {
  GEOMIP_REQUIRE_SHARED_MESH(bunny, "bunny.obj");
  const std::string out = dir_ + "/bunny.obj";
  const Outcome r = geomip("repair --quiet '" + bunny + "' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());  // --quiet
  const auto j = nlohmann::json::parse(geomip("info --json '" + out + "'").out);
  EXPECT_EQ(j["boundary_loops"], 0);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["manifold"], true);
}

}  // namespace
}  // namespace geomip

namespace geomip {
namespace {

class CliParam : public Cli {
 protected:
  std::string spot_ = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  std::string corr(const std::string& name, const std::string& models_json) {
    return file(name, "{\"models\": [" + models_json + "]}");
  }
  std::string model(const std::string& points, const std::string& features = "[]") {
    return "{\"mesh\": \"" + spot_ + "\", \"partition_points\": " + points + ", \"features\": " + features + "}";
  }
};

// --threads runs the patches on that many threads: the files are byte-identical for every count.
TEST_F(CliParam, ThreadsGiveByteIdenticalOutput) {
  std::string obj, json;
  for (const char* threads : {"1", "2"}) {
    const std::string out = dir_ + "/threads" + threads;
    const Outcome r = geomip("param --quiet --no-baseline --threads " + std::string(threads) + " '" + spot_ +
                             "' -o '" + out + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto j = nlohmann::json::parse(slurp(out + "/spot.param.json"));
    j.erase("seconds");  // the only field that may differ
    if (obj.empty()) {
      obj = slurp(out + "/spot.param.obj");
      json = j.dump();
    } else {
      EXPECT_EQ(slurp(out + "/spot.param.obj"), obj);
      EXPECT_EQ(j.dump(), json);
    }
  }
  const Outcome bad = geomip("param --quiet --threads -1 '" + spot_ + "' -o '" + dir_ + "/bad'");
  EXPECT_FALSE(bad.crashed);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  EXPECT_NE(bad.err.find("--threads"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ + "/bad"));
}

TEST_F(CliParam, WritesObjWithPerPatchTexcoordsAndJson) {
  const std::string out = dir_ + "/out";
  const Outcome r = geomip("param --quiet '" + spot_ + "' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(out + "/spot.param.json"));
  ASSERT_EQ(j["patches"].size(), 2u);
  EXPECT_EQ(j["flipped_triangles"], 0);
  for (const auto& p : j["patches"]) {
    EXPECT_LT(p["stretch"]["l2"].get<double>(), p["stretch_mvc"]["l2"].get<double>());
    EXPECT_EQ(p["corners"].size(), 4u);
  }
  EXPECT_EQ(j["adjacency"].size(), 8u);
  // The OBJ: the mesh's vertices in order, one group per patch, every corner v/vt with vt of its own patch.
  std::istringstream obj(slurp(out + "/spot.param.obj"));
  std::string line;
  std::size_t v = 0, vt = 0, faces = 0, groups = 0, vt_group_start = 0;
  bool vt_in_group = true;
  while (std::getline(obj, line)) {
    if (line.rfind("v ", 0) == 0) ++v;
    if (line.rfind("vt ", 0) == 0) {
      double a = -1, b = -1;
      std::sscanf(line.c_str(), "vt %lf %lf", &a, &b);
      EXPECT_TRUE(a >= 0 && a <= 1 && b >= 0 && b <= 1) << line;
      ++vt;
    }
    if (line.rfind("g patch", 0) == 0) {
      ++groups;
      vt_group_start = vt;
    }
    if (line.rfind("f ", 0) == 0) {
      ++faces;
      std::istringstream f(line.substr(2));
      std::string corner;
      while (f >> corner) {
        const std::size_t slash = corner.find('/');
        ASSERT_NE(slash, std::string::npos) << line;
        const std::size_t t = std::stoul(corner.substr(slash + 1));
        vt_in_group = vt_in_group && t > vt_group_start && t <= vt;
      }
    }
  }
  EXPECT_EQ(v, 2930u);  // spot is closed and clean: no repair, no split
  EXPECT_EQ(faces, 5856u);
  EXPECT_EQ(groups, 2u);
  EXPECT_GT(vt, v);  // seam vertices have one vt per patch
  EXPECT_TRUE(vt_in_group);
}

// Issue #13: a single triangle or a flat fan used to end in "internal failure" (exit 1) with an empty output
// folder left behind; now one InvalidInput line before any output exists.
TEST_F(CliParam, TooSmallOrFlatMeshesExitTwoWithoutOutput) {
  const std::string one = file("one.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::string fan_text = "v 0 0 0\n";
  for (int k = 0; k < 12; ++k) {
    const double a = 2 * M_PI * k / 12;
    fan_text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  for (int k = 0; k < 12; ++k)
    fan_text += "f 1 " + std::to_string(2 + k) + " " + std::to_string(2 + (k + 1) % 12) + "\n";
  const std::string fan = file("fan.obj", fan_text);
  for (const std::string& mesh : {one, fan}) {
    const std::string out_dir = dir_ + "/param-out";
    expect_bad_input("param -q '" + mesh + "' -o '" + out_dir + "'", mesh);
    EXPECT_FALSE(fs::exists(out_dir)) << mesh;
    const std::string pack = dir_ + "/x.gip";
    expect_bad_input("convert -q '" + mesh + "' --level 3 -o '" + pack + "'", mesh);
    EXPECT_FALSE(fs::exists(pack)) << mesh;
    for (const char* cmd : {"gimage -q --level 3", "remesh -q --level 3"}) {
      expect_bad_input(std::string(cmd) + " '" + mesh + "' -o '" + out_dir + "'", mesh);
      EXPECT_FALSE(fs::exists(out_dir)) << cmd << " " << mesh;
    }
    const Outcome r = geomip("param -q '" + mesh + "' -o '" + out_dir + "'");
    EXPECT_EQ(r.err.find("internal failure"), std::string::npos) << r.err;
  }
}

TEST_F(CliParam, BadCorrespondenceFilesExitTwo) {
  const std::string out = dir_ + "/out";
  auto expect_two = [&](const std::string& path, const std::string& needle) {
    const Outcome r = geomip("param --points '" + path + "' -o '" + out + "'");
    EXPECT_FALSE(r.crashed);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  };
  expect_two(corr("dup.json", model("[10, 10, 200, 300]")), "distinct");
  expect_two(corr("range.json", model("[10, 20, 30, 99999]")), "99999");
  expect_two(corr("three.json", model("[10, 20, 30]")), "4 points");
  expect_two(corr("features.json", model("[0, 1000, 2000, 2900]", "[5]") + "," + model("[0, 1000, 2000, 2900]")),
             "features");
  expect_two(file("garbage.json", "{not json"), "JSON");
  expect_two(dir_ + "/missing.json", "no such file");
  // The model is named in messages about its points.
  expect_two(corr("named.json", model("[0, 1000, 2000, 2900]") + "," + model("[10, 20, 30, 99999]")),
             "models[1] (spot.obj): partition_points[3] is vertex 99999");
  // A misspelled key would be lost silently: refused, naming the key it resembles. Keys of the user's own
  // (names, notes) stay allowed.
  expect_two(
      file("typo.json", "{\"models\": [{\"mesh\": \"" + spot_ +
                            "\", \"partition_points\": [0, 1000, 2000, 2900], \"auxilary_points\": []}]}"),
      "did you mean \"auxiliary_points\"");
  expect_two(file("case.json", "{\"Models\": [], \"models\": [" + model("[0, 1000, 2000, 2900]") + "]}"),
             "did you mean \"models\"");
  expect_two(file("model.json", "{\"model\": [" + model("[0, 1000, 2000, 2900]") + "]}"),
             "did you mean \"models\"");
  // Models of different genus: said as such (it was a message about auxiliary points, naming no model).
  {
    std::ofstream torus(dir_ + "/torus.obj");
    write_mesh(test::torus(24, 12), torus, MeshFormat::kObj);
  }
  expect_two(file("genus.json", "{\"models\": [" + model("[0, 1000, 2000, 2900]") + ", {\"mesh\": \"" + dir_ +
                                    "/torus.obj\", \"partition_points\": [0, 50, 100, 150]}]}"),
             "model 'torus' has genus 1, model 'spot' genus 0");
  expect_two(file("aux2.json",
                  "{\"models\": [" + model("[0, 1000, 2000, 2900]") + ", {\"mesh\": \"" + spot_ +
                      "\", \"partition_points\": [0, 1000, 2000, 2900], \"auxiliary_points\": [5, 6]}]}"),
             "model 'spot-1': partition_mesh: a genus-0 mesh takes 0 or 4 auxiliary points, got 2");
  // An [x,y,z] point far from the surface is a mistake (units, mesh), not a vertex to snap to.
  expect_two(corr("far.json", model("[0, 1000, 2000, [100, 100, 100]]")), "from the nearest vertex");
  const Outcome note =
      geomip("param -q --points '" +
             file("note.json", "{\"note\": \"mine\", \"models\": [" +
                                   model("[0, 1000, 2000, 2900]").insert(1, "\"name\": \"cow\", ") + "]}") +
             "' -o '" + dir_ + "/noted'");
  EXPECT_EQ(note.exit_code, 0) << note.err;
  // Several meshes without a correspondence file.
  const Outcome r = geomip("param '" + spot_ + "' '" + spot_ + "' -o '" + out + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--points"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out + "/spot.param.obj"));
}

// --tip-loop routes the two-square loop down a spike to its tip; param.json lists the loop's guides as
// side_guides, and the same points given back through CORR.json reproduce the same patches.
TEST_F(CliParam, TipLoopGuidesRoundTripThroughCorrespondenceFiles) {
  const TriMesh m = test::spiked_ellipsoid(4, 0.15);
  const std::string mesh = dir_ + "/spiked.obj";
  {
    std::ofstream out(mesh);
    write_mesh(m, out, MeshFormat::kObj);
  }
  const Outcome r = geomip("param -q --tip-loop '" + mesh + "' -o '" + dir_ + "/tip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir_ + "/tip/spiked.param.json"));
  ASSERT_TRUE(j.contains("side_guides")) << "the spike's tip is a guide of the loop";
  ASSERT_EQ(j["side_guides"].size(), 4u);
  EXPECT_TRUE(j["auxiliary_points"].empty());
  int highest = 0;
  for (int v = 1; v < static_cast<int>(m.positions.size()); ++v) {
    if (m.positions[v].z() > m.positions[highest].z()) highest = v;
  }
  bool tip_guided = false;
  for (const auto& list : j["side_guides"]) {
    for (const auto& g : list) tip_guided = tip_guided || g.get<int>() == highest;
  }
  for (const auto& c : j["partition_points"]) tip_guided = tip_guided || c.get<int>() == highest;
  EXPECT_TRUE(tip_guided) << "the highest vertex is a corner or a guide";

  const std::string c = file("tip.json", "{\"models\": [{\"mesh\": \"" + mesh + "\", \"partition_points\": " +
                                             j["partition_points"].dump() + ", \"side_guides\": " +
                                             j["side_guides"].dump() + "}]}");
  const Outcome again = geomip("param -q --points '" + c + "' -o '" + dir_ + "/again'");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto k = nlohmann::json::parse(slurp(dir_ + "/again/spiked.param.json"));
  ASSERT_EQ(k["patches"].size(), j["patches"].size());
  for (std::size_t p = 0; p < j["patches"].size(); ++p) {
    EXPECT_EQ(k["patches"][p]["sides"], j["patches"][p]["sides"]) << "patch " << p;
    EXPECT_EQ(k["patches"][p]["triangles"], j["patches"][p]["triangles"]) << "patch " << p;
  }

  // Bad guide lists and bad combinations: one line, exit 2, nothing written.
  const std::string corners = j["partition_points"].dump();
  for (const auto& [body, needle] : std::vector<std::pair<std::string, std::string>>{
           {"\"side_guides\": [[1], [2], [3]]", "4 lists"},
           {"\"side_guides\": [[1], [2], [3], \"x\"]", "side_guides[3]"},
           {"\"auxiliary_points\": [1, 2, 3, 4], \"side_guides\": [[5], [6], [7], [8]]", "both"}}) {
    const std::string bad = file("bad.json", "{\"models\": [{\"mesh\": \"" + mesh + "\", \"partition_points\": " +
                                                 corners + ", " + body + "}]}");
    const Outcome b = geomip("param -q --points '" + bad + "' -o '" + dir_ + "/bad'");
    EXPECT_FALSE(b.crashed) << body;
    EXPECT_EQ(b.exit_code, 2) << body << "\n" << b.err;
    EXPECT_EQ(std::count(b.err.begin(), b.err.end(), '\n'), 1) << b.err;
    EXPECT_NE(b.err.find(needle), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad")) << body;
  }
  for (const std::string& args : {"param -q --tip-loop --points '" + c + "' -o '" + dir_ + "/bad'",
                                  "param -q --tip-loop --patches 4 '" + mesh + "' -o '" + dir_ + "/bad'"}) {
    const Outcome b = geomip(args);
    EXPECT_EQ(b.exit_code, 2) << args << "\n" << b.err;
    EXPECT_NE(b.err.find("--tip-loop"), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad")) << args;
  }
}

// Issue #15 item 5: two features that lie the other way round on two models get the same common (u,v), so
// neither can be reached. param, remesh and convert say so in one line naming both features, exit 2 and write
// nothing.
TEST_F(CliParam, FeaturesWithTheSameCommonTargetExitTwoWithoutOutput) {
  const std::string c = corr("swap.json", model("[0, 1000, 2000, 2900]", "[100, 1752]") + "," +
                                              model("[0, 1000, 2000, 2900]", "[1752, 100]"));
  const std::string out = dir_ + "/swap";
  for (const std::string& args : {"param -q --points '" + c + "' -o '" + out + "'",
                                  "remesh -q --points '" + c + "' --level 3 -o '" + out + "'",
                                  "convert -q --points '" + c + "' --level 3 -o '" + out + ".gip'"}) {
    const Outcome r = geomip(args);
    EXPECT_FALSE(r.crashed) << args;
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("features 0 and 1 get the same common (u,v)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
    EXPECT_FALSE(fs::exists(out + ".gip")) << args;
  }
}

}  // namespace
}  // namespace geomip

namespace geomip {
namespace {

class CliGimage : public Cli {
 protected:
  std::string spot_ = std::string(GEOMIP_SOURCE_DIR) + "/data/spot.obj";
  // Two spheres, the second deformed, with corresponding partition points, and their CORR.json.
  std::string sphere_pair() {
    const TriMesh a = test::sphere(3);
    TriMesh b = a;
    for (auto& p : b.positions) p = Eigen::Vector3d(1.6 * p.x() + 0.2 * p.y() * p.y(), p.y(), 0.7 * p.z());
    for (const auto& [name, mesh] : {std::pair<std::string, const TriMesh*>{"a", &a}, {"b", &b}}) {
      std::ofstream out(dir_ + "/" + name + ".obj");
      write_mesh(*mesh, out, MeshFormat::kObj);
    }
    std::string points = "[";
    const Eigen::Vector3d corners[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    for (int k = 0; k < 4; ++k) points += (k ? ", " : "") + std::to_string(test::nearest_vertex(a, corners[k]));
    points += "]";
    return file("pair.json", "{\"models\": [{\"mesh\": \"a.obj\", \"partition_points\": " + points +
                                 "}, {\"mesh\": \"b.obj\", \"partition_points\": " + points + "}]}");
  }
};

TEST_F(CliGimage, GimageWritesOnePyramidPerPatch) {
  const std::string out = dir_ + "/out";
  const Outcome r = geomip("gimage --json '" + spot_ + "' --level 4 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["models"].size(), 1u);
  EXPECT_EQ(j["models"][0]["patches"], 2);
  EXPECT_EQ(j["models"][0]["normal_level"], 5);
  const GeometryImageFile g = read_geometry_image_exr(out + "/spot.geometry.exr");
  ASSERT_EQ(g.parts.size(), 2u);
  EXPECT_EQ(g.info.level, 4);
  EXPECT_EQ(g.info.kind, "geometry");
  EXPECT_EQ(g.info.adjacency.size(), 8u);
  EXPECT_EQ(g.info.source_mesh, "spot.obj");  // the file name, never the converting machine's directories
  ASSERT_EQ(g.parts[0].size(), 6u);  // 17, 9, 5, 3, 2, 1
  EXPECT_EQ(g.parts[0][0].width, 17);
  EXPECT_EQ(g.parts[0][3].width, 3);
  const GeometryImageFile n = read_geometry_image_exr(out + "/spot.normals.exr");
  EXPECT_EQ(n.info.kind, "normals");
  EXPECT_EQ(n.parts[1][0].width, 33);
  for (float v : n.parts[1][0].rgb) EXPECT_LE(std::abs(v), 1.001f);
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

// OBJ, PLY and GLB of the same remesh: the same watertight genus-0 surface (geomip's glTF reader merges the
// GLB's per-patch seam vertices again); the GLB carries NORMAL and TEXCOORD_0 for every vertex.
TEST_F(CliGimage, RemeshWritesWatertightObjPlyAndGlb) {
  const std::string out = dir_ + "/out";
  const Outcome r = geomip("remesh --quiet '" + spot_ + "' --level 3 -o '" + out + "' --ply --glb");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string glb = slurp(out + "/spot.M3.glb");
  ASSERT_GT(glb.size(), 20u);
  std::uint32_t json_bytes = 0;
  std::memcpy(&json_bytes, glb.data() + 12, 4);
  ASSERT_LE(20u + json_bytes, glb.size());
  const auto gltf = nlohmann::json::parse(glb.substr(20, json_bytes));
  const auto& attributes = gltf["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attributes.contains("NORMAL") && attributes.contains("TEXCOORD_0")) << attributes.dump();
  const auto count = [&](const char* name) { return gltf["accessors"][attributes[name].get<int>()]["count"]; };
  EXPECT_EQ(count("POSITION"), 2 * 9 * 9);  // 2 patches of (2^3+1)² samples, seams not welded
  EXPECT_EQ(count("NORMAL"), count("POSITION"));
  EXPECT_EQ(count("TEXCOORD_0"), count("POSITION"));
  for (const char* ext : {".obj", ".ply", ".glb"}) {
    const TriMesh m = read_mesh(out + "/spot.M3" + ext);
    EXPECT_EQ(m.triangles.size(), 256u) << ext;  // 2 patches · 4^3 quads · 2
    const TopologyReport t = analyze_topology(m);
    EXPECT_EQ(t.boundary_loops, 0u) << ext;
    EXPECT_TRUE(t.manifold) << ext;
    EXPECT_EQ(t.genus, 0) << ext;
  }
  // --draco: the same surface through KHR_draco_mesh_compression, in a smaller GLB; without --glb, refused.
  const Outcome d = geomip("remesh --quiet '" + spot_ + "' --level 3 -o '" + dir_ + "/draco' --glb --draco=12");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  const std::string dglb = slurp(dir_ + "/draco/spot.M3.glb");
  EXPECT_LT(dglb.size(), glb.size());
  EXPECT_NE(dglb.find("\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]"), std::string::npos);
  const TriMesh m = read_mesh(dir_ + "/draco/spot.M3.glb");
  EXPECT_EQ(m.triangles.size(), 256u);
  const TopologyReport t = analyze_topology(m);
  EXPECT_EQ(t.boundary_loops, 0u);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.genus, 0);
  const Outcome refused = geomip("remesh --quiet '" + spot_ + "' --level 3 -o '" + dir_ + "/nodraco' --draco");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("--glb"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir_ + "/nodraco"));
}

TEST_F(CliGimage, ConsistentSetSharesTheFaceList) {
  const std::string corr = sphere_pair();
  const std::string out = dir_ + "/out";
  const Outcome r = geomip("remesh --quiet --points '" + corr + "' --level 4 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const TriMesh a = read_mesh(out + "/a.M4.obj");
  const TriMesh b = read_mesh(out + "/b.M4.obj");
  EXPECT_EQ(a.triangles.size(), 1024u);  // 2 patches · 4^4 quads · 2
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_NE(a.positions, b.positions);
  // gimage on the same set: one pair of files per model, the same layout in both.
  const Outcome g = geomip("gimage --quiet --points '" + corr + "' --level 3 -o '" + out + "'");
  ASSERT_EQ(g.exit_code, 0) << g.err;
  const GeometryImageFile ga = read_geometry_image_exr(out + "/a.geometry.exr");
  const GeometryImageFile gb = read_geometry_image_exr(out + "/b.geometry.exr");
  EXPECT_EQ(adjacency_to_text(ga.info.adjacency), adjacency_to_text(gb.info.adjacency));
  EXPECT_EQ(ga.parts.size(), 2u);
  EXPECT_EQ(gb.parts.size(), 2u);
  EXPECT_TRUE(fs::exists(out + "/b.normals.exr"));
}

// remesh --fit (gimage/fit.h): one face list for both models of the set (with --quad-split fixed also the
// same as without --fit), closed, genus 0, and closer to each original (symmetric RMS; the ratios measured:
// docs/measurements.md, "Fitted geometry images"). --fit without a uniform remesh exits 2 with one line.
TEST_F(CliGimage, FitKeepsTheConsistentFaceListAndGetsCloser) {
  const std::string corr = sphere_pair();
  const std::string out = dir_ + "/out";
  for (const char* split : {"shorter", "fixed"}) {
    for (const char* fit : {"--fit", "--no-fit"}) {
      const Outcome r = geomip("remesh --quiet --points '" + corr + "' --level 4 " + fit + " --quad-split " +
                               split + " -o '" + out + "/" + split + (fit + 2) + "'");
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }
  std::vector<std::array<int, 3>> faces, fixed_faces;
  for (const char* name : {"a", "b"}) {
    SCOPED_TRACE(name);
    const TriMesh original = read_mesh(dir_ + "/" + name + ".obj");
    const TriMesh fitted = read_mesh(out + "/shorterfit/" + name + ".M4.obj");
    const TriMesh plain = read_mesh(out + "/shorterno-fit/" + name + ".M4.obj");
    const TriMesh fitted_fixed = read_mesh(out + "/fixedfit/" + name + ".M4.obj");
    const TriMesh plain_fixed = read_mesh(out + "/fixedno-fit/" + name + ".M4.obj");
    if (faces.empty()) faces = fitted.triangles;
    if (fixed_faces.empty()) fixed_faces = plain_fixed.triangles;
    EXPECT_EQ(fitted.triangles, faces);  // both models of the set
    EXPECT_EQ(fitted_fixed.triangles, fixed_faces);
    EXPECT_EQ(plain_fixed.triangles, fixed_faces);
    EXPECT_EQ(plain.num_triangles(), fixed_faces.size());
    const TopologyReport t = analyze_topology(fitted);
    EXPECT_EQ(t.boundary_edges, 0u);
    EXPECT_TRUE(t.manifold);
    EXPECT_EQ(t.genus, 0);
    const double ratio =
        measure_surface_distance(original, fitted).rms / measure_surface_distance(original, plain).rms;
    RecordProperty(std::string(name) + "_rms_ratio", std::to_string(ratio));
    EXPECT_LT(ratio, 0.6);
  }
  expect_bad_input("remesh --points '" + corr + "' --adaptive 0.01 --fit -o '" + out + "/x'", "--fit");
  EXPECT_FALSE(fs::exists(out + "/x"));
}

// A user layout in CORR.json: the cube's 6 faces over test::sphere()'s corners 0..7 (kept by write_mesh), one
// face list for both models; a bad layout exits 2 with one line and writes nothing.
TEST_F(CliGimage, CorrespondenceLayoutGivesSixPatchesAndOneFaceList) {
  sphere_pair();
  const std::string quads = "[[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]]";
  const std::string models = "\"models\": [{\"mesh\": \"a.obj\", \"partition_points\": [0,1,2,3,4,5,6,7]}, "
                             "{\"mesh\": \"b.obj\", \"partition_points\": [0,1,2,3,4,5,6,7]}]";
  const std::string corr = file("cube.json", "{\"layout\": {\"quads\": " + quads + "}, " + models + "}");
  const std::string out = dir_ + "/out";
  const Outcome r = geomip("remesh --quiet --points '" + corr + "' --level 3 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const TriMesh a = read_mesh(out + "/a.M3.obj");
  const TriMesh b = read_mesh(out + "/b.M3.obj");
  EXPECT_EQ(a.triangles.size(), 6u * 2 * 64);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(analyze_topology(a).genus, 0);
  const std::string bad = dir_ + "/bad";
  for (const std::string& layout : {std::string("[[0,3,2,1],[4,5,6,7]]"),  // not closed
                                    std::string("[[0,0,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]]"),
                                    std::string("[[0,3,2]]")}) {
    const std::string c = file("bad.json", "{\"layout\": {\"quads\": " + layout + "}, " + models + "}");
    const Outcome e = geomip("remesh --points '" + c + "' --level 2 -o '" + bad + "'");
    EXPECT_FALSE(e.crashed) << layout;
    EXPECT_EQ(e.exit_code, 2) << layout << "\n" << e.err;
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << layout << "\n" << e.err;
  }
  EXPECT_FALSE(fs::exists(bad));
}

TEST_F(CliGimage, BadInputsExitTwo) {
  const std::string out = dir_ + "/out";
  for (const std::string& args : {"gimage '" + spot_ + "' --level 11 -o '" + out + "'",
                                 "gimage '" + spot_ + "' --level 4 --normal-level 3 -o '" + out + "'",
                                 "remesh '" + spot_ + "' --level -1 -o '" + out + "'",
                                 "remesh '" + dir_ + "/missing.obj' --level 2 -o '" + out + "'",
                                 "remesh '" + spot_ + "' '" + spot_ + "' --level 2 -o '" + out + "'"}) {
    const Outcome r = geomip(args);
    EXPECT_FALSE(r.crashed) << args;
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  for (const char* args : {"gimage --help", "remesh --help"}) EXPECT_EQ(geomip(args).exit_code, 0) << args;
  EXPECT_EQ(geomip("gimage '" + spot_ + "' -o '" + out + "'").exit_code, 2);  // --level is required
}

TEST_F(Cli, EvalReportsMetroDistancesAndInfinitePsnrForIdenticalMeshes) {
  // A unit square and a copy 0.25 above it: every distance is 0.25, PSNR = 20·log10(√2 / 0.25).
  const std::string square = file("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  const std::string lifted =
      file("lifted.obj", "v 0 0 0.25\nv 1 0 0.25\nv 1 1 0.25\nv 0 1 0.25\nf 1 2 4\nf 2 3 4\n");
  const Outcome r = geomip("eval --json --samples 5000 '" + square + "' '" + lifted + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"hausdorff_pct", "rms_pct", "psnr_db", "hausdorff", "rms", "bbox_diagonal",
                          "original_to_approx", "approx_to_original", "seed"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_NEAR(j["hausdorff"].get<double>(), 0.25, 1e-12);
  EXPECT_NEAR(j["rms"].get<double>(), 0.25, 1e-12);
  EXPECT_NEAR(j["bbox_diagonal"].get<double>(), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(j["hausdorff_pct"].get<double>(), 25 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(j["psnr_db"].get<double>(), 20 * std::log10(std::sqrt(2.0) / 0.25), 1e-9);
  for (const char* side : {"original_to_approx", "approx_to_original"}) {
    EXPECT_EQ(j[side]["face_samples"], 5000) << side;
    EXPECT_EQ(j[side]["vertex_samples"], 4) << side;
    EXPECT_EQ(j[side]["samples"], 5004) << side;
  }
  // Text form of the same.
  const Outcome text = geomip("eval --samples 5000 '" + square + "' '" + lifted + "'");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("PSNR: 15.05 dB"), std::string::npos) << text.out;

  // Identical surfaces: PSNR is +inf, "inf" in text and null in JSON.
  const Outcome same = geomip("eval --json '" + square + "' '" + square + "'");
  ASSERT_EQ(same.exit_code, 0) << same.err;
  const auto k = nlohmann::json::parse(same.out);
  EXPECT_TRUE(k["psnr_db"].is_null());
  EXPECT_EQ(k["hausdorff"], 0.0);
  EXPECT_NE(geomip("eval '" + square + "' '" + square + "'").out.find("PSNR: inf dB"), std::string::npos);

  // Bad input: one line, exit 2, naming the file.
  const std::string missing = dir_ + "/missing.obj";
  expect_bad_input("eval '" + square + "' '" + missing + "'", missing);
  const std::string flat = file("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  expect_bad_input("eval '" + flat + "' '" + square + "'", flat);
  // Error maps: PLY files other tools read back (geomip's own reader, which is OpenMesh's), with the
  // distance as quality; the location of the maximum in JSON; a non-PLY map is refused and nothing written.
  const std::string map = dir_ + "/map.ply", map_original = dir_ + "/map-original.ply";
  const Outcome mapped = geomip("eval --json --samples 5000 '" + square + "' '" + lifted + "' --error-map '" +
                                map + "' --error-map-original '" + map_original + "'");
  ASSERT_EQ(mapped.exit_code, 0) << mapped.err;
  const auto m = nlohmann::json::parse(mapped.out);
  EXPECT_NEAR(m["error_map_scale_pct"].get<double>(), 25 / std::sqrt(2.0), 1e-4);  // every face at 0.25
  EXPECT_NEAR(m["approx_to_original"]["max_at"][2].get<double>(), 0.25, 1e-12);   // a point of `lifted`
  for (const std::string& path : {map, map_original}) {
    const TriMesh back = read_mesh(path);
    EXPECT_EQ(back.num_vertices(), 4u) << path;
    EXPECT_EQ(back.num_triangles(), 2u) << path;
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(bytes.find("property float quality"), std::string::npos) << path;
  }
  EXPECT_NEAR(read_mesh(map).positions[0].z(), 0.25, 1e-7);
  EXPECT_NEAR(read_mesh(map_original).positions[0].z(), 0.0, 1e-7);
  const std::string wrong = dir_ + "/map.obj";
  expect_bad_input("eval '" + square + "' '" + lifted + "' --error-map '" + wrong + "'", wrong);
  EXPECT_FALSE(fs::exists(wrong));
  EXPECT_EQ(geomip("eval '" + square + "'").exit_code, 2);  // APPROX missing
  EXPECT_EQ(geomip("eval --help").exit_code, 0);
}

}  // namespace
}  // namespace geomip

namespace geomip {
namespace {

// The consistent set of issue #3: horse, cow, pig and spot with corresponding partition points and eight
// features (feet, ears, eyes) from tests/data/animals.corr.json.
TEST_F(Cli, AnimalsGetIdenticalFeatureCoordinates) {
  GEOMIP_REQUIRE_SHARED_MESH(horse, "horse.obj");
  const std::string corr = std::string(GEOMIP_SOURCE_DIR) + "/tests/data/animals.corr.json";
  const std::string out = dir_ + "/animals";
  const Outcome r = geomip("param --json --points '" + corr + "' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<nlohmann::json> models;
  for (const char* stem : {"horse", "cow", "pig", "spot"}) {
    models.push_back(nlohmann::json::parse(slurp(out + "/" + stem + ".param.json")));
    EXPECT_EQ(models.back()["flipped_triangles"], 0) << stem;
    EXPECT_EQ(models.back()["seam_mismatches"], 0) << stem;
    ASSERT_EQ(models.back()["features"].size(), 8u) << stem;
  }
  for (std::size_t k = 0; k < 8; ++k) {
    const auto& f0 = models[0]["features"][k];
    for (std::size_t m = 1; m < models.size(); ++m) {
      const auto& f = models[m]["features"][k];
      EXPECT_EQ(f["patch"], f0["patch"]) << "feature " << k << " model " << m;
      EXPECT_LE(std::abs(f["u"].get<double>() - f0["u"].get<double>()), 1e-9) << "feature " << k << " model " << m;
      EXPECT_LE(std::abs(f["v"].get<double>() - f0["v"].get<double>()), 1e-9) << "feature " << k << " model " << m;
    }
  }
}

// Issue 15: the four animals with a user layout (tests/data/animals-layout.corr.json, made by
// make_animals_layout.py: a torso tube with each leg and the tail extruded as 5 patches of their own and the head
// as 17 (neck, head, a face strip between the ears and eyes, a snout), 64 quads). Every model gets the 64
// patches, no flip, and the 9 features at identical (patch, u, v) in all four, each in its designated patch (a
// foot in its leg's cap, an ear in the face's side on its side, an eye in the snout's side on its side, the tail
// root in the tail's cap); the uniform and the adaptive remesh give one face list for all four, closed, genus 0
// and outward (positive volume: no triangle turned over as a whole).
TEST_F(CliGimage, AnimalsWithAUserLayoutShareFeaturesAndFaceLists) {
  GEOMIP_REQUIRE_SHARED_MESH(horse, "horse.obj");
  const std::string corr = std::string(GEOMIP_SOURCE_DIR) + "/tests/data/animals-layout.corr.json";
  const auto spec = nlohmann::json::parse(slurp(corr));
  const auto& quad_names = spec["layout"]["quad_names"];
  const auto& feature_names = spec["layout"]["feature_names"];
  ASSERT_EQ(quad_names.size(), 64u);
  ASSERT_EQ(feature_names.size(), 9u);
  auto designated = [](const std::string& feature) -> std::string {
    if (feature.rfind("foot_", 0) == 0) return "leg_" + feature.substr(5) + "_cap";
    if (feature == "ear_l") return "face_left";
    if (feature == "ear_r") return "face_right";
    if (feature == "eye_l") return "snout_left";
    if (feature == "eye_r") return "snout_right";
    return feature + "_cap";
  };
  const std::string out = dir_ + "/animals";
  const Outcome r = geomip("param --quiet --points '" + corr + "' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const char* stems[] = {"horse", "cow", "pig", "spot"};
  std::vector<nlohmann::json> models;
  for (const char* stem : stems) {
    models.push_back(nlohmann::json::parse(slurp(out + "/" + stem + ".param.json")));
    const auto& m = models.back();
    EXPECT_EQ(m["flipped_triangles"], 0) << stem;
    EXPECT_EQ(m["seam_mismatches"], 0) << stem;
    EXPECT_EQ(m["patches"].size(), 64u) << stem;
    EXPECT_EQ(m["layout_quads"], spec["layout"]["quads"]) << stem;
    ASSERT_EQ(m["features"].size(), 9u) << stem;
    for (std::size_t k = 0; k < 9; ++k) {
      const std::string name = feature_names[k];
      EXPECT_EQ(quad_names[m["features"][k]["patch"].get<std::size_t>()], designated(name)) << stem << " " << name;
    }
  }
  for (std::size_t k = 0; k < 9; ++k)
    for (std::size_t m = 1; m < models.size(); ++m) {
      const auto &f0 = models[0]["features"][k], &f = models[m]["features"][k];
      EXPECT_EQ(f["patch"], f0["patch"]) << "feature " << k << " " << stems[m];
      EXPECT_LE(std::abs(f["u"].get<double>() - f0["u"].get<double>()), 1e-9) << "feature " << k << " " << stems[m];
      EXPECT_LE(std::abs(f["v"].get<double>() - f0["v"].get<double>()), 1e-9) << "feature " << k << " " << stems[m];
    }

  const std::string meshes = dir_ + "/remesh";
  const Outcome s = geomip("remesh --quiet --points '" + corr + "' --level 4 --adaptive 0.01 --max-depth 5 -o '" +
                           meshes + "'");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  for (const char* kind : {".M4.obj", ".adaptive.obj"}) {
    const TriMesh first = read_mesh(meshes + "/horse" + kind);
    if (std::string(kind) == ".M4.obj") {
      EXPECT_EQ(first.triangles.size(), 64u * 2 * 16 * 16);
    }
    for (const char* stem : stems) {
      const TriMesh m = read_mesh(meshes + "/" + stem + kind);
      EXPECT_EQ(m.triangles, first.triangles) << stem << kind;
      const TopologyReport t = analyze_topology(m);
      EXPECT_EQ(t.boundary_loops, 0u) << stem << kind;
      EXPECT_TRUE(t.manifold) << stem << kind;
      EXPECT_EQ(t.genus, 0) << stem << kind;
      double volume = 0;
      for (const auto& tri : m.triangles)
        volume += m.positions[tri[0]].dot(m.positions[tri[1]].cross(m.positions[tri[2]])) / 6;
      EXPECT_GT(volume, 0) << stem << kind;
    }
  }
}

TEST_F(CliGimage, AdaptiveRemeshIsWatertightSharedAndCoarserForLargerEps) {
  const std::string corr = sphere_pair();
  std::size_t previous = 0;
  for (const char* eps : {"0.02", "0.005"}) {
    const std::string out = dir_ + "/out" + eps;
    const Outcome r =
        geomip("remesh --json --points '" + corr + "' --adaptive " + eps + " --max-depth 6 -o '" + out + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["models"].size(), 2u);
    EXPECT_FALSE(fs::exists(out + "/a.M0.obj"));  // no uniform remesh unless --level is given
    const TriMesh a = read_mesh(out + "/a.adaptive.obj");
    const TriMesh b = read_mesh(out + "/b.adaptive.obj");
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_NE(a.positions, b.positions);
    EXPECT_EQ(j["models"][0]["faces"].get<std::size_t>(), a.triangles.size());
    for (const TriMesh* m : {&a, &b}) {
      const TopologyReport t = analyze_topology(*m);
      EXPECT_EQ(t.boundary_loops, 0u);
      EXPECT_TRUE(t.manifold);
      EXPECT_EQ(t.genus, 0);
    }
    EXPECT_GT(a.triangles.size(), previous) << "smaller eps, more faces";
    previous = a.triangles.size();
  }
  // --measure-samples bounds the error of more points: never fewer faces.
  const std::string strict = dir_ + "/strict";
  ASSERT_EQ(geomip("remesh --quiet --points '" + corr +
                   "' --adaptive 0.005 --max-depth 6 --measure-samples -o '" + strict + "'")
                .exit_code,
            0);
  EXPECT_GE(read_mesh(strict + "/a.adaptive.obj").triangles.size(), previous);
  const std::string out = dir_ + "/bad";
  EXPECT_EQ(geomip("remesh '" + spot_ + "' --adaptive -1 -o '" + out + "'").exit_code, 2);
  EXPECT_EQ(geomip("remesh '" + spot_ + "' --adaptive 0.01 --max-depth 11 -o '" + out + "'").exit_code, 2);
  EXPECT_EQ(geomip("remesh '" + spot_ + "' -o '" + out + "'").exit_code, 2);  // neither --level nor --adaptive
}

}  // namespace
}  // namespace geomip

namespace geomip {
namespace {

class CliPack : public CliGimage {
 protected:
  /// `geomip convert` of the spot mesh at level 4 with `switches` into DIR/name; the pack's bytes (the
  /// conversion must succeed).
  std::vector<std::uint8_t> spot_pack(const std::string& switches, const std::string& name) {
    const std::string pack = dir_ + "/" + name;
    const Outcome c = geomip("convert -q '" + spot_ + "' --level 4 " + switches + " -o '" + pack + "'");
    EXPECT_EQ(c.exit_code, 0) << c.err;
    const std::string bytes = slurp(pack);
    return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
  }
};

// convert → decode: the whole pack gives the level-N remesh's connectivity (watertight, consistently oriented);
// a prefix gives a coarser but still watertight model; --json keys; outputs atomic.
TEST_F(CliPack, ConvertThenDecodeWholeAndPrefix) {
  const std::string pack = dir_ + "/spot.gip";
  Outcome r = geomip("convert --json '" + spot_ + "' --level 5 -o '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  const std::size_t bytes = j["bytes"];
  EXPECT_EQ(bytes, fs::file_size(pack));
  EXPECT_LT(j["manifest_bytes"].get<std::size_t>(),
            530u);  // 66-90 of them: the viewer's frame (convert --up)
  // One mesh: normal-mesh resampling of the framed steps by default; nearly every sample finds its crossing.
  EXPECT_EQ(j["normal_mesh"]["steps"], 3);
  EXPECT_GE(j["normal_mesh"]["moved"].get<double>(), 0.9 * j["normal_mesh"]["samples"].get<double>());

  r = geomip("decode --json '" + pack + "' -o '" + dir_ + "/full.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["models"][0]["faces"], 2 * 2 * 32 * 32);
  const TriMesh full = read_mesh(dir_ + "/full.obj");
  const TopologyReport t = analyze_topology(full);
  EXPECT_EQ(t.boundary_loops, 0u);
  EXPECT_EQ(t.genus, 0);
  EXPECT_TRUE(t.manifold);

  r = geomip("decode --json '" + pack + "' --bytes " + std::to_string(bytes / 10) + " --level 4 -o '" + dir_ +
             "/prefix.ply'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["models"][0]["faces"], 2 * 2 * 16 * 16);
  EXPECT_LT(j["bytes_used"].get<std::size_t>(), bytes);
  EXPECT_EQ(analyze_topology(read_mesh(dir_ + "/prefix.ply")).boundary_loops, 0u);
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos);

  // glTF out and in: the same decode as .glb and .gltf gives the same `geomip info` counts as the OBJ.
  const auto info_of = [&](const std::string& path) {
    const Outcome i = geomip("info --json '" + path + "'");
    EXPECT_EQ(i.exit_code, 0) << i.err;
    auto k = nlohmann::json::parse(i.out);
    if (k.is_array()) k = k[0];
    k.erase("file");
    return k;
  };
  const nlohmann::json obj_info = info_of(dir_ + "/full.obj");
  for (const char* name : {"/full.glb", "/full.gltf"}) {
    r = geomip("decode -q '" + pack + "' -o '" + dir_ + name + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(info_of(dir_ + name), obj_info) << name;
  }
  expect_bad_input("decode -q '" + pack + "' -o '" + dir_ + "/x.stl'", "x.stl");
  // --draco: KHR_draco_mesh_compression GLB, read back with the OBJ's counts and topology (positions quantized).
  r = geomip("decode -q --draco '" + pack + "' -o '" + dir_ + "/draco.glb'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(fs::file_size(dir_ + "/draco.glb"), fs::file_size(dir_ + "/full.glb") / 2);
  const nlohmann::json draco_info = info_of(dir_ + "/draco.glb");
  for (const char* key : {"vertices", "faces", "edges", "boundary_loops", "genus", "manifold"})
    EXPECT_EQ(draco_info[key], obj_info[key]) << key;
  expect_bad_input("decode -q --draco '" + pack + "' -o '" + dir_ + "/x.obj'", "--draco");
  expect_bad_input("decode -q --draco=31 '" + pack + "' -o '" + dir_ + "/x.glb'", "--draco=31");
}

// Normal-mesh resampling is for one mesh: asked for with a consistent set it is refused before any work,
// and it is off by default there.
// --choose-loop builds the pack with the plain loop, the tip loop and the end loop and keeps the one whose
// prefixes are closest to the mesh: the pack written is byte for byte the candidate with the highest score,
// which the same convert with that loop alone writes.
// Finite coordinates whose bounding box's extent overflows float (a sphere of radius 3e38): Draco crashed
// (SIGSEGV) and left the hidden temporary file behind. `remesh --draco` refuses before the work (no output
// directory); `decode --draco` of a pack of it refuses before a byte is written (no file, no temporary file);
// one line, exit 2. Without Draco the same pack decodes.
TEST_F(CliPack, DracoRefusesAnExtentBeyondFloatRange) {
  const std::string mesh = dir_ + "/huge.obj";
  {
    TriMesh huge = test::sphere(3);
    for (auto& p : huge.positions) p *= 3e38;  // −3e38..3e38: extent 6e38 > FLT_MAX
    std::ofstream out(mesh);
    write_mesh(huge, out, MeshFormat::kObj);
  }
  expect_bad_input("remesh -q '" + mesh + "' --level 3 -o '" + dir_ + "/rm' --glb --draco", "huge.obj");
  EXPECT_FALSE(fs::exists(dir_ + "/rm"));
  const std::string pack = dir_ + "/huge.gip";
  Outcome r = geomip("convert -q --no-normals --level 3 '" + mesh + "' -o '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  fs::create_directory(dir_ + "/dec");
  expect_bad_input("decode -q --draco '" + pack + "' -o '" + dir_ + "/dec/h.glb'", "overflows float");
  EXPECT_TRUE(fs::is_empty(dir_ + "/dec")) << "no output and no temporary file";
  r = geomip("decode -q '" + pack + "' -o '" + dir_ + "/dec/h.glb'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST_F(CliPack, ChooseLoopKeepsTheBestOfTheLoops) {
  const std::string mesh = write_spiked_ellipsoid(dir_);
  const std::string common = " --no-normals --level 5 '" + mesh + "' -o '" + dir_;
  const Outcome r = geomip("convert --json --choose-loop" + common + "/chosen.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double plain = j["loop_psnr_db"]["plain"], tips = j["loop_psnr_db"]["tips"];
  EXPECT_TRUE(std::isfinite(plain) && std::isfinite(tips) && plain > 30 && tips > 30) << j.dump();
  std::string best = tips > plain ? "tips" : "plain";
  if (!j["loop_psnr_db"]["ends"].is_null()) {
    const double ends = j["loop_psnr_db"]["ends"];
    EXPECT_TRUE(std::isfinite(ends) && ends > 30) << j.dump();
    if (ends > std::max(plain, tips)) best = "ends";
  }
  const std::string loop = j["loop"];
  EXPECT_EQ(loop, best) << j.dump();
  ASSERT_EQ(geomip("convert -q" + common + "/plain.gip'").exit_code, 0);
  ASSERT_EQ(geomip("convert -q --tip-loop" + common + "/tips.gip'").exit_code, 0);
  ASSERT_EQ(geomip("convert -q --end-loop" + common + "/ends.gip'").exit_code, 0);
  const std::string chosen = slurp(dir_ + "/chosen.gip");
  EXPECT_EQ(chosen, slurp(dir_ + "/" + loop + ".gip"));
  EXPECT_NE(slurp(dir_ + "/plain.gip"), slurp(dir_ + "/tips.gip")) << "the loops differ on a spiked shape";
  EXPECT_NE(slurp(dir_ + "/tips.gip"), slurp(dir_ + "/ends.gip")) << "the end loop slides its seams";

  // A mesh without tips: the plain pack, no other candidate.
  const Outcome s = geomip("convert --json --choose-loop --no-normals --level 4 '" + spot_ + "' -o '" + dir_ + "/spot.gip'");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto k = nlohmann::json::parse(s.out);
  EXPECT_EQ(k["loop"], "plain");
  EXPECT_TRUE(k["loop_psnr_db"]["tips"].is_null());
  EXPECT_TRUE(k["loop_psnr_db"]["ends"].is_null());

  for (const std::string& args : {"convert -q --choose-loop --tip-loop" + common + "/bad.gip'",
                                  "convert -q --choose-loop --end-loop" + common + "/bad.gip'",
                                  "convert -q --choose-loop --patches 4" + common + "/bad.gip'"}) {
    const Outcome b = geomip(args);
    EXPECT_EQ(b.exit_code, 2) << args << "\n" << b.err;
    EXPECT_NE(b.err.find("--choose-loop"), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad.gip")) << args;
  }
  for (const std::string& args : {"convert -q --tip-loop --end-loop" + common + "/bad.gip'",
                                  "convert -q --end-loop --patches 4" + common + "/bad.gip'"}) {
    const Outcome b = geomip(args);
    EXPECT_EQ(b.exit_code, 2) << args << "\n" << b.err;
    EXPECT_NE(b.err.find("--end-loop"), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad.gip")) << args;
  }
}

// --search builds the loops, the 8- to 64-patch layouts at about the same samples, the best of them fitted,
// the best with the L∞ pass and the best with more framed steps, scores each on the same prefix sizes, and
// keeps the highest mean: the pack written is byte for byte what convert writes with the chosen switches, and
// the scores it reports are the decoded prefixes' PSNR (rechecked here with decode --bytes and eval for the
// chosen pack). Mixed with the switches it chooses itself: exit 2, no pack.
TEST_F(CliPack, SearchKeepsTheBestCandidate) {
  const std::string mesh = write_spiked_ellipsoid(dir_);
  const std::string common = " --no-normals --level 5 '" + mesh + "' -o '" + dir_;
  const Outcome r = geomip("convert --json --search" + common + "/chosen.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& search = j["search"];
  ASSERT_TRUE(search.is_object()) << j.dump();
  const std::vector<std::size_t> sizes = search["sizes"];
  ASSERT_FALSE(sizes.empty());
  std::string best;
  double best_psnr = -1;
  bool fitted = false, layout = false, layout32 = false, layout64 = false, framed = false, linf = false;
  for (const auto& c : search["candidates"]) {
    const std::string name = c["name"];
    ASSERT_EQ(c["psnr_db"].size(), sizes.size()) << name;
    fitted = fitted || name.find("+ fit") != std::string::npos;
    framed = framed || name.find("frame steps") != std::string::npos;
    linf = linf || name.find("+ L∞ pass") != std::string::npos;
    layout = layout || name.find("8 patches level 4") != std::string::npos;
    layout32 = layout32 || name.find("32 patches level 3") != std::string::npos;
    layout64 = layout64 || name.find("64 patches level 3") != std::string::npos;
    const double mean = c["mean_psnr_db"];
    EXPECT_TRUE(std::isfinite(mean) && mean > 30) << c.dump();
    if (mean > best_psnr) best_psnr = mean, best = name;
  }
  EXPECT_TRUE(fitted) << "the best layout is tried with --fit: " << search.dump();
  EXPECT_TRUE(layout) << "the 8-patch layout one level coarser is a candidate: " << search.dump();
  EXPECT_TRUE(layout32) << "the 32-patch layout two levels coarser is a candidate: " << search.dump();
  EXPECT_TRUE(layout64) << "the 64-patch layout two levels coarser is a candidate: " << search.dump();
  EXPECT_TRUE(framed) << "the best is tried with 4 (and, at its level, 5) framed steps: " << search.dump();
  EXPECT_TRUE(linf) << "the best is tried with the L∞ pass: " << search.dump();
  EXPECT_EQ(search["chosen"], best) << search.dump();
  const std::string switches = search["switches"];
  const std::size_t level_at = switches.find("--level ");
  EXPECT_EQ(j["level"], level_at == std::string::npos ? 5 : std::stoi(switches.substr(level_at + 8)));
  // The same pack as convert with the chosen switches.
  const std::string direct_common =
      level_at == std::string::npos ? common : " --no-normals '" + mesh + "' -o '" + dir_;  // its own --level
  ASSERT_EQ(geomip("convert -q " + switches + direct_common + "/direct.gip'").exit_code, 0);
  EXPECT_EQ(slurp(dir_ + "/chosen.gip"), slurp(dir_ + "/direct.gip")) << switches;
  // Its score is the PSNR of its decoded prefixes (the grids as decoded, as rd measures them).
  double sum = 0;
  for (std::size_t n : sizes) {
    ASSERT_EQ(geomip("decode -q --no-untangle '" + dir_ + "/chosen.gip' --bytes " + std::to_string(n) +
                     " -o '" + dir_ + "/prefix.obj'")
                  .exit_code,
              0);
    const Outcome e = geomip("eval --json '" + mesh + "' '" + dir_ + "/prefix.obj'");
    ASSERT_EQ(e.exit_code, 0) << e.err;
    sum += nlohmann::json::parse(e.out)["psnr_db"].get<double>();
  }
  EXPECT_NEAR(sum / static_cast<double>(sizes.size()), best_psnr, 1e-6);

  for (const std::string& args : {"convert -q --search --fit" + common + "/bad.gip'",
                                  "convert -q --search --tip-loop" + common + "/bad.gip'",
                                  "convert -q --search --patches 8" + common + "/bad.gip'",
                                  "convert -q --search --choose-loop" + common + "/bad.gip'"}) {
    const Outcome b = geomip(args);
    EXPECT_EQ(b.exit_code, 2) << args << "\n" << b.err;
    EXPECT_NE(b.err.find("--search"), std::string::npos) << b.err;
    EXPECT_FALSE(fs::exists(dir_ + "/bad.gip")) << args;
  }
  const Outcome b = geomip("rd --search --fit '" + mesh + "' -o '" + dir_ + "/rd'");
  EXPECT_EQ(b.exit_code, 2) << b.err;
  EXPECT_NE(b.err.find("--search"), std::string::npos) << b.err;
  EXPECT_FALSE(fs::exists(dir_ + "/rd/rd.csv"));
}

TEST_F(CliPack, NormalMeshRefusedForSeveralMeshes) {
  const std::string pack = dir_ + "/two.gip";
  const Outcome r = geomip("convert -q '" + spot_ + "' '" + spot_ + "' --normal-mesh 2 --level 3 -o '" + pack + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("one mesh"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(pack));
  expect_bad_input("convert -q '" + spot_ + "' --normal-mesh 9 --level 8 -o '" + pack + "'", "--normal-mesh");
}

// The codec's tools can be switched off for ablations: without local frames (and without normal-mesh
// resampling) the whole pack decodes losslessly up to the quantization, i.e. every decoded vertex lies within
// half a quantization step per coordinate of the level-N remesh's (same parameterization, same samples);
// with the default frames the rotation rounds (about a step per coordinate), which this bound does not allow.
// Both commands are given the same curvature metric (convert's default is not remesh's), so the same
// parameterization, and convert --no-fit (samples on the surface, as remesh's). Out-of-range switches: exit
// 2, one line, no pack.
TEST_F(CliPack, CodecSwitchesForAblations) {
  Outcome r = geomip("remesh --quiet '" + spot_ +
                     "' --level 4 --sampling-exponent 0 --curvature-metric 0.03 -o '" + dir_ + "/m'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const TriMesh remesh = read_mesh(dir_ + "/m/spot.M4.obj");
  const BoundingBox box = referenced_bounding_box(remesh);
  const double step = (box.max - box.min).maxCoeff() / 16384.0;  // 14 bits over the largest extent
  const auto largest_offset_in_steps = [&](const std::string& switches) {
    const std::string pack = dir_ + "/ablation.gip";
    const Outcome c = geomip("convert -q '" + spot_ +
                             "' --level 4 --no-normals --normal-mesh 0 --no-fit --curvature-metric 0.03 " +
                             switches + " -o '" + pack + "'");
    EXPECT_EQ(c.exit_code, 0) << c.err;
    const Outcome d = geomip("decode -q --no-untangle '" + pack + "' -o '" + dir_ + "/ablation.obj'");
    EXPECT_EQ(d.exit_code, 0) << d.err;
    const TriMesh decoded = read_mesh(dir_ + "/ablation.obj");
    EXPECT_EQ(decoded.num_vertices(), remesh.num_vertices());
    double largest = 0;  // over decoded vertices: distance (L∞) to the nearest remesh vertex
    for (const Eigen::Vector3d& p : decoded.positions) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector3d& q : remesh.positions) nearest = std::min(nearest, (p - q).lpNorm<Eigen::Infinity>());
      largest = std::max(largest, nearest);
    }
    return largest / step;
  };
  EXPECT_LE(largest_offset_in_steps("--frame-steps 0 --no-orientation-weights --headroom-bits 0"),
            0.5 + 1e-6);
  EXPECT_LE(largest_offset_in_steps("--frame-steps 0 --headroom-bits 0"), 0.5 + 1e-6);
  EXPECT_GT(largest_offset_in_steps("--frame-steps 3 --tangential-shift 2 --headroom-bits 0"), 0.5);
  // With the default headroom the finest band loses its last 4 of 18 bits (reconstructed at the middle):
  // no longer within half a 14-bit step, but within two.
  const double headroom = largest_offset_in_steps("--frame-steps 0");
  EXPECT_GT(headroom, 0.5);
  EXPECT_LE(headroom, 2.0);
  const std::string pack = dir_ + "/bad.gip";
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --frame-steps 5 -o '" + pack + "'", "--frame-steps");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --tangential-shift 9 -o '" + pack + "'",
                   "--tangential-shift");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --headroom-bits 11 -o '" + pack + "'",
                   "--headroom-bits");
}

// convert --normal-layers: 2 (the default, pack format 11) codes the normal maps in two layers, 1 as the xyz
// map alone; both decode to unit normals on the same geometry; out-of-range values and --no-normals exit 2
// with one line and nothing written.
TEST_F(CliPack, NormalLayersChooseTheCoding) {
  const std::vector<std::uint8_t> two = spot_pack("", "l2.gip"),
                                  one = spot_pack("--normal-layers 1", "l1.gip");
  codec::PackInfo a, b;
  ASSERT_EQ(codec::read_pack_info(two, a), codec::Status::kOk);
  ASSERT_EQ(codec::read_pack_info(one, b), codec::Status::kOk);
  EXPECT_EQ(a.models.at(0).normal_layers, 2);
  EXPECT_EQ(b.models.at(0).normal_layers, 1);
  const codec::PackDecodeResult x = codec::decode_pack(two), y = codec::decode_pack(one);
  ASSERT_EQ(x.status, codec::Status::kOk);
  ASSERT_EQ(y.status, codec::Status::kOk);
  ASSERT_EQ(x.models.at(0).normals.size(), y.models.at(0).normals.size());
  double worst = 1;
  for (std::size_t p = 0; p < x.models[0].normals.size(); ++p) {
    EXPECT_EQ(x.models[0].geometry[p].values, y.models[0].geometry[p].values) << "patch " << p;
    const std::vector<float>& u = x.models[0].normals[p].values;
    const std::vector<float>& v = y.models[0].normals[p].values;
    ASSERT_EQ(u.size(), v.size());
    for (std::size_t k = 0; k + 2 < u.size(); k += 3) {
      ASSERT_NEAR(std::sqrt(u[k] * u[k] + u[k + 1] * u[k + 1] + u[k + 2] * u[k + 2]), 1.0, 1e-5);
      // Both codings end near the same map: within a degree of each other (measured: 0.36° at most).
      worst = std::min(worst, double(u[k] * v[k] + u[k + 1] * v[k + 1] + u[k + 2] * v[k + 2]));
      ASSERT_GT(u[k] * v[k] + u[k + 1] * v[k + 1] + u[k + 2] * v[k + 2], std::cos(M_PI / 180)) << k;
    }
  }
  std::cout << "[ figures  ] largest angle between the codings "
            << std::acos(std::min(worst, 1.0)) * 180 / M_PI << "°\n";
  const std::string pack = dir_ + "/bad.gip";
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --normal-layers 3 -o '" + pack + "'",
                   "--normal-layers");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --no-normals --normal-layers 2 -o '" + pack + "'",
                   "--normal-layers");
}

// convert --normal-bits B: the normal maps are quantized with B bits instead of 10 — a smaller pack whose
// decoded normals lie within the coarser quantization of the 10-bit pack's (without headroom a full decode
// is lossless up to the quantization, each component within half a step of the unit input, step = extent /
// 2^B ≤ 2 / 2^B, and is then renormalized: a unit vector off by e ends at most |e| ≤ √3·step/2 (to first
// order) from the input); the geometry is untouched; out-of-range values and --no-normals exit 2 with one
// line and nothing written. --normal-headroom-bits H reaches the normal maps' codec header (the bottom
// bit-plane; 4 by default), with the same refusals. (The xyz coding: --normal-layers 1; two layers are
// checked by NormalLayersChooseTheCoding.)
TEST_F(CliPack, NormalBitsQuantizeTheNormalMaps) {
  const auto convert = [&](const std::string& switches, const std::string& name) {
    return spot_pack(switches, name);
  };
  const std::vector<std::uint8_t> ten = convert("--normal-headroom-bits 0 --normal-layers 1", "n10.gip"),
                                  seven = convert(
                                      "--normal-bits 7 --normal-headroom-bits 0 --normal-layers 1", "n7.gip"),
                                  room = convert("", "n10h.gip"),
                                  room2 = convert("--normal-headroom-bits 2", "n10h2.gip");
  const auto bottom_plane = [](const std::vector<std::uint8_t>& pack) {
    codec::PackInfo info;
    EXPECT_EQ(codec::read_pack_info(pack, info), codec::Status::kOk);
    return info.models.at(0).normals.bottom_bitplane;
  };
  EXPECT_EQ(bottom_plane(ten), 0);
  EXPECT_EQ(bottom_plane(seven), 0);
  EXPECT_EQ(bottom_plane(room), codec::PackWriteOptions{}.normal_codec.headroom_bits);
  EXPECT_EQ(bottom_plane(room2), 2);
  EXPECT_LT(seven.size(), ten.size() * 9 / 10);
  const codec::PackDecodeResult a = codec::decode_pack(ten), b = codec::decode_pack(seven);
  ASSERT_EQ(a.status, codec::Status::kOk);
  ASSERT_EQ(b.status, codec::Status::kOk);
  ASSERT_EQ(a.models.size(), 1u);
  ASSERT_EQ(b.models.size(), 1u);
  const codec::DecodedModel &ma = a.models[0], &mb = b.models[0];
  ASSERT_EQ(ma.normals.size(), mb.normals.size());
  ASSERT_FALSE(ma.normals.empty());
  // Measured 0.0100 on this mesh; 6 bits would reach about twice that.
  const double bound = 1.02 * std::sqrt(3.0) / 2 * (2.0 / 128 + 2.0 / 1024);
  double largest = 0;
  bool differ = false;
  for (std::size_t p = 0; p < ma.normals.size(); ++p) {
    ASSERT_EQ(ma.normals[p].values.size(), mb.normals[p].values.size());
    for (std::size_t k = 0; k < ma.normals[p].values.size(); ++k) {
      const double d = std::abs(double(ma.normals[p].values[k]) - double(mb.normals[p].values[k]));
      largest = std::max(largest, d);
      differ = differ || d > 0;
    }
    EXPECT_EQ(ma.geometry[p].values, mb.geometry[p].values) << "patch " << p;
  }
  EXPECT_TRUE(differ) << "--normal-bits 7 decoded the same normals as 10 bits";
  EXPECT_LE(largest, bound);
  const std::string pack = dir_ + "/bad.gip";
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --normal-bits 5 -o '" + pack + "'", "--normal-bits");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --normal-bits 17 -o '" + pack + "'",
                   "--normal-bits");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --normal-bits 8 --no-normals -o '" + pack + "'",
                   "--normal-bits");
  expect_bad_input("convert -q '" + spot_ + "' --level 4 --normal-headroom-bits 9 -o '" + pack + "'",
                   "--normal-headroom-bits");
  expect_bad_input(
      "convert -q '" + spot_ + "' --level 4 --normal-headroom-bits 2 --no-normals -o '" + pack + "'",
      "--normal-headroom-bits");
  EXPECT_FALSE(fs::exists(pack));
}

// convert --fit: the whole pack decodes closer to the mesh (symmetric RMS; the ratio measured:
// docs/measurements.md, "Fitted geometry images"), and with `decode --quad-split fixed` to the same faces as
// without it (the default split follows the decoded samples); --fit=x exits 2 with one line. The default
// (fit_by_default()): one mesh is fitted, on two squares and on a K-patch layout; a consistent set is not.
TEST_F(CliPack, FitDecodesCloserToTheMesh) {
  const TriMesh original = read_mesh(spot_);
  std::vector<TriMesh> decoded, fixed;
  std::vector<std::string> bytes;
  for (const char* fit : {"--fit", "--no-fit"}) {
    const std::string pack = dir_ + "/fit.gip", obj = dir_ + "/fit.obj", fixed_obj = dir_ + "/fit-fixed.obj";
    const Outcome c = geomip("convert -q '" + spot_ + "' --level 5 --no-normals " + fit + " -o '" + pack + "'");
    ASSERT_EQ(c.exit_code, 0) << c.err;
    bytes.push_back(slurp(pack));
    const Outcome d = geomip("decode -q '" + pack + "' -o '" + obj + "'");
    ASSERT_EQ(d.exit_code, 0) << d.err;
    decoded.push_back(read_mesh(obj));
    const Outcome f = geomip("decode -q '" + pack + "' --quad-split fixed -o '" + fixed_obj + "'");
    ASSERT_EQ(f.exit_code, 0) << f.err;
    fixed.push_back(read_mesh(fixed_obj));
  }
  EXPECT_EQ(fixed[0].triangles, fixed[1].triangles);
  EXPECT_EQ(decoded[0].num_triangles(), fixed[0].num_triangles());
  const double ratio =
      measure_surface_distance(original, decoded[0]).rms / measure_surface_distance(original, decoded[1]).rms;
  RecordProperty("spot_rms_ratio", std::to_string(ratio));
  EXPECT_LT(ratio, 0.85);
  ASSERT_NE(bytes[0], bytes[1]);
  const Outcome d =
      geomip("convert --json -q '" + spot_ + "' --level 5 --no-normals -o '" + dir_ + "/d.gip'");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_TRUE(nlohmann::json::parse(d.out)["fit"].get<bool>());
  EXPECT_EQ(slurp(dir_ + "/d.gip"), bytes[0]);  // two squares: fitted by default
  std::vector<std::string> k_patches;
  for (const char* fit : {"", "--no-fit", "--fit"}) {
    const std::string pack = dir_ + "/k" + std::to_string(k_patches.size()) + ".gip";
    const Outcome c = geomip("convert --json -q '" + spot_ + "' --patches 6 --level 4 --no-normals " + fit +
                             " -o '" + pack + "'");
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(nlohmann::json::parse(c.out)["fit"].get<bool>(), std::string(fit) != "--no-fit") << fit;
    k_patches.push_back(slurp(pack));
  }
  EXPECT_EQ(k_patches[0], k_patches[2]);  // K patches: fitted by default too
  EXPECT_NE(k_patches[0], k_patches[1]);
  const Outcome set = geomip("convert --json -q --points '" + sphere_pair() +
                             "' --level 3 --no-normals -o '" + dir_ + "/set.gip'");
  ASSERT_EQ(set.exit_code, 0) << set.err;
  EXPECT_FALSE(nlohmann::json::parse(set.out)["fit"].get<bool>());  // a consistent set: not by default
  const Outcome bad = geomip("convert -q '" + spot_ + "' --level 3 --fit=x -o '" + dir_ + "/bad.gip'");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ + "/bad.gip"));
}

// decode opens the folds of the decoded grids by default (normal-mesh resampling leaves triangles that cross
// their neighbours: the level-6 spot had 328 self-intersecting faces): far fewer self-intersections, the same
// face list and vertex count as --no-untangle (the grids as decoded choose the split), the distance to the
// mesh no worse than a few percent, and the glTF seams still closed (bit-identical seam samples). Grids
// coarser than level 6 are left as decoded (opening their folds shortened a level-4 horse's legs: −7 dB).
TEST_F(CliPack, DecodeOpensFoldsKeepingFacesAndDistance) {
  const TriMesh original = read_mesh(spot_);
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 6 --no-normals -o '" + pack + "'").exit_code, 0);
  const Outcome d = geomip("decode --json '" + pack + "' -o '" + dir_ + "/open.obj'");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  const auto stats = nlohmann::json::parse(d.out)["models"][0]["untangle"];
  EXPECT_GT(stats["folded_before"].get<int>(), 0);
  EXPECT_LT(stats["folded_after"].get<int>(), stats["folded_before"].get<int>());
  EXPECT_EQ(stats["level"].get<int>(), 6);  // the grid the counts are on
  ASSERT_EQ(geomip("decode -q --no-untangle '" + pack + "' -o '" + dir_ + "/raw.obj'").exit_code, 0);
  const TriMesh open = read_mesh(dir_ + "/open.obj"), raw = read_mesh(dir_ + "/raw.obj");
  EXPECT_EQ(open.triangles, raw.triangles);
  ASSERT_EQ(open.num_vertices(), raw.num_vertices());
  EXPECT_NE(open.positions, raw.positions);
  const auto crossings_open = count_self_intersections(open), crossings_raw = count_self_intersections(raw);
  ASSERT_TRUE(crossings_open && crossings_raw);
  RecordProperty("self_intersecting_faces", std::to_string(crossings_open->faces) + " of " +
                                                std::to_string(open.num_triangles()) + " (raw " +
                                                std::to_string(crossings_raw->faces) + ")");
  EXPECT_GT(crossings_raw->faces, 100u) << "the fixture no longer folds: the test would prove nothing";
  EXPECT_LT(crossings_open->faces * 3, crossings_raw->faces);
  EXPECT_LT(measure_surface_distance(original, open).rms, 1.05 * measure_surface_distance(original, raw).rms);
  const TopologyReport t = analyze_topology(open);
  EXPECT_EQ(t.boundary_edges, 0u);
  EXPECT_EQ(t.genus, 0);
  ASSERT_EQ(geomip("decode -q '" + pack + "' -o '" + dir_ + "/open.glb'").exit_code, 0);
  const TopologyReport g = analyze_topology(read_mesh(dir_ + "/open.glb"));
  EXPECT_EQ(g.boundary_edges, 0u) << "seam samples moved differently in the patches that share them";
  EXPECT_EQ(g.genus, 0);
  // A level-5 pack is written as decoded.
  const std::string coarse = dir_ + "/spot5.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 5 --no-normals -o '" + coarse + "'").exit_code, 0);
  const Outcome c = geomip("decode --json '" + coarse + "' -o '" + dir_ + "/c.obj'");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(nlohmann::json::parse(c.out)["models"][0]["untangle"]["applied"], false);
  ASSERT_EQ(geomip("decode -q --no-untangle '" + coarse + "' -o '" + dir_ + "/c_raw.obj'").exit_code, 0);
  EXPECT_EQ(read_mesh(dir_ + "/c.obj").positions, read_mesh(dir_ + "/c_raw.obj").positions);
  // So is an output level below 6 of a finer pack: the folds opened are those of the grid written.
  const Outcome l5 = geomip("decode --json --level 5 '" + pack + "' -o '" + dir_ + "/l5.obj'");
  ASSERT_EQ(l5.exit_code, 0) << l5.err;
  EXPECT_EQ(nlohmann::json::parse(l5.out)["models"][0]["untangle"]["applied"], false);
  ASSERT_EQ(geomip("decode -q --no-untangle --level 5 '" + pack + "' -o '" + dir_ + "/l5_raw.obj'").exit_code,
            0);
  EXPECT_EQ(read_mesh(dir_ + "/l5.obj").positions, read_mesh(dir_ + "/l5_raw.obj").positions);
}

// Options and inputs that used to pass silently: NaN where a number in a range is asked (CLI::Range lets
// NaN through, and the option acted as its default), --normal-mesh below 0, two error maps on one path, and a
// closed mesh with a face flipped (analyze_topology calls it manifold; its volume cancels, and convert said
// "the mesh is flat"): now refused, or repaired first as an open mesh is.
TEST_F(CliPack, NanOptionsSharedOutputsAndFlippedFacesAreHandled) {
  expect_bad_input("convert -q '" + spot_ + "' --sampling-exponent nan -o '" + dir_ + "/x.gip'", "nan");
  expect_bad_input("param -q '" + spot_ + "' --curvature-metric inf -o '" + dir_ + "/x'", "inf");
  expect_bad_input("convert -q '" + spot_ + "' --normal-mesh-reach nan -o '" + dir_ + "/x.gip'", "nan");
  expect_bad_input("convert -q '" + spot_ + "' --normal-mesh -1 -o '" + dir_ + "/x.gip'", "-1");
  EXPECT_FALSE(fs::exists(dir_ + "/x.gip"));
  expect_bad_input("eval '" + spot_ + "' '" + spot_ + "' --error-map '" + dir_ +
                       "/m.ply' --error-map-original '" + dir_ + "/./m.ply'",
                   "overwrite");
  EXPECT_FALSE(fs::exists(dir_ + "/m.ply"));
  // repair_mesh's refusals name the file (they said "repair_mesh: every face is degenerate").
  const std::string collapsed =
      file("collapsed.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n");
  expect_bad_input("repair '" + collapsed + "' -o '" + dir_ + "/r.obj'",
                   "collapsed.obj: every face is degenerate");
  expect_bad_input("convert -q '" + collapsed + "' -o '" + dir_ + "/r.gip'",
                   "collapsed.obj: every face is degenerate");
  // A mesh whose faces all go in repair: said of the file, nothing written (it was "write_mesh: the mesh has
  // no triangles").
  const std::string line = file("line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n");
  expect_bad_input("repair '" + line + "' -o '" + dir_ + "/r.obj'", "line.obj: no face is left after repair");
  EXPECT_FALSE(fs::exists(dir_ + "/r.obj"));
  TriMesh flipped = read_mesh(spot_);
  std::swap(flipped.triangles[7][1], flipped.triangles[7][2]);
  const std::string path = dir_ + "/flipped.obj";
  {
    std::ofstream out(path);
    write_mesh(flipped, out, MeshFormat::kObj);
  }
  const Outcome r = geomip("convert '" + path + "' --level 3 --no-normals -o '" + dir_ + "/f.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("inconsistently oriented mesh repaired first"), std::string::npos) << r.err;
}

// A pack with normal maps decodes to OBJ/PLY/OFF with the maps' normals per vertex (OBJ `vn` and `v//vn`,
// PLY nx/ny/nz, NOFF): unit, one per vertex, facing as the surface does; a geometry-only pack writes none.
TEST_F(CliPack, DecodeWritesTheNormalMapsNormalsInEveryFormat) {
  const std::string pack = dir_ + "/spot.gip", bare = dir_ + "/bare.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 4 -o '" + pack + "'").exit_code, 0);
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 4 --no-normals -o '" + bare + "'").exit_code, 0);
  ASSERT_EQ(geomip("decode -q '" + pack + "' -o '" + dir_ + "/n.obj'").exit_code, 0);
  const std::string obj = slurp(dir_ + "/n.obj");
  std::istringstream lines(obj);
  std::string line;
  std::vector<Eigen::Vector3d> normals;
  std::size_t corners_with_normal = 0, faces = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("vn ", 0) == 0) {
      Eigen::Vector3d n;
      std::istringstream(line.substr(3)) >> n.x() >> n.y() >> n.z();
      normals.push_back(n);
    } else if (line.rfind("f ", 0) == 0) {
      ++faces;
      corners_with_normal += static_cast<std::size_t>(std::count(line.begin(), line.end(), '/')) / 2;
    }
  }
  const TriMesh mesh = read_mesh(dir_ + "/n.obj");
  ASSERT_EQ(normals.size(), mesh.num_vertices());
  EXPECT_EQ(corners_with_normal, 3 * faces);
  const std::vector<Eigen::Vector3d> geometric = vertex_normals(mesh);
  std::size_t agree = 0;
  for (std::size_t v = 0; v < normals.size(); ++v) {
    EXPECT_NEAR(normals[v].norm(), 1.0, 1e-4) << v;
    agree += normals[v].dot(geometric[v]) > 0.5 ? 1 : 0;
  }
  EXPECT_GT(agree, 95 * normals.size() / 100) << "the maps' normals face as the surface does";
  for (const char* ext : {"ply", "off"}) {
    ASSERT_EQ(geomip("decode -q '" + pack + "' -o '" + dir_ + "/n." + ext + "'").exit_code, 0) << ext;
    EXPECT_EQ(read_mesh(dir_ + "/n." + ext).positions, mesh.positions) << ext;
  }
  EXPECT_NE(slurp(dir_ + "/n.ply").find("property float nx"), std::string::npos);
  EXPECT_EQ(slurp(dir_ + "/n.off").rfind("NOFF", 0), 0u);
  ASSERT_EQ(geomip("decode -q '" + bare + "' -o '" + dir_ + "/b.obj'").exit_code, 0);
  EXPECT_EQ(slurp(dir_ + "/b.obj").find("\nvn "), std::string::npos) << "no normal maps, no normals";
}

// remesh --untangle: the same face list and vertex count as the paper's remesh, no more crossing faces, the
// distance to the mesh within a few percent.
TEST_F(CliPack, RemeshUntangleKeepsFacesAndDoesNotAddCrossings) {
  const TriMesh original = read_mesh(spot_);
  ASSERT_EQ(geomip("remesh -q '" + spot_ + "' --level 6 -o '" + dir_ + "/plain'").exit_code, 0);
  const Outcome r = geomip("remesh --json '" + spot_ + "' --level 6 --untangle -o '" + dir_ + "/open'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"folded_after\""), std::string::npos) << "--json reports the untangling";
  const TriMesh plain = read_mesh(dir_ + "/plain/spot.M6.obj"), open = read_mesh(dir_ + "/open/spot.M6.obj");
  EXPECT_EQ(open.triangles, plain.triangles);
  ASSERT_EQ(open.num_vertices(), plain.num_vertices());
  const auto a = count_self_intersections(plain), b = count_self_intersections(open);
  ASSERT_TRUE(a && b);
  EXPECT_LE(b->faces, a->faces);
  EXPECT_LT(measure_surface_distance(original, open).rms,
            1.05 * measure_surface_distance(original, plain).rms);
}

// decode --quad-split: shorter (default) and fixed give the same vertices, watertight genus-0 meshes of the
// same size with different diagonals, and the shorter split is closer to the mesh; the models of a consistent
// pack share one face list; a bad value exits 2 with one line and nothing written.
TEST_F(CliPack, QuadSplitShorterIsCloserAndSharedByTheSet) {
  const TriMesh original = read_mesh(spot_);
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 5 --no-normals -o '" + pack + "'").exit_code, 0);
  std::vector<TriMesh> meshes;
  for (const char* split : {"shorter", "fixed"}) {
    const std::string obj = dir_ + "/" + split + ".obj";
    const Outcome d =
        geomip("decode -q --no-untangle '" + pack + "' --quad-split " + split + " -o '" + obj + "'");
    ASSERT_EQ(d.exit_code, 0) << d.err;
    meshes.push_back(read_mesh(obj));
    const TopologyReport t = analyze_topology(meshes.back());
    EXPECT_EQ(t.boundary_edges, 0u) << split;
    EXPECT_TRUE(t.manifold) << split;
    EXPECT_EQ(t.genus, 0) << split;
  }
  EXPECT_EQ(meshes[0].positions, meshes[1].positions);
  EXPECT_EQ(meshes[0].num_triangles(), meshes[1].num_triangles());
  EXPECT_NE(meshes[0].triangles, meshes[1].triangles);
  const double ratio =
      measure_surface_distance(original, meshes[0]).rms / measure_surface_distance(original, meshes[1]).rms;
  RecordProperty("spot_rms_ratio", std::to_string(ratio));
  EXPECT_LT(ratio, 1.0);

  const std::string corr = sphere_pair(), set = dir_ + "/pair.gip";
  ASSERT_EQ(geomip("convert -q --points '" + corr + "' --level 4 --no-normals -o '" + set + "'").exit_code, 0);
  ASSERT_EQ(geomip("decode -q '" + set + "' -o '" + dir_ + "/pair.obj'").exit_code, 0);
  const TriMesh a = read_mesh(dir_ + "/pair.a.obj"), b = read_mesh(dir_ + "/pair.b.obj");
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_NE(a.positions, b.positions);
  ASSERT_EQ(geomip("decode -q '" + set + "' --quad-split fixed -o '" + dir_ + "/pair-fixed.obj'").exit_code, 0);
  EXPECT_NE(read_mesh(dir_ + "/pair-fixed.a.obj").triangles, a.triangles);

  expect_bad_input("decode -q '" + pack + "' --quad-split diagonal -o '" + dir_ + "/bad.obj'", "--quad-split");
  EXPECT_FALSE(fs::exists(dir_ + "/bad.obj"));
}

// A single mesh on two squares gets its patches' L2 stretch in the JSON. From 1.5 up (tools/
// convert_pipeline.h, kStretchedTwoSquares: the horse and the armadillo coded better on more patches, six
// rounder shapes did not) convert moves it, when the layout is left to it, to 16 or 64 patches (one or two
// levels coarser), whichever layout's geometry prefixes measure closer to the mesh, and with --patches 2
// prints a note pointing at --patches and --search instead. The cow's legs stretch its squares (about
// 1.74), the spot's round body does not (about 1.23); another layout has no such figure.
// JSON error weights as --layout-error-weights takes them ("1,0.5,2,0.25,4").
std::string weights_switch(const nlohmann::json& weights) {
  std::string text;
  for (const nlohmann::json& w : weights) {
    std::ostringstream one;
    one << w.get<double>();
    if (!text.empty()) text += ',';  // (not `(empty ? "" : ",") + str`: GCC 12 warns -Wrestrict on it)
    text += one.str();
  }
  return text;
}

TEST_F(CliPack, ConvertMovesAStretchedShapeToItsBetterLayoutUnlessTold) {
  GEOMIP_REQUIRE_SHARED_MESH(cow, "cow.obj");
  const std::string note = "note: the two squares stretch this shape";
  const std::string moved = "layout: the two squares stretch this shape";
  const auto convert_json = [&](const std::string& mesh, const std::string& switches,
                                const std::string& out) {
    const Outcome r =
        geomip("convert --json '" + mesh + "' --level 4 --no-normals " + switches + " -o '" + out + "'");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  // The cow (L2 stretch 1.74 on two squares) is converted on 16 patches at level 3 and 64 at level 2, each
  // with one error weight and with five (kStretchedLayoutErrorWeights); the pack is byte for byte that of
  // asking for the layout kept.
  const nlohmann::json cow_auto = convert_json(cow, "", dir_ + "/cow-auto.gip");
  EXPECT_GE(cow_auto["two_squares_l2_stretch"].get<double>(), 1.5);
  EXPECT_TRUE(cow_auto["moved_to_patches"].get<bool>());
  const nlohmann::json& choice = cow_auto["layout_choice"];
  ASSERT_EQ(choice["layouts"].size(), 4u) << choice;
  const std::vector<std::size_t> sizes = choice["sizes"].get<std::vector<std::size_t>>();
  ASSERT_FALSE(sizes.empty());
  const int chosen = choice["chosen_patches"].get<int>();
  const std::string chosen_weights = weights_switch(choice["chosen_error_weights"]);
  EXPECT_EQ(cow_auto["patches"], chosen);
  std::map<std::string, double> reported_mean, measured_mean;  // by "K W"
  std::map<std::string, std::string> packs;
  std::string kept;
  for (const nlohmann::json& layout : choice["layouts"]) {
    const int k = layout["patches"].get<int>(), level = layout["level"].get<int>();
    const std::string weights = weights_switch(layout["error_weights"]);
    const std::string name = std::to_string(k) + " " + weights;
    EXPECT_EQ(level, k == 16 ? 3 : 2) << layout;
    EXPECT_TRUE(weights == "1" || weights == "1,0.5,2,0.25,4") << layout;
    packs[name] = dir_ + "/cow" + std::to_string(k) + "-" + std::to_string(packs.size()) + ".gip";
    ASSERT_EQ(geomip("convert -q '" + cow + "' --patches " + std::to_string(k) + " --level " +
                     std::to_string(level) + " --layout-error-weights " + weights + " --no-normals -o '" +
                     packs[name] + "'")
                  .exit_code,
              0);
    if (!layout["not_built"].is_null()) {
      // Five weights that choose the one-weight layout are not converted again: the same pack.
      EXPECT_NE(layout["not_built"].get<std::string>().find("the same layout as with error weights 1"),
                std::string::npos)
          << layout;
      EXPECT_EQ(slurp(packs[name]), slurp(packs.at(std::to_string(k) + " 1"))) << name;
      continue;
    }
    reported_mean[name] = layout["mean_psnr_db"].get<double>();
    if (k == chosen && weights == chosen_weights) {
      kept = name;
      EXPECT_EQ(cow_auto["level"], level);
    }
    EXPECT_EQ(slurp(packs[name]).size(), layout["geometry_bytes"].get<std::size_t>());
    // Each layout's prefixes measured independently (decode and eval's default measure, ten times the
    // choice's samples).
    double sum = 0;
    for (std::size_t n : sizes) {
      const std::string obj = dir_ + "/cow-prefix.obj";
      ASSERT_EQ(geomip("decode -q --no-untangle '" + packs[name] + "' --bytes " + std::to_string(n) +
                       " -o '" + obj + "'")
                    .exit_code,
                0);
      const Outcome e = geomip("eval --json '" + cow + "' '" + obj + "'");
      ASSERT_EQ(e.exit_code, 0) << e.err;
      sum += nlohmann::json::parse(e.out)["psnr_db"].get<double>();
    }
    measured_mean[name] = sum / static_cast<double>(sizes.size());
    // The choice measures with a tenth of eval's face samples (geomip eval --samples 100000).
    EXPECT_NEAR(measured_mean[name], reported_mean[name], 0.5) << name;
  }
  ASSERT_FALSE(kept.empty()) << choice;
  ASSERT_GE(reported_mean.size(), 2u) << choice;  // 16 and 64 patches at least
  // The layout kept measured best, by its report and, within the two measures' difference, independently;
  // and better than the worst by either.
  double worst_measured = measured_mean[kept];
  for (const auto& [name, mean] : reported_mean) {
    if (name == kept) continue;
    EXPECT_GT(reported_mean[kept], mean) << name;
    EXPECT_GE(measured_mean[kept], measured_mean[name] - 0.5) << name;
    worst_measured = std::min(worst_measured, measured_mean[name]);
  }
  EXPECT_GT(measured_mean[kept], worst_measured);
  EXPECT_EQ(slurp(dir_ + "/cow-auto.gip"), slurp(packs[kept]));
  // The layouts are built side by side on threads (one per candidate here); one after the other they give
  // the same report and the same bytes.
  const nlohmann::json cow_one_thread = convert_json(cow, "--threads 1", dir_ + "/cow-auto-1.gip");
  EXPECT_EQ(cow_one_thread["layout_choice"]["layouts"], choice["layouts"]);
  EXPECT_EQ(slurp(dir_ + "/cow-auto-1.gip"), slurp(dir_ + "/cow-auto.gip"));
  // With normal maps the layouts are scored on the same geometry-only packs (encoded again from the
  // conversion's images), so the choice is the same, and the pack is that of asking for the layout.
  const Outcome with_normals = geomip("convert --json '" + cow + "' --level 4 -o '" + dir_ + "/cow-n.gip'");
  ASSERT_EQ(with_normals.exit_code, 0) << with_normals.err;
  const nlohmann::json jn = nlohmann::json::parse(with_normals.out);
  EXPECT_TRUE(jn["normals"].get<bool>());
  EXPECT_EQ(jn["layout_choice"]["layouts"], choice["layouts"]);
  ASSERT_EQ(geomip("convert -q '" + cow + "' --patches " + std::to_string(chosen) +
                   " --layout-error-weights " + chosen_weights + " --level " +
                   std::to_string(cow_auto["level"].get<int>()) + " -o '" + dir_ + "/cow-n-named.gip'")
                .exit_code,
            0);
  EXPECT_EQ(slurp(dir_ + "/cow-n.gip"), slurp(dir_ + "/cow-n-named.gip"));
  // --patches 2 keeps the two squares (and the note says more patches may code it better).
  const nlohmann::json cow_two = convert_json(cow, "--patches 2", dir_ + "/cow2.gip");
  EXPECT_EQ(cow_two["patches"], 2);
  EXPECT_EQ(cow_two["level"], 4);
  EXPECT_FALSE(cow_two["moved_to_patches"].get<bool>());
  // Spot (1.23) stays on two squares.
  const nlohmann::json spot = convert_json(spot_, "", dir_ + "/spot.gip");
  EXPECT_GT(spot["two_squares_l2_stretch"].get<double>(), 1.0);
  EXPECT_LT(spot["two_squares_l2_stretch"].get<double>(), 1.5);
  EXPECT_EQ(spot["patches"], 2);
  EXPECT_FALSE(spot["moved_to_patches"].get<bool>());
  EXPECT_TRUE(spot["layout_choice"].is_null());
  EXPECT_TRUE(convert_json(spot_, "--patches 6", dir_ + "/spot6.gip")["two_squares_l2_stretch"].is_null());
  // What the report says.
  Outcome r = geomip("convert '" + cow + "' --level 4 --no-normals -o '" + dir_ + "/cow.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(moved), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("layout: " + std::to_string(chosen) + " patches (error weights " + chosen_weights +
                       ") at level "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(", kept"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(note), std::string::npos) << r.out;
  r = geomip("convert '" + cow + "' --patches 2 --level 4 --no-normals -o '" + dir_ + "/cow.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(note), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(moved), std::string::npos) << r.out;
  r = geomip("convert '" + spot_ + "' --level 4 --no-normals -o '" + dir_ + "/spot.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find(note), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(moved), std::string::npos) << r.out;
  r = geomip("convert --quiet '" + cow + "' --level 4 --no-normals -o '" + dir_ + "/cow.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// A long box (10 × 1 × 1) of `segments` square rings: two squares stretch it, so convert tries 16 and 64
// patches. With 2 segments (12 vertices) neither layout fits: the two squares are kept (exit 0; the report
// says why), as before the move existed. With 20, convert and rd --level 3 both move it (16 patches at level
// 2 or 64 at level 1) and agree byte for byte.
TEST_F(CliPack, AStretchedShapeThatCannotMoveKeepsItsTwoSquares) {
  const auto box = [&](int segments) {
    std::ostringstream obj;
    for (int i = 0; i <= segments; ++i) {
      const double x = 10.0 * i / segments;
      obj << "v " << x << " 0 0\nv " << x << " 1 0\nv " << x << " 1 1\nv " << x << " 0 1\n";
    }
    for (int i = 0; i < segments; ++i) {
      for (int k = 0; k < 4; ++k) {
        const int a = 4 * i + k + 1, b = 4 * i + (k + 1) % 4 + 1, c = a + 4, d = b + 4;
        obj << "f " << a << " " << d << " " << c << "\nf " << a << " " << b << " " << d << "\n";
      }
    }
    const int last = 4 * segments;
    obj << "f 1 3 2\nf 1 4 3\n";
    obj << "f " << last + 1 << " " << last + 2 << " " << last + 3 << "\nf " << last + 1 << " " << last + 3
        << " " << last + 4 << "\n";
    return file("box" + std::to_string(segments) + ".obj", obj.str());
  };
  const std::string small = box(2);
  Outcome r = geomip("convert --json '" + small + "' --level 4 --no-normals -o '" + dir_ + "/small.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GE(j["two_squares_l2_stretch"].get<double>(), 1.5);
  EXPECT_EQ(j["patches"], 2);
  EXPECT_FALSE(j["moved_to_patches"].get<bool>());
  ASSERT_EQ(
      geomip("convert -q '" + small + "' --patches 2 --level 4 --no-normals -o '" + dir_ + "/small2.gip'")
          .exit_code,
      0);
  EXPECT_EQ(slurp(dir_ + "/small.gip"), slurp(dir_ + "/small2.gip"));
  // The report says why neither layout was built and keeps its note's advice (more patches) to itself.
  EXPECT_EQ(j["layout_choice"]["chosen_patches"], 0);
  for (const nlohmann::json& layout : j["layout_choice"]["layouts"])
    EXPECT_NE(layout["not_built"].get<std::string>().find("corners"), std::string::npos) << layout;
  r = geomip("convert '" + small + "' --level 4 --no-normals -o '" + dir_ + "/small.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"16 patches (error weights 1)", "16 patches (error weights 1,0.5,2,0.25,4)",
                           "64 patches (error weights 1)", "64 patches (error weights 1,0.5,2,0.25,4)"})
    EXPECT_NE(r.out.find(std::string("layout: ") + name + ": not built"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("layout: keeping the two squares"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("note: the two squares stretch this shape"), std::string::npos) << r.out;
  // At --level 2 the 64 patches' level would be 0: said so, and the one layout left is kept unmeasured.
  r = geomip("convert --json '" + box(20) + "' --level 2 --no-normals -o '" + dir_ + "/l2.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["layout_choice"]["chosen_patches"], 16) << j["layout_choice"];
  EXPECT_TRUE(j["layout_choice"]["sizes"].empty());
  for (const std::size_t i : {2, 3}) {  // 64 patches, with one error weight and with five
    EXPECT_EQ(j["layout_choice"]["layouts"][i]["patches"], 64);
    EXPECT_NE(j["layout_choice"]["layouts"][i]["not_built"].get<std::string>().find("below 1"),
              std::string::npos);
  }

  const std::string long_box = box(20);
  r = geomip("convert --json '" + long_box + "' --level 3 --no-normals -o '" + dir_ + "/long.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j["moved_to_patches"].get<bool>());
  EXPECT_EQ(j["level"], j["patches"] == 16 ? 2 : 1) << j["layout_choice"];
  r = geomip("rd -q --quick --level 3 '" + long_box + "' -o '" + dir_ + "/rd'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(dir_ + "/rd/box20.gip"), slurp(dir_ + "/long.gip"));
}

// --patches K: a K-quad layout through remesh, convert and decode (the codec and the decoder take any patch
// count): watertight, genus 0, K·2·4^L faces, V = K·4^L + 2; convert's level without --level; bad K exit 2
// with one line and nothing written.
TEST_F(CliPack, KPatchLayoutThroughRemeshConvertAndDecode) {
  const std::string out = dir_ + "/k6";
  Outcome r = geomip("remesh --quiet '" + spot_ + "' --patches 6 --level 3 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const TriMesh m = read_mesh(out + "/spot.M3.obj");
  EXPECT_EQ(m.triangles.size(), 6u * 2 * 64);
  EXPECT_EQ(m.positions.size(), 6u * 64 + 2);
  TopologyReport t = analyze_topology(m);
  EXPECT_EQ(t.boundary_loops, 0u);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.genus, 0);
  r = geomip("param --quiet '" + spot_ + "' --patches 6 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto param = nlohmann::json::parse(slurp(out + "/spot.param.json"));
  EXPECT_EQ(param["patches"].size(), 6u);
  EXPECT_EQ(param["layout_quads"].size(), 6u);
  EXPECT_EQ(param["flipped_triangles"], 0);
  const std::string pack = dir_ + "/spot6.gip";
  r = geomip("convert --quiet '" + spot_ + "' --patches 6 --level 4 --no-normals -o '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = geomip("decode --json '" + pack + "' -o '" + dir_ + "/spot6.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["models"][0]["faces"], 6 * 2 * 16 * 16);
  t = analyze_topology(read_mesh(dir_ + "/spot6.obj"));
  EXPECT_EQ(t.boundary_loops, 0u);
  EXPECT_EQ(t.genus, 0);
  // Without --level a K-patch layout gets the coarsest level whose K grids hold at least as many samples as
  // two squares at level 8: 32 patches, level 6 (32·65² = 135,200 against 2·257² = 132,098; level 5 would
  // hold 34,848), not level 8's 16 times as many.
  const std::string pack32 = dir_ + "/spot32.gip";
  r = geomip("convert --json '" + spot_ + "' --patches 32 --no-normals -o '" + pack32 + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["level"], 6);
  r = geomip("decode --json '" + pack32 + "' -o '" + dir_ + "/spot32.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["models"][0]["faces"], 32 * 2 * 64 * 64);
  // 32 patches are simplified by equal error, --equal-area-layout by equal area: two different layouts,
  // both without flipped triangles.
  std::vector<std::set<int>> corner_sets;
  for (const std::string flag : {"", " --equal-area-layout"}) {
    const std::string dir = out + (flag.empty() ? "/error" : "/area");
    r = geomip("param --quiet '" + spot_ + "' --patches 32" + flag + " -o '" + dir + "'");
    ASSERT_EQ(r.exit_code, 0) << flag << "\n" << r.err;
    const auto p = nlohmann::json::parse(slurp(dir + "/spot.param.json"));
    EXPECT_EQ(p["patches"].size(), 32u) << flag;
    EXPECT_EQ(p["flipped_triangles"], 0) << flag;
    std::set<int> corners;
    for (const auto& patch : p["patches"])
      for (const auto& c : patch["corners"]) corners.insert(c["vertex"].get<int>());
    corner_sets.push_back(corners);
  }
  EXPECT_NE(corner_sets[0], corner_sets[1]);
  const std::string bad = dir_ + "/bad";
  for (const std::string& args :
       {"remesh '" + spot_ + "' --patches 1 --level 2 -o '" + bad + "'",
        "remesh '" + spot_ + "' --patches 4000 --level 2 -o '" + bad + "'",
        "convert '" + spot_ + "' --patches 4000 -o '" + dir_ + "/x.gip'",
        // --layout-error-weights: each finite and > 0, 1 to 8 of them, not with
        // --search (which chooses the layout itself)
        "convert '" + spot_ + "' --patches 16 --layout-error-weights 1,-1 -o '" + dir_ + "/x.gip'",
        "convert '" + spot_ + "' --patches 16 --layout-error-weights nan -o '" + dir_ + "/x.gip'",
        "remesh '" + spot_ + "' --patches 16 --layout-error-weights 0 -o '" + bad + "'",
        "convert '" + spot_ + "' --patches 16 --layout-error-weights 1,2,3,4,5,6,7,8,9 -o '" + dir_ +
            "/x.gip'",
        "convert '" + spot_ + "' --search --layout-error-weights 1,2 -o '" + dir_ + "/x.gip'",
        "rd '" + spot_ + "' --search --layout-error-weights 1,2 -o '" + bad + "'"}) {
    r = geomip(args);
    EXPECT_FALSE(r.crashed) << args;
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    if (args.find("--layout-error-weights") != std::string::npos) {
      EXPECT_NE(r.err.find("--layout-error-weights"), std::string::npos) << args << "\n" << r.err;
    }
  }
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_FALSE(fs::exists(dir_ + "/x.gip"));
}

// Genus 2 (test::double_torus(): two tori joined by a tube) has no two-square layout: without --patches, remesh
// and convert choose a K-quad layout themselves (and say so); remesh, the decoded pack and a prefix of it are
// watertight with genus 2. --patches too small for the genus exits 2 with one line.
TEST_F(CliPack, GenusTwoThroughRemeshConvertAndDecode) {
  const std::string mesh = dir_ + "/double_torus.obj";
  {
    std::ofstream out(mesh);
    write_mesh(test::double_torus(), out, MeshFormat::kObj);
  }
  ASSERT_EQ(analyze_topology(read_mesh(mesh)).genus, 2);
  const std::string out = dir_ + "/g2";
  Outcome r = geomip("remesh '" + mesh + "' --level 3 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("genus 2: automatic layout of "), std::string::npos) << r.err;
  TopologyReport t = analyze_topology(read_mesh(out + "/double_torus.M3.obj"));
  EXPECT_EQ(t.boundary_loops, 0u);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.genus, 2);
  const std::string pack = dir_ + "/g2.gip";
  r = geomip("convert --quiet '" + mesh + "' --level 4 --no-normals -o '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const std::string& bytes : {std::string(), " --bytes " + std::to_string(fs::file_size(pack) / 4)}) {
    r = geomip("decode --quiet '" + pack + "'" + bytes + " -o '" + dir_ + "/g2.obj'");
    ASSERT_EQ(r.exit_code, 0) << bytes << "\n" << r.err;
    t = analyze_topology(read_mesh(dir_ + "/g2.obj"));
    EXPECT_EQ(t.boundary_loops, 0u) << bytes;
    EXPECT_TRUE(t.manifold) << bytes;
    EXPECT_EQ(t.genus, 2) << bytes;
  }
  r = geomip("remesh '" + mesh + "' --patches 4 --level 2 -o '" + dir_ + "/bad'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/bad"));
}

// `geomip info PACK`: the chunk table as a reader receives it (cumulative sizes end at the file's size, in
// file order), the first level's byte count is one `decode --bytes` accepts, and a non-pack is refused.
TEST_F(CliPack, InfoDescribesAPack) {
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 4 -o '" + pack + "'").exit_code, 0);
  const Outcome r = geomip("info --json '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["bytes"], fs::file_size(pack));
  ASSERT_EQ(j["models"].size(), 1u);
  EXPECT_EQ(j["models"][0]["level"], 4);
  EXPECT_EQ(j["models"][0]["patches"], 2);
  EXPECT_EQ(j["models"][0]["normals"], true);
  std::uint64_t previous = j["manifest_bytes"];
  int geometry_chunks = 0;
  for (const auto& c : j["chunks"]) {
    EXPECT_EQ(c["cumulative"].get<std::uint64_t>(), previous + c["bytes"].get<std::uint64_t>());
    previous = c["cumulative"];
    geometry_chunks += c["kind"] == "geometry";
  }
  EXPECT_EQ(previous, fs::file_size(pack));
  // One chunk per geometry pass (with headroom the passes end above weighted plane 0).
  EXPECT_EQ(j["models"][0]["geometry_passes"].get<int>(), geometry_chunks);
  const std::uint64_t first = j["first_level_bytes"];
  EXPECT_LT(first, fs::file_size(pack));
  EXPECT_EQ(geomip("decode -q '" + pack + "' --bytes " + std::to_string(first) + " -o '" + dir_ + "/first.obj'").exit_code, 0);
  EXPECT_EQ(geomip("decode -q '" + pack + "' --bytes " + std::to_string(first - 1) + " -o '" + dir_ + "/none.obj'").exit_code, 2);
  const Outcome text = geomip("info '" + pack + "'");
  EXPECT_NE(text.out.find("first level of detail after " + std::to_string(first) + " bytes"), std::string::npos) << text.out;
  expect_bad_input("info '" + file("junk.gip", "not a pack") + "'", "junk.gip");
}

// A pack of models whose grids have different levels (`encode` of two geometry-image sets): each model is
// decoded at its own level, and --level above a model's level is refused naming that model (it took the first
// model's level for all of them, so the second was reported at the wrong level or refused by an internal
// check).
TEST_F(CliPack, DecodeGivesEachModelOfAMixedLevelPackItsOwnLevel) {
  ASSERT_EQ(geomip("gimage -q '" + spot_ + "' --level 3 -o '" + dir_ + "/g3'").exit_code, 0);
  ASSERT_EQ(geomip("gimage -q '" + spot_ + "' --level 4 -o '" + dir_ + "/g4'").exit_code, 0);
  const std::string pack = dir_ + "/mixed.gip";
  ASSERT_EQ(geomip("encode -q --no-normals '" + dir_ + "/g4' '" + dir_ + "/g3' -o '" + pack + "'").exit_code,
            0);
  Outcome r = geomip("decode --json '" + pack + "' -o '" + dir_ + "/d.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["models"].size(), 2u);
  // spot's patches: (2^N)² quads of two triangles each, whatever their count.
  const std::size_t faces4 = j["models"][0]["faces"], faces3 = j["models"][1]["faces"];
  EXPECT_EQ(faces4, 4 * faces3);
  r = geomip("decode '" + pack + "' -o '" + dir_ + "/e.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(level 4,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(level 3,"), std::string::npos) << r.out;
  r = geomip("decode '" + pack + "' --level 4 -o '" + dir_ + "/f.obj'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("level 3"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("decoded_mesh"), std::string::npos) << r.err;
  EXPECT_EQ(geomip("decode -q '" + pack + "' --level 3 -o '" + dir_ + "/g.obj'").exit_code, 0);
}

TEST_F(CliPack, EncodeFromGimageDirectory) {
  ASSERT_EQ(geomip("gimage -q '" + spot_ + "' --level 4 -o '" + dir_ + "/gi'").exit_code, 0);
  const Outcome r = geomip("encode --json '" + dir_ + "/gi' -o '" + dir_ + "/x.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["normals"], true);
  const Outcome d = geomip("decode -q '" + dir_ + "/x.gip' -o '" + dir_ + "/x.obj'");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_EQ(read_mesh(dir_ + "/x.obj").triangles.size(), 2u * 2 * 16 * 16);
  // --normal-bits as in convert: a coarser normal quantization, a smaller pack; out of range exits 2.
  ASSERT_EQ(geomip("encode -q '" + dir_ + "/gi' --normal-bits 7 -o '" + dir_ + "/x7.gip'").exit_code, 0);
  EXPECT_LT(fs::file_size(dir_ + "/x7.gip"), fs::file_size(dir_ + "/x.gip") * 9 / 10);
  expect_bad_input("encode -q '" + dir_ + "/gi' --normal-bits 20 -o '" + dir_ + "/bad.gip'", "--normal-bits");
  expect_bad_input("encode -q '" + dir_ + "/gi' --normal-bits 8 --no-normals -o '" + dir_ + "/bad.gip'",
                   "--normal-bits");
  EXPECT_FALSE(fs::exists(dir_ + "/bad.gip"));
}

// Model names come from files (a mesh's stem, a pack's manifest) and become file names on decode: two models
// of the same name get two files, and a crafted name (a path, control bytes) neither leads outside the output
// directory nor reaches the terminal raw.
TEST_F(CliPack, ModelNamesBecomeSafeDistinctFileNames) {
  const std::string long_name = "spot_with_a_long_name";  // 21 bytes, as the crafted names below
  fs::copy_file(spot_, dir_ + "/" + long_name + ".obj");
  ASSERT_EQ(geomip("gimage -q '" + dir_ + "/" + long_name + ".obj' --level 3 -o '" + dir_ + "/gi'").exit_code,
            0);
  const std::string pack = dir_ + "/two.gip";
  ASSERT_EQ(geomip("encode -q --no-normals '" + dir_ + "/gi' '" + dir_ + "/gi' -o '" + pack + "'").exit_code,
            0);
  fs::create_directories(dir_ + "/o/s/x.a");
  Outcome r = geomip("decode '" + pack + "' -o '" + dir_ + "/o/s/x.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ + "/o/s/x." + long_name + ".obj"));
  EXPECT_TRUE(fs::exists(dir_ + "/o/s/x." + long_name + "-1.obj")) << r.out;

  // The same pack with its names replaced in the manifest (same lengths) and the manifest's CRC made anew.
  std::string bytes = slurp(pack);
  const std::size_t first = bytes.find(long_name), second = bytes.find(long_name, first + 1);
  ASSERT_NE(second, std::string::npos);
  bytes.replace(first, 21, "a/../../../escaped_xx");
  bytes.replace(second, 21, "\x1b[31mred\x07____________");  // ESC [31m red BEL, 12 underscores
  bytes = with_manifest_crc(bytes);
  const std::string crafted = file("crafted.gip", bytes);
  fs::remove_all(dir_ + "/o");
  fs::create_directories(dir_ + "/o/s/x.a");
  r = geomip("decode '" + crafted + "' -o '" + dir_ + "/o/s/x.a/../x.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/escaped_xx.obj"));
  std::set<std::string> written;
  for (const auto& e : fs::recursive_directory_iterator(dir_ + "/o"))
    if (e.is_regular_file()) written.insert(fs::relative(e.path(), dir_ + "/o").string());
  EXPECT_EQ(written,
            (std::set<std::string>{"s/x.a_.._.._.._escaped_xx.obj", "s/x._[31mred_____________-1.obj"}));
  for (const std::string& text : {r.out, geomip("info '" + crafted + "'").out})
    EXPECT_EQ(text.find_first_of("\x1b\x07"), std::string::npos) << text;
  // info --json stays valid JSON with the names as they are (escaped).
  r = geomip("info --json '" + crafted + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["models"][0]["name"], "a/../../../escaped_xx");
}

// A pack whose grids are finer than any mesh decode makes (level 11: the format's bound is one above
// meshes') is refused from its manifest with one line (it decoded 400 MB of grids to fail in the remesher).
TEST_F(CliPack, DecodeRefusesALevelAboveMeshesFromTheManifest) {
  const std::string pack = dir_ + "/s.gip";
  ASSERT_EQ(
      geomip("convert -q '" + spot_ + "' --level 3 --no-normals --patches 2 -o '" + pack + "'").exit_code, 0);
  std::string bytes = slurp(pack);
  // Manifest: name (varint length, bytes), normalization form (identity: 1 byte), the codec header as format
  // 4 on stores it (varint offset, varint size, then serialize(): version byte, level varint, ...).
  const std::size_t name = bytes.find("spot");
  ASSERT_NE(name, std::string::npos);
  const std::size_t level_at = name + 4 + 1 + 1 + 1 + 1;
  ASSERT_EQ(static_cast<int>(bytes[level_at]), 3) << "the manifest layout changed";
  bytes[level_at] = 11;
  bytes = with_manifest_crc(bytes);
  const std::string crafted = file("l11.gip", bytes);
  const Outcome info = geomip("info --json '" + crafted + "'");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  ASSERT_EQ(nlohmann::json::parse(info.out)["models"][0]["level"], 11) << info.out;
  expect_bad_input("decode '" + crafted + "' --level 0 -o '" + dir_ + "/l11.obj'", "up to level 10");
  EXPECT_FALSE(fs::exists(dir_ + "/l11.obj"));
}

// Outputs that would destroy an input, or that cannot be written at all, are refused before any work (exit
// 2).
TEST_F(CliPack, OutputsOverInputsAndDirectoriesExitTwoBeforeAnyWork) {
  ASSERT_EQ(geomip("gimage -q '" + spot_ + "' --level 3 -o '" + dir_ + "/gi'").exit_code, 0);
  const std::string exr = dir_ + "/gi/spot.geometry.exr";
  const auto exr_bytes = slurp(exr);
  expect_bad_input("encode -q '" + dir_ + "/gi' -o '" + exr + "'", exr);
  EXPECT_EQ(slurp(exr), exr_bytes);
  fs::create_directories(dir_ + "/adir.gip");
  expect_bad_input("convert -q '" + spot_ + "' --level 3 -o '" + dir_ + "/adir.gip'", dir_ + "/adir.gip");
  // A directory that takes no files although its permissions say so (/proc for root): found before the
  // work, not when the temporary file could not be created at the end (exit 1).
  if (fs::is_directory("/proc"))
    expect_bad_input("convert -q '" + spot_ + "' --level 3 -o /proc/geomip-test.gip",
                     "/proc/geomip-test.gip");
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("encode -q '" + dir_ + "/gi' -o '" + pack + "'").exit_code, 0);
  expect_bad_input("decode -q '" + pack + "' -o '" + pack + "/x.obj'",
                   pack);  // a file where a directory goes
  ASSERT_EQ(geomip("decode -q '" + pack + "' -o '" + dir_ + "/m.ply'").exit_code, 0);
  const auto ply = slurp(dir_ + "/m.ply");
  expect_bad_input("eval '" + spot_ + "' '" + dir_ + "/m.ply' --error-map '" + dir_ + "/m.ply'",
                   dir_ + "/m.ply");
  EXPECT_EQ(slurp(dir_ + "/m.ply"), ply);
  // Bad geometry images: garbage, truncated, an EXR that is no geometry image: exit 2, one line naming it.
  const std::string cut = file("cut.geometry.exr", exr_bytes.substr(0, exr_bytes.size() / 2));
  const std::string junk = file("junk.geometry.exr", std::string(500, 'x'));
  expect_bad_input("encode -q '" + cut + "' -o '" + dir_ + "/b.gip'", cut);
  expect_bad_input("encode -q '" + junk + "' -o '" + dir_ + "/b.gip'", junk);
  EXPECT_FALSE(fs::exists(dir_ + "/b.gip"));
}

// An output that is a device or a pipe is written through, not replaced: `-o /dev/full` renamed a temporary
// file over the device node (as root), reported success and left /dev/full a regular file. Now the write
// fails (exit 1, one line) and the device stays; /dev/null takes the pack; a named pipe gets the bytes.
TEST_F(CliPack, OutputsThatAreDevicesOrPipesAreWrittenThroughNotReplaced) {
  if (!fs::is_character_file("/dev/full") || !fs::is_character_file("/dev/null"))
    GTEST_SKIP() << "no /dev/full or /dev/null";
  Outcome r = geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o /dev/full");
  EXPECT_FALSE(r.crashed);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("/dev/full"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  // A mesh writer that checks its own stream names the file and the reason too (it said "write_mesh: writing
  // the obj stream failed").
  fs::create_symlink("/dev/full", dir_ + "/full.obj");
  r = geomip("repair -q '" + spot_ + "' -o '" + dir_ + "/full.obj'");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("full.obj: write failed (No space left on device)"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir_ + "/full.obj"));
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o /dev/null");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  const std::string fifo = dir_ + "/pipe.gip";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string copy = dir_ + "/from-pipe.gip", done = dir_ + "/pipe-done";
  ASSERT_EQ(std::system(("(cat '" + fifo + "' > '" + copy + "'; touch '" + done + "') &").c_str()), 0);
  r = geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o '" + fifo + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_fifo(fifo));
  for (int i = 0; i < 600 && !fs::exists(done); ++i) ::usleep(100000);  // cat ends when the writer closes
  ASSERT_TRUE(fs::exists(done));
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o '" + dir_ + "/plain.gip'").exit_code,
            0);
  EXPECT_EQ(slurp(copy), slurp(dir_ + "/plain.gip"));
}

// Issue #13: `decode --bytes N` before the first level of detail used to write a 262,144-face mesh of zero
// extent (exit 0), and a file cut inside its manifest was reported as "477418 of 0 bytes".
TEST_F(CliPack, PrefixesWithoutALevelOfDetailExitTwoWithoutOutput) {
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 4 -o '" + pack + "'").exit_code, 0);
  const std::string bytes = slurp(pack);
  // Where the chunks start (header + manifest), as `geomip info` reports it.
  const Outcome info = geomip("info --json '" + pack + "'");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const std::size_t manifest_end = nlohmann::json::parse(info.out)["manifest_bytes"];
  ASSERT_GT(manifest_end, 20u);
  const std::string out = dir_ + "/out.obj";

  const std::string just_manifest = std::to_string(manifest_end + 1);
  expect_bad_input("decode '" + pack + "' --bytes " + just_manifest + " -o '" + out + "'", pack);
  Outcome r = geomip("decode '" + pack + "' --bytes " + just_manifest + " -o '" + out + "'");
  const std::string needs = "bytes hold no level of detail; the first level needs ";
  const std::size_t at = r.err.find(needs);
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the first " + just_manifest + " bytes"), std::string::npos) << r.err;
  const std::size_t level_one_size = std::stoul(r.err.substr(at + needs.size()));  // bytes, not a time
  EXPECT_GT(level_one_size, manifest_end + 1);
  EXPECT_LT(level_one_size, bytes.size());
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(
      geomip("decode -q '" + pack + "' --bytes " + std::to_string(level_one_size - 1) + " -o '" + out + "'")
          .exit_code,
      2);
  EXPECT_FALSE(fs::exists(out));
  // From there on, a coarse model with an extent.
  r = geomip("decode -q '" + pack + "' --bytes " + std::to_string(level_one_size) + " -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(analyze_topology(read_mesh(out)).bbox_diagonal, 0.1);

  // Cut inside the manifest: the real byte counts, not "N of 0 bytes".
  const std::string cut = file("cut.gip", bytes.substr(0, manifest_end - 5));
  expect_bad_input("decode '" + cut + "' -o '" + dir_ + "/cut.obj'", cut);
  r = geomip("decode '" + cut + "' -o '" + dir_ + "/cut.obj'");
  EXPECT_NE(r.err.find("the file has " + std::to_string(manifest_end - 5) +
                       " bytes, the manifest alone needs " + std::to_string(manifest_end)),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(" of 0 bytes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/cut.obj"));
  // A prefix asked of the whole file that ends inside the manifest names the prefix that decodes.
  r = geomip("decode '" + pack + "' --bytes 20 -o '" + dir_ + "/short.obj'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the first level of detail needs " + std::to_string(level_one_size)),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ + "/short.obj"));
}

// Small conveniences: --level 1 and 2 work with the default framed steps (capped at the level), --tip-loop on
// a shape without tips says that it fell back to the plain loop, morph of a one-model pack says it needs
// two, rd -q prints nothing and still writes its files.
TEST_F(CliPack, DefaultsFitLowLevelsAndFallbacksAreSaid) {
  for (const char* level : {"1", "2"}) {
    Outcome r = geomip("convert -q '" + spot_ + "' --level " + level + " -o '" + dir_ + "/low.gip'");
    EXPECT_EQ(r.exit_code, 0) << level << ": " << r.err;
  }
  expect_bad_input("convert -q '" + spot_ + "' --level 2 --frame-steps 3 -o '" + dir_ + "/low.gip'",
                   "--frame-steps 3");
  Outcome r = geomip("convert '" + spot_ + "' --tip-loop --level 3 --no-normals -o '" + dir_ + "/t.gip'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const bool tips = r.err.find("found no protrusion tips") == std::string::npos;
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o '" + dir_ + "/p.gip'").exit_code, 0);
  // Said exactly when the pack is the plain loop's.
  EXPECT_EQ(tips, slurp(dir_ + "/t.gip") != slurp(dir_ + "/p.gip")) << r.err;
  expect_bad_input("morph '" + dir_ + "/p.gip' -o '" + dir_ + "/m'", "holds one model");
  EXPECT_FALSE(fs::exists(dir_ + "/m"));
  // Told from the manifest, before any grid is decoded: a damaged chunk of a one-model pack says the same.
  {
    std::string bytes = slurp(dir_ + "/p.gip");
    bytes.back() = static_cast<char>(bytes.back() ^ 0x5A);  // the last CRC trailer
    std::ofstream(dir_ + "/damaged.gip", std::ios::binary) << bytes;
    expect_bad_input("morph '" + dir_ + "/damaged.gip' -o '" + dir_ + "/m'", "holds one model");
  }
  r = geomip("rd -q --quick '" + spot_ + "' -o '" + dir_ + "/rd'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_TRUE(fs::exists(dir_ + "/rd/rd.csv"));
}

// convert --up: the viewer's frame goes into each model's normalization only (decoded meshes keep the mesh's
// units: the same OBJ, byte for byte, with and without a frame); --up none and --no-normals store none; a bad
// axis exits 2 with one line and writes nothing.
TEST_F(CliPack, ConvertUpStoresAFrameAndLeavesDecodedMeshesAlone) {
  const std::string framed = dir_ + "/framed.gip", plain = dir_ + "/plain.gip", bare = dir_ + "/bare.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --up z -o '" + framed + "'").exit_code, 0);
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --up none -o '" + plain + "'").exit_code, 0);
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --no-normals -o '" + bare + "'").exit_code, 0);
  const auto normalization = [&](const std::string& path) {
    const std::string bytes = slurp(path);
    codec::PackInfo info;
    EXPECT_EQ(
        codec::read_pack_info({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, info),
        codec::Status::kOk);
    return info.models.empty() ? std::array<double, 16>{} : info.models[0].normalization;
  };
  const std::array<double, 16> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_EQ(normalization(plain), identity);
  EXPECT_EQ(normalization(bare), identity) << "geometry-only (R-D) packs carry no frame by default";
  const auto n = normalization(framed);
  // Row 1 (the viewer's +y) is the model's +z, scaled to the unit box.
  EXPECT_EQ(n[4], 0);
  EXPECT_EQ(n[5], 0);
  EXPECT_GT(n[6], 0);
  EXPECT_EQ(n[15], 1);
  ASSERT_EQ(geomip("decode -q '" + framed + "' -o '" + dir_ + "/framed.obj'").exit_code, 0);
  ASSERT_EQ(geomip("decode -q '" + plain + "' -o '" + dir_ + "/plain.obj'").exit_code, 0);
  EXPECT_EQ(slurp(dir_ + "/framed.obj"), slurp(dir_ + "/plain.obj"));
  // glTF: the same positions, and the frame as the node's rotation (glTF's +Y up): a viewer stands it up.
  const auto glb_json = [&](const std::string& pack) {
    const std::string glb = dir_ + "/x.glb";
    EXPECT_EQ(geomip("decode -q '" + pack + "' -o '" + glb + "'").exit_code, 0);
    const std::string bytes = slurp(glb);
    std::uint32_t json_bytes = 0;
    std::memcpy(&json_bytes, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.substr(20, json_bytes));
  };
  const auto framed_glb = glb_json(framed), plain_glb = glb_json(plain);
  EXPECT_FALSE(plain_glb["nodes"][0].contains("matrix"));
  ASSERT_TRUE(framed_glb["nodes"][0].contains("matrix"));
  const auto m = framed_glb["nodes"][0]["matrix"].get<std::vector<double>>();  // column-major
  const double scale = std::hypot(n[0], n[1], n[2]);
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) EXPECT_NEAR(m[4 * col + row], n[4 * row + col] / scale, 1e-12);
  EXPECT_EQ(framed_glb["accessors"], plain_glb["accessors"]) << "positions as decoded, bounds included";
  const std::string bad = dir_ + "/bad.gip";
  const Outcome r = geomip("convert -q '" + spot_ + "' --level 3 --up w -o '" + bad + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--up"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(bad));
}

// convert --up auto on an open mesh: the frame is guessed from the mesh as read, not from the repaired one.
// The camel head is cut open at the neck (at −y, its crown towards +y); repair fills the cut with a faired
// dome, which looked like a crown to ground_direction() and turned the head upside down.
TEST_F(CliPack, ConvertUpAutoStandsTheOpenCamelHeadOnItsNeckCut) {
  GEOMIP_REQUIRE_SHARED_MESH(camel, "camelhead.obj");
  const std::string pack = dir_ + "/camel.gip";
  ASSERT_EQ(geomip("convert -q '" + camel + "' --level 3 -o '" + pack + "'").exit_code, 0);
  const std::array<double, 16> n = sole_normalization(pack);
  // Row 1 (the viewer's +y) is the model's +y, scaled to the unit box.
  EXPECT_EQ(n[4], 0);
  EXPECT_GT(n[5], 0);
  EXPECT_EQ(n[6], 0);
}

// convert --front: the named model axis becomes the viewer's +x (row 0 of the normalization); an axis along
// up, or a front without a frame (--up none), exits 2 with one line and writes nothing.
TEST_F(CliPack, ConvertFrontNamesTheViewersFront) {
  const std::string faced = dir_ + "/faced.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 --up y --front -x -o '" + faced + "'").exit_code, 0);
  const std::array<double, 16> n = sole_normalization(faced);
  EXPECT_LT(n[0], 0) << "row 0 (the viewer's +x) is the model's -x";
  EXPECT_EQ(n[1], 0);
  EXPECT_EQ(n[2], 0);
  EXPECT_GT(n[5], 0) << "row 1 (the viewer's +y) is the model's +y";
  for (const char* args : {"--up y --front +y", "--up none --front +x", "--front +q"}) {
    const std::string bad = dir_ + "/bad_front.gip";
    const Outcome r = geomip("convert -q '" + spot_ + "' --level 3 " + args + " -o '" + bad + "'");
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find("--front"), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(bad)) << args;
  }
}

// `geomip info PACK` prints the viewer's frame stored in each model's normalization: the model axes shown as
// up (+y), front (+x, what --front names) and camera side (+z), or "none" when no frame is stored.
TEST_F(CliPack, InfoPrintsTheStoredViewFrame) {
  struct Case {
    const char* args;
    const char* up;
    const char* front;
    const char* camera_side;
  };
  // Spot stands on −y, its head at −z (mesh/view_frame.h; docs/streaming.md "Upright and front").
  const Case cases[] = {{"", "+y", "-z", "+x"},
                        {"--up y --front -x", "+y", "-x", "-z"},
                        {"--up x --front +y", "+x", "+y", "-z"},
                        {"--up none", "none", "none", "none"}};
  for (const Case& c : cases) {
    const std::string pack = dir_ + "/framed.gip";
    ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 3 " + c.args + " -o '" + pack + "'").exit_code, 0)
        << c.args;
    const Outcome json = geomip("info --json '" + pack + "'");
    ASSERT_EQ(json.exit_code, 0) << json.err;
    const auto model = nlohmann::json::parse(json.out)["models"][0];
    EXPECT_EQ(model["up"], c.up) << c.args;
    EXPECT_EQ(model["front"], c.front) << c.args;
    EXPECT_EQ(model["camera_side"], c.camera_side) << c.args;
    const Outcome text = geomip("info '" + pack + "'");
    ASSERT_EQ(text.exit_code, 0) << text.err;
    const std::string frame = std::string(c.up) == "none" ? "; frame none\n"
                                                          : std::string("; up ") + c.up + ", front " + c.front +
                                                                ", camera side " + c.camera_side + "\n";
    EXPECT_NE(text.out.find("model 0 'spot': "), std::string::npos) << text.out;
    EXPECT_NE(text.out.find(frame), std::string::npos) << c.args << ":\n" << text.out;
    fs::remove(pack);
  }
}

// `convert --up auto` on a bust: Max Planck (up +y, its face towards −z in the data) is upright, so its face
// becomes the viewer's +z, the default camera's side (mesh/view_frame.h); `geomip info` shows that frame.
TEST_F(CliPack, ConvertAutoTurnsABustsFaceToTheCameraSide) {
  GEOMIP_REQUIRE_SHARED_MESH(bust, "max-planck.obj");
  const std::string pack = dir_ + "/max-planck.gip";
  ASSERT_EQ(geomip("convert -q '" + bust + "' --level 3 -o '" + pack + "'").exit_code, 0);
  const Outcome r = geomip("info --json '" + pack + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto model = nlohmann::json::parse(r.out)["models"][0];
  EXPECT_EQ(model["up"], "+y");
  EXPECT_EQ(model["camera_side"], "-z") << "the face";
  EXPECT_EQ(model["front"], "-x") << "up × face";
}

TEST_F(CliPack, BadPacksExitTwoWithoutOutput) {
  const std::string pack = dir_ + "/spot.gip";
  ASSERT_EQ(geomip("convert -q '" + spot_ + "' --level 4 --no-normals -o '" + pack + "'").exit_code, 0);
  const std::string bytes = slurp(pack);
  const std::string truncated = file("truncated.gip", bytes.substr(0, bytes.size() / 2));
  std::string flipped_bytes = bytes;
  flipped_bytes[bytes.size() - 3] ^= 0x20;
  const std::string flipped = file("flipped.gip", flipped_bytes);
  const std::string garbage = file("garbage.gip", "this is not a pack at all");
  std::string old_version_bytes = bytes;  // the magic, but a version field whose header layout does not fit
  old_version_bytes[8] = 2;
  old_version_bytes[9] = 0;
  const std::string old_version = file("old-version.gip", old_version_bytes);
  const std::string out = dir_ + "/out.obj";
  expect_bad_input("decode '" + truncated + "' -o '" + out + "'", truncated);
  expect_bad_input("decode '" + flipped + "' -o '" + out + "'", flipped);
  expect_bad_input("decode '" + garbage + "' -o '" + out + "'", garbage);
  expect_bad_input("decode '" + old_version + "' -o '" + out + "'", "corrupt geomip pack header (version 2");
  expect_bad_input("decode '" + dir_ + "/missing.gip' -o '" + out + "'", dir_ + "/missing.gip");
  expect_bad_input("decode '" + pack + "' --bytes 10 -o '" + out + "'", pack);  // inside the manifest
  EXPECT_FALSE(fs::exists(out));
  // The truncated file decodes when the prefix is asked for on purpose.
  EXPECT_EQ(geomip("decode -q '" + truncated + "' --bytes " + std::to_string(bytes.size() / 2) + " -o '" + out + "'")
                .exit_code,
            0);
  for (const char* args : {"convert --help", "encode --help", "decode --help"})
    EXPECT_EQ(geomip(args).exit_code, 0) << args;
}

/// The names in `dir` (not recursive): what a run left there, temporary files included.
std::set<std::string> names_in(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// A command's output files are one set, written all or none. `remesh --ply --glb` whose .glb could not be
// written had written the .obj (over an earlier run's) and the .ply, and left them.
TEST_F(CliPack, RemeshWritesAllItsFilesOrNone) {
  const std::string out = dir_ + "/out";
  fs::create_directories(out + "/spot.M3.glb");
  file("out/spot.M3.obj", "an earlier run's");
  expect_bad_input("remesh -q '" + spot_ + "' --level 3 --ply --glb -o '" + out + "'", out + "/spot.M3.glb");
  EXPECT_EQ(slurp(out + "/spot.M3.obj"), "an earlier run's");
  EXPECT_EQ(names_in(out), (std::set<std::string>{"spot.M3.glb", "spot.M3.obj"}));
  // The same with the adaptive remesh's file in the way: no file of the uniform remesh either.
  fs::remove(out + "/spot.M3.glb");
  fs::create_directories(out + "/spot.adaptive.obj");
  expect_bad_input("remesh -q '" + spot_ + "' --level 3 --ply --adaptive 0.01 --max-depth 3 -o '" + out + "'",
                   out + "/spot.adaptive.obj");
  EXPECT_EQ(slurp(out + "/spot.M3.obj"), "an earlier run's");
  EXPECT_EQ(names_in(out), (std::set<std::string>{"spot.adaptive.obj", "spot.M3.obj"}));
}

// decode of a pack of several models: the last model's mesh not written (its place a directory, a full
// disk) left the first model's mesh written (over an earlier one), and said "decode ... → ..." for it.
TEST_F(CliPack, DecodeWritesEveryModelsMeshOrNone) {
  ASSERT_EQ(geomip("gimage -q '" + spot_ + "' --level 3 -o '" + dir_ + "/gi'").exit_code, 0);
  const std::string pack = dir_ + "/two.gip";
  ASSERT_EQ(geomip("encode -q --no-normals '" + dir_ + "/gi' '" + dir_ + "/gi' -o '" + pack + "'").exit_code,
            0);
  const std::string out = dir_ + "/o", first = out + "/x.spot.obj", last = out + "/x.spot-1.obj";
  fs::create_directories(last);
  file("o/x.spot.obj", "an earlier run's");
  Outcome r = geomip("decode '" + pack + "' -o '" + out + "/x.obj'");
  EXPECT_FALSE(r.crashed);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(last), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out, "");  // no "decode spot → ..." for a file that is not there
  EXPECT_EQ(slurp(first), "an earlier run's");
  EXPECT_EQ(names_in(out), (std::set<std::string>{"x.spot-1.obj", "x.spot.obj"}));
  if (fs::is_character_file("/dev/full")) {  // a full disk at the last model
    fs::remove(last);
    fs::create_symlink("/dev/full", last);
    r = geomip("decode '" + pack + "' -o '" + out + "/x.obj'");
    EXPECT_FALSE(r.crashed);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(last + ": write failed (No space left on device)"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(slurp(first), "an earlier run's");
    EXPECT_TRUE(fs::is_symlink(last));
    EXPECT_EQ(names_in(out), (std::set<std::string>{"x.spot-1.obj", "x.spot.obj"}));
  }
  fs::remove(last);
  r = geomip("decode '" + pack + "' -o '" + out + "/x.obj'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("→ " + last), std::string::npos) << r.out;
  EXPECT_EQ(read_mesh(first).triangles, read_mesh(last).triangles);
  EXPECT_EQ(read_mesh(first).triangles.size(), 2u * 2 * 8 * 8);
}

// param's .param.obj and .param.json, gimage's two images, eval's two error maps, all or none.
TEST_F(CliPack, ParamGimageAndEvalWriteAllTheirFilesOrNone) {
  const std::string param = dir_ + "/param";
  fs::create_directories(param + "/spot.param.json");
  expect_bad_input("param -q --no-baseline '" + spot_ + "' -o '" + param + "'", param + "/spot.param.json");
  EXPECT_EQ(names_in(param), (std::set<std::string>{"spot.param.json"}));

  const std::string gi = dir_ + "/gi";
  fs::create_directories(gi + "/spot.normals.exr");
  expect_bad_input("gimage -q '" + spot_ + "' --level 3 -o '" + gi + "'", gi + "/spot.normals.exr");
  EXPECT_EQ(names_in(gi), (std::set<std::string>{"spot.normals.exr"}));

  if (fs::is_character_file("/dev/full")) {
    ASSERT_EQ(geomip("remesh -q '" + spot_ + "' --level 3 -o '" + dir_ + "'").exit_code, 0);
    const std::string approx = dir_ + "/spot.M3.obj", map = dir_ + "/map.ply", full = dir_ + "/full.ply";
    fs::create_symlink("/dev/full", full);
    const Outcome r = geomip("eval '" + spot_ + "' '" + approx + "' --error-map '" + map +
                             "' --error-map-original '" + full + "'");
    EXPECT_FALSE(r.crashed);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(full + ": write failed"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(map));
  }
}

}  // namespace
}  // namespace geomip
