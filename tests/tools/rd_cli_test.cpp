// End to end: `geomip rd --quick` writes rd.csv and rd.svg, and fails cleanly (exit 2, one line, no output
// files) on a missing mesh.
#include "mesh/mesh_io.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace geomip {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

class RdCli : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("rd_cli");
  void TearDown() override { fs::remove_all(dir_); }

  int geomip(const std::string& args, std::string& err) {
    const std::string cmd = std::string("timeout 300 '") + GEOMIP_BINARY + "' " + args + " > '" + dir_ +
                            "/stdout' 2> '" + dir_ + "/stderr' < /dev/null";
    const int status = std::system(cmd.c_str());
    err = slurp(fs::path(dir_) / "stderr");
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  /// A closed sphere of 3072 faces, written as OBJ.
  std::string sphere_obj() const {
    const std::string mesh = dir_ + "/sphere.obj";
    std::ofstream out(mesh);
    write_mesh(test::sphere(4), out, MeshFormat::kObj);
    return mesh;
  }
};

TEST_F(RdCli, QuickRunWritesCsvAndSvg) {
  const std::string mesh = sphere_obj();
  const std::string out_dir = dir_ + "/rd";
  std::string err;
  ASSERT_EQ(geomip("rd --quick '" + mesh + "' -o '" + out_dir + "'", err), 0) << err;
  const std::string csv = slurp(fs::path(out_dir) / "rd.csv");
  const std::string svg = slurp(fs::path(out_dir) / "rd.svg");
  EXPECT_EQ(csv.rfind("method,bytes,psnr_db,hausdorff_pct,decode_ms", 0), 0u);
  std::set<std::string> methods;
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  // geomip's prefixes: sizes increasing, and the whole pack never worse than its smallest prefix.
  std::vector<std::pair<double, double>> geomip_points;  // bytes, psnr
  while (std::getline(lines, line)) {
    const std::string method = line.substr(0, line.find(','));
    methods.insert(method);
    if (method == "geomip") {
      std::istringstream fields(line.substr(method.size() + 1));
      double bytes = 0, psnr = 0;
      char comma;
      fields >> bytes >> comma >> psnr;
      geomip_points.push_back({bytes, psnr});
    }
  }
  // The sphere is an oriented 2-manifold: the Lindstrom–Turk baseline (the strongest) is built by default.
  EXPECT_EQ(methods, (std::set<std::string>{"draco", "draco_qem", "draco_envelope", "draco_lt",
                                            "draco_lt_envelope", "meshopt", "geomip"}));
  EXPECT_EQ(err.find("Lindstrom"), std::string::npos) << err;
  ASSERT_GE(geomip_points.size(), 3u);
  EXPECT_TRUE(std::is_sorted(geomip_points.begin(), geomip_points.end()));
  EXPECT_GT(geomip_points.back().second, geomip_points.front().second + 5);
  EXPECT_TRUE(fs::exists(fs::path(out_dir) / "sphere.gip"));
  for (const char* method :
       {"draco", "draco_qem", "draco_envelope", "draco_lt_envelope", "meshopt", "geomip"})
    EXPECT_NE(svg.find(std::string("data-method=\"") + method + "\""), std::string::npos) << method;
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // No temporary files left beside the outputs.
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(out_dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 3u);  // rd.csv, rd.svg, sphere.gip
}

// The comparison table reads geomip at exactly each size it names: a --quick run measures only a few
// prefixes, and its table showed a smaller prefix's PSNR at 4.7, 8.8 and 12 KB against the envelope there
// (margins of −22 dB). Every row is a measured prefix of that size, or the whole pack from its size on.
TEST_F(RdCli, TheTableReadsGeomipAtExactlyItsSizes) {
  const std::string mesh = sphere_obj();
  const std::string out_dir = dir_ + "/rd";
  std::string err;
  ASSERT_EQ(geomip("rd --quick --json '" + mesh + "' -o '" + out_dir + "'", err), 0) << err;
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(dir_) / "stdout"));
  std::map<double, double> measured;  // bytes → PSNR of geomip's prefixes, from rd.csv
  std::istringstream lines(slurp(fs::path(out_dir) / "rd.csv"));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) {
    if (line.rfind("geomip,", 0) != 0) continue;
    std::istringstream fields(line.substr(7));
    double bytes = 0, psnr = 0;
    char comma;
    fields >> bytes >> comma >> psnr;
    measured[bytes] = psnr;
  }
  ASSERT_FALSE(measured.empty());
  const double pack_size = static_cast<double>(fs::file_size(fs::path(out_dir) / "sphere.gip"));
  for (const char* key : {"geomip_vs_draco_envelope", "geomip_vs_draco_lt_envelope"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    ASSERT_FALSE(j[key].empty()) << key;
    for (const auto& row : j[key]) {
      const double bytes = row["bytes"].get<double>();
      const double expected = bytes >= pack_size      ? measured.rbegin()->second
                              : measured.count(bytes) ? measured[bytes]
                                                      : NAN;
      ASSERT_FALSE(std::isnan(expected)) << key << ", " << bytes << " B: not measured, yet in the table";
      EXPECT_NEAR(row["geomip_db"].get<double>(), expected, 0.01) << key << ", " << bytes;
    }
  }
}

// The Lindstrom–Turk baseline is built by default, since it is the strongest; a mesh CGAL's half-edge
// structure cannot hold (here one triangle of a sphere turned over, so its orientation disagrees with its
// neighbours') still gets the other baselines, with one note on stderr that says why that one is missing.
// --lindstrom-turk makes it required (exit 2, one line, nothing written); --no-lindstrom-turk drops it and
// the note; the two together are refused.
TEST_F(RdCli, LindstromTurkByDefaultAndANoteWhereTheMeshCannotTakeIt) {
  const std::string mesh = dir_ + "/flipped.obj";
  {
    TriMesh flipped = test::sphere(3);
    std::swap(flipped.triangles[7][1], flipped.triangles[7][2]);
    std::ofstream out(mesh);
    write_mesh(flipped, out, MeshFormat::kObj);
  }
  const auto methods = [&](const std::string& out_dir) {
    std::set<std::string> found;
    std::istringstream lines(slurp(fs::path(out_dir) / "rd.csv"));
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) found.insert(line.substr(0, line.find(',')));
    return found;
  };
  const std::set<std::string> without_lt = {"draco", "draco_qem", "draco_envelope", "meshopt"};
  std::string err;
  ASSERT_EQ(geomip("rd -q --quick --no-geomip '" + mesh + "' -o '" + dir_ + "/a'", err), 0) << err;
  EXPECT_EQ(methods(dir_ + "/a"), without_lt);
  EXPECT_NE(err.find("note: no Lindstrom-Turk baseline"), std::string::npos) << err;
  EXPECT_NE(err.find("flipped.obj is not an oriented 2-manifold"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;

  EXPECT_EQ(geomip("rd -q --quick --no-geomip --lindstrom-turk '" + mesh + "' -o '" + dir_ + "/b'", err), 2);
  EXPECT_NE(err.find("--lindstrom-turk needs an oriented 2-manifold"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "b" / "rd.csv"));

  ASSERT_EQ(geomip("rd -q --quick --no-geomip --no-lindstrom-turk '" + mesh + "' -o '" + dir_ + "/c'", err),
            0)
      << err;
  EXPECT_EQ(methods(dir_ + "/c"), without_lt);
  EXPECT_EQ(err, "");

  EXPECT_EQ(geomip("rd -q --quick --no-geomip --lindstrom-turk --no-lindstrom-turk '" + mesh + "' -o '" +
                       dir_ + "/d'",
                   err),
            2);
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "d" / "rd.csv"));

  // The same sphere the right way round takes it.
  const std::string closed = sphere_obj();
  ASSERT_EQ(geomip("rd -q --quick --no-geomip '" + closed + "' -o '" + dir_ + "/e'", err), 0) << err;
  EXPECT_TRUE(methods(dir_ + "/e").count("draco_lt_envelope"));
  EXPECT_EQ(err, "");
}

// `rd --fit` codes samples fitted to the surface by least squares (as `convert --fit`): on a sphere the whole
// pack decodes closer to the mesh than without, and the flag takes no value.
TEST_F(RdCli, FitRaisesTheWholePack) {
  const std::string mesh = sphere_obj();
  auto whole_pack_psnr = [&](const std::string& flag) {
    const std::string out_dir = dir_ + "/rd" + flag;
    std::string err;
    EXPECT_EQ(geomip("rd --quick " + flag + " '" + mesh + "' -o '" + out_dir + "'", err), 0) << err;
    std::istringstream lines(slurp(fs::path(out_dir) / "rd.csv"));
    std::string line;
    double best_bytes = -1, psnr_at_best = 0;
    while (std::getline(lines, line)) {
      if (line.rfind("geomip,", 0) != 0) continue;
      std::istringstream fields(line.substr(7));
      double bytes = 0, psnr = 0;
      char comma;
      fields >> bytes >> comma >> psnr;
      if (bytes > best_bytes) best_bytes = bytes, psnr_at_best = psnr;
    }
    EXPECT_GT(best_bytes, 0) << flag;
    return psnr_at_best;
  };
  const double plain = whole_pack_psnr("--no-fit"), fitted = whole_pack_psnr("--fit");
  EXPECT_GT(fitted, plain + 0.5) << "fitted " << fitted << " dB, plain " << plain << " dB";
  std::string err;
  EXPECT_EQ(geomip("rd --quick --fit=x '" + mesh + "' -o '" + dir_ + "/bad'", err), 2);
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "bad" / "rd.csv"));
}

// `rd --end-loop` (`--tip-loop`) measures the pack `convert --no-normals --end-loop` writes, byte for byte;
// both loops together, or a loop with --patches 4, exit 2 with nothing written.
TEST_F(RdCli, LoopFlagsMeasureThatLoopsPack) {
  const std::string mesh = dir_ + "/spiked.obj";
  {
    std::ofstream out(mesh);
    write_mesh(test::spiked_ellipsoid(4, 0.15), out, MeshFormat::kObj);
  }
  std::string err;
  for (const std::string flag : {"--end-loop", "--tip-loop"}) {
    const std::string out_dir = dir_ + "/rd" + flag;
    ASSERT_EQ(geomip("rd --quick --level 5 " + flag + " '" + mesh + "' -o '" + out_dir + "'", err), 0) << err;
    ASSERT_EQ(geomip("convert -q --no-normals --level 5 " + flag + " '" + mesh + "' -o '" + dir_ + "/c.gip'", err), 0)
        << err;
    EXPECT_EQ(slurp(fs::path(out_dir) / "spiked.gip"), slurp(fs::path(dir_) / "c.gip")) << flag;
  }
  EXPECT_NE(slurp(fs::path(dir_) / "rd--end-loop" / "spiked.gip"), slurp(fs::path(dir_) / "rd--tip-loop" / "spiked.gip"));
  for (const std::string args : {"--end-loop --tip-loop", "--end-loop --patches 4"}) {
    EXPECT_EQ(geomip("rd --quick " + args + " '" + mesh + "' -o '" + dir_ + "/bad'", err), 2) << args;
    EXPECT_NE(err.find("--end-loop"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(fs::path(dir_) / "bad")) << args;
  }
}

// Without --patches, rd measures the pack `convert` would write: the cow, which two squares stretch, on the
// layout convert chooses (16 or 64 patches; byte for byte convert's pack), and says so; --patches 2 keeps
// the two squares.
TEST_F(RdCli, StretchedShapeIsMeasuredOnConvertsLayout) {
  GEOMIP_REQUIRE_SHARED_MESH(cow, "cow.obj");
  std::string err;
  ASSERT_EQ(geomip("convert --json --no-normals --level 4 '" + cow + "' -o '" + dir_ + "/c.gip'", err), 0)
      << err;
  const nlohmann::json c = nlohmann::json::parse(slurp(fs::path(dir_) / "stdout"));
  ASSERT_TRUE(c["moved_to_patches"].get<bool>());
  ASSERT_EQ(geomip("rd --quick --level 4 '" + cow + "' -o '" + dir_ + "/rd'", err), 0) << err;
  std::string weights;  // as --layout-error-weights takes them
  for (const nlohmann::json& w : c["layout_choice"]["chosen_error_weights"]) {
    std::ostringstream one;
    one << w.get<double>();
    weights += (weights.empty() ? "" : ",") + one.str();
  }
  const std::string said = "geomip pack: " + std::to_string(c["patches"].get<int>()) +
                           " patches, error weights " + weights + ", at level " +
                           std::to_string(c["level"].get<int>());
  EXPECT_NE(slurp(fs::path(dir_) / "stdout").find(said), std::string::npos) << said;
  EXPECT_EQ(slurp(fs::path(dir_) / "rd" / "cow.gip"), slurp(fs::path(dir_) / "c.gip"));
  ASSERT_EQ(geomip("rd --quick --json --level 4 --patches 2 '" + cow + "' -o '" + dir_ + "/rd2'", err), 0)
      << err;
  EXPECT_EQ(slurp(fs::path(dir_) / "stdout").find("geomip_moved_to_patches"), std::string::npos);
  ASSERT_EQ(
      geomip("convert -q --no-normals --level 4 --patches 2 '" + cow + "' -o '" + dir_ + "/c2.gip'", err), 0)
      << err;
  EXPECT_EQ(slurp(fs::path(dir_) / "rd2" / "cow.gip"), slurp(fs::path(dir_) / "c2.gip"));
}

// Finite coordinates whose extent overflows float (a sphere of radius 3e38): Draco crashed (SIGSEGV) in
// every series. Now refused before the work: exit 2, one line naming the mesh, no output directory.
TEST_F(RdCli, ExtentBeyondFloatRangeIsRefusedBeforeDraco) {
  const std::string mesh = dir_ + "/huge.obj";
  {
    TriMesh huge = test::sphere(2);
    for (auto& p : huge.positions) p *= 3e38;  // the unit sphere spans −3e38..3e38: extent 6e38
    std::ofstream out(mesh);
    write_mesh(huge, out, MeshFormat::kObj);
  }
  const std::string out_dir = dir_ + "/rd";
  std::string err;
  EXPECT_EQ(geomip("rd -q --quick --no-geomip '" + mesh + "' -o '" + out_dir + "'", err), 2) << err;
  EXPECT_NE(err.find("huge.obj"), std::string::npos) << err;
  EXPECT_NE(err.find("overflows float"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(out_dir));
}

// rd.csv, rd.svg and the pack are one set: a pack that could not be written (its place a directory) left the
// table and the plot of the run written.
TEST_F(RdCli, APackThatCannotBeWrittenLeavesNoTableOrPlot) {
  const std::string mesh = dir_ + "/sphere.obj";
  {
    std::ofstream out(mesh);
    write_mesh(test::sphere(3), out, MeshFormat::kObj);
  }
  const std::string out_dir = dir_ + "/rd";
  fs::create_directories(out_dir + "/sphere.gip");
  std::string err;
  EXPECT_EQ(geomip("rd -q --quick '" + mesh + "' -o '" + out_dir + "'", err), 2) << err;
  EXPECT_NE(err.find(out_dir + "/sphere.gip"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(out_dir)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"sphere.gip"}));
}

// A flat mesh: every coded copy lies on its surface (PSNR infinite, nothing to plot). rd failed in the plot
// after all its work and wrote nothing; now the table and a plot that says so are written.
TEST_F(RdCli, FlatMeshStillWritesItsTableAndPlot) {
  const std::string mesh = dir_ + "/flat.obj";
  {
    TriMesh flat;
    const int n = 12;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) flat.positions.emplace_back(i / double(n - 1), j / double(n - 1), 0.0);
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i;
        flat.triangles.push_back({a, a + 1, a + n + 1});
        flat.triangles.push_back({a, a + n + 1, a + n});
      }
    std::ofstream out(mesh);
    write_mesh(flat, out, MeshFormat::kObj);
  }
  const std::string out_dir = dir_ + "/rd";
  std::string err;
  ASSERT_EQ(geomip("rd -q --quick --no-geomip '" + mesh + "' -o '" + out_dir + "'", err), 0) << err;
  EXPECT_NE(slurp(fs::path(out_dir) / "rd.csv").find("draco,"), std::string::npos);
  EXPECT_NE(slurp(fs::path(out_dir) / "rd.svg").find("nothing to plot"), std::string::npos);
}

TEST_F(RdCli, MissingMeshFailsCleanly) {
  const std::string out_dir = dir_ + "/rd";
  std::string err;
  EXPECT_EQ(geomip("rd '" + dir_ + "/no-such-mesh.obj' -o '" + out_dir + "'", err), 2);
  EXPECT_NE(err.find("no-such-mesh.obj"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(out_dir));
  EXPECT_EQ(geomip("rd --quick", err), 2);  // missing arguments
}

}  // namespace
}  // namespace geomip
