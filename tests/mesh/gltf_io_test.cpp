// glTF 2.0 through TinyGLTF: exact float round trips (GLB and JSON), attributes written with the sizes and
// bounds the specification requires, node transforms applied on input, and crafted files refused with a
// message instead of a crash (accessors past their buffers, indices out of range, garbage). Draco
// (KHR_draco_mesh_compression): positions within the quantization step, the same triangles, a smaller file,
// the extension declared as required, damaged Draco bytes refused.
#include "mesh/errors.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh_io.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

namespace geomip {
namespace {

std::string to_gltf(const TriMesh& mesh, const MeshAttributes& attributes, bool binary, int draco_bits = 0) {
  std::ostringstream out;
  GltfWriteOptions o;
  o.binary = binary;
  o.draco_position_bits = draco_bits;
  write_gltf(mesh, attributes, out, o);
  return out.str();
}

TriMesh float_rounded(const TriMesh& m) { return test::float32(m); }

TEST(GltfIo, RoundTripIsExactInFloatForGlbAndJson) {
  const TriMesh torus = float_rounded(test::torus(12, 7));
  for (bool binary : {true, false}) {
    const std::string bytes = to_gltf(torus, {}, binary);
    EXPECT_EQ(bytes.rfind("glTF", 0) == 0, binary);
    const TriMesh back = read_gltf_from_memory(bytes, "torus", "");
    ASSERT_EQ(back.positions.size(), torus.positions.size());
    ASSERT_EQ(back.triangles, torus.triangles);
    for (std::size_t v = 0; v < torus.positions.size(); ++v) EXPECT_EQ(back.positions[v], torus.positions[v]) << v;
  }
}

// A node rotation (a pack's view frame) is written as the node's matrix: positions stay as given, a reader
// that applies node transforms (ours) sees them turned; a matrix that is no rotation is refused.
TEST(GltfIo, NodeRotationTurnsTheSceneNotThePositions) {
  const TriMesh torus = float_rounded(test::torus(12, 7));
  GltfWriteOptions o;
  o.node_rotation = {0, 0, 1, 0, 1, 0, -1, 0, 0};  // row-major: (x, y, z) ↦ (z, y, −x)
  std::ostringstream out;
  write_gltf(torus, {}, out, o);
  const std::string bytes = out.str();
  std::uint32_t json_bytes = 0;
  std::memcpy(&json_bytes, bytes.data() + 12, 4);
  const auto json = nlohmann::json::parse(bytes.substr(20, json_bytes));
  const std::vector<double> column_major = {0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1};
  EXPECT_EQ(json["nodes"][0]["matrix"].get<std::vector<double>>(), column_major);
  const auto accessor =
      json["accessors"][json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()];
  double max_x = -HUGE_VAL;
  for (const auto& p : torus.positions) max_x = std::max(max_x, p.x());
  EXPECT_FLOAT_EQ(accessor["max"][0].get<double>(), max_x) << "positions as given";
  const TriMesh back = read_gltf_from_memory(bytes, "torus", "");
  ASSERT_EQ(back.positions.size(), torus.positions.size());
  for (std::size_t v = 0; v < torus.positions.size(); ++v) {
    const Eigen::Vector3d& p = torus.positions[v];
    EXPECT_LT((back.positions[v] - Eigen::Vector3d(p.z(), p.y(), -p.x())).norm(), 1e-6) << v;
  }
  // Identity: no matrix at all; a scale or a mirror: refused.
  std::ostringstream plain;
  write_gltf(torus, {}, plain, {});
  EXPECT_EQ(plain.str().find("\"matrix\""), std::string::npos);
  for (const std::array<double, 9>& bad : {std::array<double, 9>{2, 0, 0, 0, 2, 0, 0, 0, 2},
                                           std::array<double, 9>{-1, 0, 0, 0, 1, 0, 0, 0, 1}}) {
    o.node_rotation = bad;
    std::ostringstream sink;
    EXPECT_THROW(write_gltf(torus, {}, sink, o), InvalidInput);
  }
}

// glTF splits vertices at texture seams; geomip reads positions only, so a torus written with every
// triangle's corners duplicated (a "triangle soup", as per-face attributes force) reads back welded: the same
// vertices and topology as the torus itself.
TEST(GltfIo, VerticesAtIdenticalPositionsAreMergedOnInput) {
  const TriMesh torus = float_rounded(test::torus(12, 7));
  TriMesh soup;
  MeshAttributes uv_per_corner;
  for (const auto& t : torus.triangles) {
    std::array<int, 3> corners{};
    for (int k = 0; k < 3; ++k) {
      corners[k] = static_cast<int>(soup.positions.size());
      soup.positions.push_back(torus.positions[t[k]]);
      uv_per_corner.uv.emplace_back(0.5f * k, 0.25f);
    }
    soup.triangles.push_back(corners);
  }
  const TriMesh back = read_gltf_from_memory(to_gltf(soup, uv_per_corner, true), "soup", "");
  ASSERT_EQ(back.positions.size(), torus.positions.size());
  ASSERT_EQ(back.triangles.size(), torus.triangles.size());
  for (std::size_t f = 0; f < torus.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(back.positions[back.triangles[f][k]], torus.positions[torus.triangles[f][k]]);
}

TEST(GltfIo, JsonCarriesAttributesAndBoundsTheSpecificationRequires) {
  const TriMesh cube = test::cube();
  MeshAttributes a;
  for (const auto& p : cube.positions) {  // unit normals from the centre, as glTF requires
    a.normals.push_back((p - Eigen::Vector3d::Constant(0.5)).normalized().cast<float>());
    a.uv.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  const auto j = nlohmann::json::parse(to_gltf(cube, a, false));
  EXPECT_EQ(j["asset"]["version"], "2.0");
  const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attributes.contains("POSITION") && attributes.contains("NORMAL") && attributes.contains("TEXCOORD_0"));
  const auto& pos = j["accessors"][attributes["POSITION"].get<int>()];
  EXPECT_EQ(pos["count"], cube.positions.size());
  ASSERT_EQ(pos["min"].size(), 3u);
  for (int c = 0; c < 3; ++c) {
    double lo = 1e300, hi = -1e300;
    for (const auto& p : cube.positions) lo = std::min(lo, p[c]), hi = std::max(hi, p[c]);
    EXPECT_DOUBLE_EQ(pos["min"][c].get<double>(), lo);
    EXPECT_DOUBLE_EQ(pos["max"][c].get<double>(), hi);
  }
  EXPECT_EQ(j["accessors"][attributes["TEXCOORD_0"].get<int>()]["type"], "VEC2");
  const auto& ix = j["accessors"][j["meshes"][0]["primitives"][0]["indices"].get<int>()];
  EXPECT_EQ(ix["count"], 3 * cube.triangles.size());
  // The buffer is embedded: the file stands alone.
  EXPECT_EQ(j["buffers"][0]["uri"].get<std::string>().rfind("data:application/octet-stream;base64,", 0), 0u);
}

TEST(GltfIo, WrongAttributeSizesAndEmptyMeshesAreRefused) {
  const TriMesh cube = test::cube();
  std::ostringstream out;
  MeshAttributes a;
  a.normals.resize(cube.positions.size() - 1);
  EXPECT_THROW(write_gltf(cube, a, out), InvalidInput);
  EXPECT_THROW(write_gltf(TriMesh{}, {}, out), InvalidInput);
}

// What the Khronos validator calls errors is refused before a byte is written: a NORMAL off unit length (it
// reports from 1 ± 0.00674), a non-finite normal or texture coordinate. Unit vectors rounded to float pass.
TEST(GltfIo, NormalsOffUnitLengthAndNonFiniteAttributesAreRefused) {
  const TriMesh cube = test::cube();
  MeshAttributes a;
  for (const auto& p : cube.positions)
    a.normals.push_back((p - Eigen::Vector3d::Constant(0.5)).normalized().cast<float>());
  a.uv.assign(cube.positions.size(), Eigen::Vector2f(0.25f, 0.75f));
  std::ostringstream ok;
  EXPECT_NO_THROW(write_gltf(cube, a, ok));
  const auto refused = [&](const MeshAttributes& bad, const std::string& why) {
    std::ostringstream out;
    try {
      write_gltf(cube, bad, out);
      ADD_FAILURE() << why << ": written";
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
    EXPECT_TRUE(out.str().empty()) << why;
  };
  MeshAttributes longer = a;
  longer.normals[3] *= 1.01f;
  refused(longer, "normal 3 is not of unit length (1.01)");
  MeshAttributes zero = a;
  zero.normals[0].setZero();
  refused(zero, "normal 0 is not of unit length (0)");
  MeshAttributes nan = a;
  nan.normals[5].x() = std::nanf("");
  refused(nan, "normal 5 is not of unit length");
  MeshAttributes uv = a;
  uv.uv[2].y() = std::numeric_limits<float>::infinity();
  refused(uv, "texture coordinate 2 is not finite");
}

TEST(GltfIo, NodeTransformsAreAppliedAndMirroringKeepsTrianglesOutward) {
  const TriMesh tet = float_rounded(test::tetrahedron());
  auto j = nlohmann::json::parse(to_gltf(tet, {}, false));
  j["nodes"][0]["translation"] = {10.0, 0.0, 0.0};
  j["nodes"][0]["scale"] = {2.0, 2.0, 2.0};
  TriMesh moved = read_gltf_from_memory(j.dump(), "moved", "");
  ASSERT_EQ(moved.positions.size(), tet.positions.size());
  for (std::size_t v = 0; v < tet.positions.size(); ++v) {
    EXPECT_NEAR((moved.positions[v] - (2.0 * tet.positions[v] + Eigen::Vector3d(10, 0, 0))).norm(), 0.0, 1e-6);
  }
  EXPECT_EQ(moved.triangles, tet.triangles);
  j["nodes"][0].erase("translation");
  j["nodes"][0]["scale"] = {-1.0, 1.0, 1.0};
  const TriMesh mirrored = read_gltf_from_memory(j.dump(), "mirrored", "");
  // Mirrored positions with the winding swapped: every triangle's normal is the mirror of the original's.
  for (std::size_t t = 0; t < tet.triangles.size(); ++t) {
    const auto& a = tet.triangles[t];
    const auto& b = mirrored.triangles[t];
    const Eigen::Vector3d na = (tet.positions[a[1]] - tet.positions[a[0]]).cross(tet.positions[a[2]] - tet.positions[a[0]]);
    const Eigen::Vector3d nb = (mirrored.positions[b[1]] - mirrored.positions[b[0]])
                                   .cross(mirrored.positions[b[2]] - mirrored.positions[b[0]]);
    // n' = M·n for M = diag(−1, 1, 1): the outward normal mirrored (without the swap it would point inward).
    EXPECT_NEAR(nb.x(), -na.x(), 1e-9) << t;
    EXPECT_NEAR(nb.y(), na.y(), 1e-9) << t;
    EXPECT_NEAR(nb.z(), na.z(), 1e-9) << t;
  }
}

void expect_refused(const std::string& bytes, const std::string& problem) {
  try {
    read_gltf_from_memory(bytes, "crafted.gltf", "");
    ADD_FAILURE() << "accepted; expected '" << problem << "'";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("crafted.gltf"), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << "'" << what << "' lacks '" << problem << "'";
  }
}

TEST(GltfIo, CraftedFilesAreRefusedWithAMessage) {
  const TriMesh tet = test::tetrahedron();
  const auto good = nlohmann::json::parse(to_gltf(tet, {}, false));
  expect_refused("", "not a glTF file (neither a binary glTF");
  expect_refused("\x8f\x02garbage bytes", "not a glTF file (neither a binary glTF");
  expect_refused("  [1, 2]", "not a glTF file (neither a binary glTF");
  expect_refused("glTF\x02\0\0\0garbage", "not a readable glTF");
  expect_refused("\xEF\xBB\xBF {\"asset\": {\"version\": \"2.0\"}}", "no triangles");  // a BOM is fine
  expect_refused("{\"asset\": {\"version\": \"2.0\"}}", "no triangles");
  auto j = good;
  j["accessors"][0]["count"] = 1000000;  // POSITION past its buffer view
  expect_refused(j.dump(), "reaches past its buffer");
  j = good;
  j["bufferViews"][0]["byteOffset"] = 1u << 30;
  expect_refused(j.dump(), "");
  j = good;
  j["accessors"][0]["byteOffset"] = 4;  // the last vertex's bytes end past the view
  expect_refused(j.dump(), "reaches past its buffer");
  j = good;
  const int ix = j["meshes"][0]["primitives"][0]["indices"];
  j["accessors"][ix]["count"] = 4;
  expect_refused(j.dump(), "multiple of 3");
  j = good;
  j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = ix;  // indices as positions: wrong type
  expect_refused(j.dump(), "wrong type");
  j = good;
  j["nodes"][0]["children"] = {0};  // a cycle: the scene's root is its own child
  expect_refused(j.dump(), "disjoint trees");
}

// glTF's nodes form disjoint trees (§3.5.3). A node that lists the next one twice, level after level, made
// 2^levels instances (60 levels in 2 KB: unbounded memory); a node with two parents, a scene root that is
// also a child or is listed twice instanced its subtree twice. All refused before any instance is made; a
// mesh that two sibling nodes reference (a tree) is read twice, as glTF means.
TEST(GltfIo, NodesThatAreNotDisjointTreesAreRefused) {
  const TriMesh tet = test::tetrahedron();
  const auto good = nlohmann::json::parse(to_gltf(tet, {}, false));
  auto j = good;
  j["nodes"] = nlohmann::json::array();
  for (int i = 0; i < 20; ++i) j["nodes"].push_back({{"children", {i + 1, i + 1}}});
  j["nodes"].push_back({{"mesh", 0}});
  j["scenes"][0]["nodes"] = {0};
  expect_refused(j.dump(), "twice as a child");
  j["nodes"] = {{{"children", {2}}}, {{"children", {2}}}, {{"mesh", 0}}};
  j["scenes"][0]["nodes"] = {0, 1};
  expect_refused(j.dump(), "child of both node 0 and node 1");
  j["nodes"] = {{{"children", {1}}}, {{"mesh", 0}}};
  expect_refused(j.dump(), "scene root node 1 is also a child of node 0");
  j["nodes"] = {{{"mesh", 0}}};
  j["scenes"][0]["nodes"] = {0, 0};
  expect_refused(j.dump(), "listed twice among the scene's root nodes");
  j["nodes"] = {{{"children", {1, 2}}}, {{"mesh", 0}, {"translation", {10.0, 0.0, 0.0}}}, {{"mesh", 0}}};
  j["scenes"][0]["nodes"] = {0};
  const TriMesh two = read_gltf_from_memory(j.dump(), "two", "");
  EXPECT_EQ(two.triangles.size(), 2 * tet.triangles.size());
  EXPECT_EQ(two.positions.size(), 2 * tet.positions.size());
}

// Trees bound the instances by the nodes, yet many sibling nodes may each instance one large accessor:
// 200 nodes × 100,000 triangles from one 300 KB index buffer. All instances together are bounded (16
// vertices plus triangles per byte of data, at least 2^24): refused, with a message, before that memory.
TEST(GltfIo, InstancesBeyondTheBudgetAreRefused) {
  const TriMesh tet = test::tetrahedron();
  auto j = nlohmann::json::parse(to_gltf(tet, {}, false));
  const std::size_t index_bytes = 300000;  // 100,000 triangles of one-byte indices, all vertex 0
  j["buffers"].push_back(
      {{"byteLength", index_bytes},
       {"uri", "data:application/octet-stream;base64," + std::string(index_bytes / 3 * 4, 'A')}});
  j["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", index_bytes}});
  j["accessors"].push_back({{"bufferView", j["bufferViews"].size() - 1},
                            {"componentType", 5121},
                            {"count", index_bytes},
                            {"type", "SCALAR"}});
  nlohmann::json prim = j["meshes"][0]["primitives"][0];
  prim["indices"] = j["accessors"].size() - 1;
  j["meshes"].push_back({{"primitives", {prim}}});
  j["nodes"] = {{{"children", nlohmann::json::array()}}};
  for (int i = 1; i <= 200; ++i) {
    j["nodes"][0]["children"].push_back(i);
    j["nodes"].push_back({{"mesh", 1}});
  }
  j["scenes"][0]["nodes"] = {0};
  expect_refused(j.dump(), "vertices and triangles");
  j["nodes"] = {{{"children", {1, 2, 3}}}, {{"mesh", 1}}, {{"mesh", 1}}, {{"mesh", 1}}};  // 300,000 triangles
  EXPECT_EQ(read_gltf_from_memory(j.dump(), "three", "").triangles.size(), 3 * index_bytes / 3);
}

// A JSON glTF of `mesh` whose buffer is the file `uri` (beside it in `dir`, as `bytes` when not empty),
// written as DIR/NAME; its path. The buffer's bytes are those of the same mesh's GLB.
std::string gltf_with_external_buffer(const TriMesh& mesh, const std::string& dir, const std::string& name,
                                      const std::string& uri, bool write_buffer) {
  auto j = nlohmann::json::parse(to_gltf(mesh, {}, false));
  const std::size_t length = j["buffers"][0]["byteLength"];
  const std::string glb = to_gltf(mesh, {}, true);
  std::uint32_t json_size = 0;
  std::memcpy(&json_size, glb.data() + 12, 4);
  if (write_buffer)
    std::ofstream(dir + "/" + uri, std::ios::binary) << glb.substr(20 + json_size + 8, length);
  j["buffers"][0]["uri"] = uri;
  std::ofstream(dir + "/" + name) << j.dump();
  return dir + "/" + name;
}

// External buffers get the checks a mesh file gets: a regular file (a directory ended in std::bad_alloc, a
// FIFO blocked forever: tests/tools/cli_test.cpp), no larger than the byteLength declared (a 64 MB sparse
// file behind "byteLength": 136 was read whole before the size mismatch was noticed). One message naming
// the URI; a buffer file that is right reads.
TEST(GltfIo, ExternalBuffersMustBeRegularFilesOfTheirDeclaredSize) {
  namespace fs = std::filesystem;
  const std::string dir = test::temp_dir("gltf_ext");
  const TriMesh tet = float_rounded(test::tetrahedron());
  const std::string good = gltf_with_external_buffer(tet, dir, "good.gltf", "good.bin", true);
  EXPECT_EQ(read_mesh(good).triangles, tet.triangles);
  fs::create_directory(dir + "/sub.bin");
  const auto expect_refused_naming = [](const std::string& path, const std::string& uri,
                                        const std::string& problem) {
    try {
      read_mesh(path);
      ADD_FAILURE() << path << " was read";
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(uri), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << "'" << what << "' lacks '" << problem << "'";
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  expect_refused_naming(gltf_with_external_buffer(tet, dir, "dir.gltf", "sub.bin", false), "sub.bin",
                        "is a directory");
  const std::string sparse = gltf_with_external_buffer(tet, dir, "sparse.gltf", "sparse.bin", true);
  fs::resize_file(dir + "/sparse.bin", std::uint64_t{64} << 20);  // a hole: no disk space, 64 MB to read
  expect_refused_naming(sparse, "sparse.bin", "more than the");
  fs::remove_all(dir);
}

// Largest distance from a vertex of `a` to its corresponding vertex in `b`, matching triangles by their
// corner positions (Draco's edgebreaker reorders vertices and triangles): for every triangle of `a`, the
// triangle of `b` whose corners are nearest, as a multiset compared corner by corner in cyclic order.
double worst_corner_distance(const TriMesh& a, const TriMesh& b) {
  double worst = 0;
  for (const auto& ta : a.triangles) {
    double best = 1e300;
    for (const auto& tb : b.triangles)
      for (int r = 0; r < 3; ++r) {
        double d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, (a.positions[ta[k]] - b.positions[tb[(k + r) % 3]]).norm());
        best = std::min(best, d);
      }
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(GltfIo, DracoGlbKeepsTrianglesWithinTheQuantizationStep) {
  const TriMesh torus = float_rounded(test::torus(12, 7));
  MeshAttributes a;
  for (const auto& p : torus.positions) {
    a.normals.push_back(p.normalized().cast<float>());
    a.uv.emplace_back(static_cast<float>(0.5 + 0.25 * p.x()), static_cast<float>(0.5 + 0.25 * p.y()));
  }
  const std::string plain = to_gltf(torus, a, true);
  std::string packed;
  for (int bits : {8, 14}) {
    const std::string bytes = to_gltf(torus, a, true, bits);
    if (bits == 14) packed = bytes;
    const TriMesh back = read_gltf_from_memory(bytes, "torus.glb", "");
    ASSERT_EQ(back.triangles.size(), torus.triangles.size()) << bits;
    ASSERT_EQ(back.positions.size(), torus.positions.size()) << bits;
    double extent = 0;
    for (int c = 0; c < 3; ++c) {
      double lo = 1e300, hi = -1e300;
      for (const auto& p : torus.positions) lo = std::min(lo, p[c]), hi = std::max(hi, p[c]);
      extent = std::max(extent, hi - lo);
    }
    // Draco quantizes every coordinate to a grid of 2^bits - 1 steps over the largest extent.
    const double step = extent / ((1 << bits) - 1);
    EXPECT_LE(worst_corner_distance(torus, back), std::sqrt(3.0) * 0.5 * step * 1.001) << bits;
    EXPECT_GT(worst_corner_distance(torus, back), 0) << bits << ": quantized positions cannot all be exact";
  }
  EXPECT_LT(packed.size(), plain.size() / 2);
  // The same from JSON glTF (the Draco bytes in a base64 data URI).
  const TriMesh from_json = read_gltf_from_memory(to_gltf(torus, a, false, 14), "torus.gltf", "");
  EXPECT_EQ(from_json.triangles.size(), torus.triangles.size());
  EXPECT_LE(worst_corner_distance(torus, from_json), worst_corner_distance(torus, read_gltf_from_memory(packed, "t", "")));

  // The JSON: the extension required, accessors without buffer views (counts and bounds of the decode).
  const std::string& glb = packed;
  std::uint32_t json_size = 0;
  std::memcpy(&json_size, glb.data() + 12, 4);
  const auto j = nlohmann::json::parse(glb.substr(20, json_size));
  EXPECT_EQ(j["extensionsRequired"], nlohmann::json::array({"KHR_draco_mesh_compression"}));
  const auto& prim = j["meshes"][0]["primitives"][0];
  const auto& ext = prim["extensions"]["KHR_draco_mesh_compression"];
  ASSERT_TRUE(ext.contains("bufferView"));
  for (const char* name : {"POSITION", "NORMAL", "TEXCOORD_0"}) {
    ASSERT_TRUE(ext["attributes"].contains(name)) << name;
    const auto& accessor = j["accessors"][prim["attributes"][name].get<int>()];
    EXPECT_FALSE(accessor.contains("bufferView")) << name;
    EXPECT_EQ(accessor["count"], torus.positions.size()) << name;
  }
  EXPECT_EQ(j["accessors"][prim["indices"].get<int>()]["count"], 3 * torus.triangles.size());
}

TEST(GltfIo, DamagedDracoBytesAndBadBitsAreRefusedWithAMessage) {
  const TriMesh torus = float_rounded(test::torus(12, 7));
  EXPECT_THROW(to_gltf(torus, {}, true, 31), InvalidInput);
  EXPECT_THROW(to_gltf(torus, {}, true, -1), InvalidInput);
  const std::string glb = to_gltf(torus, {}, true, 12);
  std::uint32_t json_size = 0;
  std::memcpy(&json_size, glb.data() + 12, 4);
  const std::size_t bin = 20 + json_size + 8;  // the Draco bytes start the binary chunk
  int refused = 0, read = 0;
  for (std::size_t k = 0; k < 64; ++k) {  // garbage over the Draco header and the start of its stream
    std::string bad = glb;
    for (std::size_t i = bin + k; i < std::min(bad.size(), bin + k + 4); ++i) bad[i] = static_cast<char>(0xA5 ^ i);
    try {
      const TriMesh m = read_gltf_from_memory(bad, "bad.glb", "");
      for (const auto& t : m.triangles)
        for (int v : t) ASSERT_LT(static_cast<std::size_t>(v), m.positions.size());
      ++read;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("bad.glb"), std::string::npos) << e.what();
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_EQ(refused + read, 64);
}

// A 1,790-byte GLB the mesh fuzzer made (tests/data/draco-texcoord-orientations.glb): its Draco stream's
// texture-coordinate prediction declares a huge orientation count (a 32-bit field), so libdraco allocates
// about 270 MB and decodes that many bits before it fails (about 5 s in a release build, 11 s under ASan: the
// reason scripts/test gives the mesh fuzzer a 30 s timeout). Bounded by that 32-bit count; what geomip owes
// is one clear message and no crash.
TEST(GltfIo, DracoStreamWithAHugeTexcoordOrientationCountIsRefusedWithAMessage) {
  std::ifstream in(std::string(GEOMIP_SOURCE_DIR) + "/tests/data/draco-texcoord-orientations.glb",
                   std::ios::binary);
  const std::string glb((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(glb.size(), 1790u);
  try {
    read_gltf_from_memory(glb, "crafted.glb", "");
    ADD_FAILURE() << "the crafted Draco stream was read";
  } catch (const InvalidInput& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("crafted.glb"), std::string::npos) << message;
    EXPECT_NE(message.find("Draco"), std::string::npos) << message;
  }
}

// Coordinates each within float range whose extent (max − min) is not: Draco divides by that extent and
// crashed (draco 1.5.5). Refused with InvalidInput before Draco sees them; the same mesh without Draco, and a
// mesh whose extent just fits, are written.
TEST(GltfIo, DracoRefusesAnExtentBeyondFloatRange) {
  TriMesh huge = test::sphere(2);
  for (auto& p : huge.positions) p *= 3e38;  // the sphere spans −3e38..3e38: extent 6e38 > FLT_MAX
  try {
    to_gltf(huge, {}, true, 14);
    ADD_FAILURE() << "an extent beyond float range was written with Draco";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("overflows float"), std::string::npos) << e.what();
  }
  EXPECT_THROW(check_draco_positions(huge.positions, "huge.obj"), InvalidInput);
  EXPECT_NO_THROW(to_gltf(huge, {}, true, 0));  // plain float accessors hold it
  TriMesh fits = test::sphere(2);
  for (auto& p : fits.positions) p *= 1.5e38;  // extent 3e38 < FLT_MAX
  EXPECT_NO_THROW(check_draco_positions(fits.positions, "fits.obj"));
  EXPECT_EQ(read_gltf_from_memory(to_gltf(fits, {}, true, 14), "fits", "").triangles.size(),
            fits.triangles.size());
}

TEST(GltfIo, IndicesBeyondTheVertexCountAreRefused) {
  TriMesh tet = test::tetrahedron();
  tet.positions.pop_back();  // the last vertex is referenced but gone
  std::ostringstream out;
  EXPECT_THROW(write_gltf(tet, {}, out), InvalidInput);
  // Crafted the other way: a valid file whose index buffer is rewritten to point past the vertices.
  const TriMesh full = test::tetrahedron();
  std::string bytes = to_gltf(full, {}, true);
  const std::size_t n = bytes.size();
  // The index buffer is the last 4·3·F bytes of the BIN chunk: set its last index to 0xFFFFFFFF.
  for (int k = 1; k <= 4; ++k) bytes[n - k] = '\xff';
  expect_refused(bytes, "beyond the");
}

// A glTF of one primitive in `mode` (4 triangles, 5 strip, 6 fan, 0 points) over float `positions`, indexed
// by uint16 `indices` (none when empty), its buffer a base64 data URI.
std::string primitive_gltf(const std::vector<Eigen::Vector3f>& positions,
                           const std::vector<std::uint16_t>& indices, int mode) {
  std::string bytes(positions.size() * 12 + indices.size() * 2, '\0');
  std::memcpy(bytes.data(), positions.data(), positions.size() * 12);
  if (!indices.empty()) std::memcpy(bytes.data() + positions.size() * 12, indices.data(), indices.size() * 2);
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = 0;
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) b64 += k <= n ? kAlphabet[v >> (18 - 6 * k) & 63] : '=';
  }
  Eigen::Vector3f lo = positions[0], hi = positions[0];
  for (const auto& p : positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  nlohmann::json j;
  j["asset"]["version"] = "2.0";
  j["buffers"] = {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + b64}}};
  j["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", positions.size() * 12}}};
  j["accessors"] = {{{"bufferView", 0},
                     {"componentType", 5126},
                     {"count", positions.size()},
                     {"type", "VEC3"},
                     {"min", {lo.x(), lo.y(), lo.z()}},
                     {"max", {hi.x(), hi.y(), hi.z()}}}};
  nlohmann::json prim = {{"attributes", {{"POSITION", 0}}}, {"mode", mode}};
  if (!indices.empty()) {
    j["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", positions.size() * 12}, {"byteLength", indices.size() * 2}});
    j["accessors"].push_back(
        {{"bufferView", 1}, {"componentType", 5123}, {"count", indices.size()}, {"type", "SCALAR"}});
    prim["indices"] = 1;
  }
  j["meshes"] = {{{"primitives", {prim}}}};
  j["nodes"] = {{{"mesh", 0}}};
  j["scenes"] = {{{"nodes", {0}}}};
  j["scene"] = 0;
  return j.dump();
}

// Every triangle's normal along +z (the winding of a strip's or fan's first triangle), none degenerate.
void expect_all_facing_up(const TriMesh& m) {
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d n =
        (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
    EXPECT_GT(n.z(), 1e-9) << t[0] << ' ' << t[1] << ' ' << t[2];
  }
}

// Strips and fans (glTF 2.0 §3.7.2.1), which exporters of older engines still write: split into triangles of
// one winding (a strip's odd triangles turned), the degenerate ones that join strips left out. They were
// skipped before, so a file of strips read as "no triangles".
TEST(GltfIo, StripsAndFansAreSplitIntoTrianglesOfOneWinding) {
  // A strip along −x: v_{2k} = (−k, 0, 0), v_{2k+1} = (−k, 1, 0), so its first triangle 0 1 2 is
  // counter-clockwise seen from +z.
  std::vector<Eigen::Vector3f> grid;
  for (int k = 0; k < 4; ++k) grid.emplace_back(-k, 0, 0), grid.emplace_back(-k, 1, 0);
  const std::vector<std::uint16_t> strip{0, 1, 2, 3, 4, 5, 6, 7};
  for (const bool indexed : {true, false}) {
    const TriMesh m = read_gltf_from_memory(
        primitive_gltf(grid, indexed ? strip : std::vector<std::uint16_t>{}, 5), "strip.gltf", "");
    EXPECT_EQ(m.triangles.size(), 6u) << indexed;
    expect_all_facing_up(m);
    double area = 0;
    for (const auto& t : m.triangles)
      area +=
          0.5 * (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm();
    EXPECT_NEAR(area, 3.0, 1e-12) << "the strip covers its 3 × 1 rectangle once";
  }
  // Two strips joined by repeated vertices (3 3 4 4): the four degenerate triangles are left out, and the
  // second strip's parity is its own again.
  std::vector<Eigen::Vector3f> two = {grid[0], grid[1], grid[2], grid[3]};
  for (int k = 0; k < 2; ++k) two.emplace_back(-5 - k, 0, 0), two.emplace_back(-5 - k, 1, 0);
  const TriMesh joined =
      read_gltf_from_memory(primitive_gltf(two, {0, 1, 2, 3, 3, 4, 4, 5, 6, 7}, 5), "joined.gltf", "");
  EXPECT_EQ(joined.triangles.size(), 4u);
  expect_all_facing_up(joined);
  // A fan around the origin, counter-clockwise, closed by repeating its first rim vertex.
  std::vector<Eigen::Vector3f> disc{{0, 0, 0}};
  for (int k = 0; k < 6; ++k)
    disc.emplace_back(static_cast<float>(std::cos(k * M_PI / 3)), static_cast<float>(std::sin(k * M_PI / 3)),
                      0.f);
  const TriMesh fan =
      read_gltf_from_memory(primitive_gltf(disc, {0, 1, 2, 3, 4, 5, 6, 1}, 6), "fan.gltf", "");
  EXPECT_EQ(fan.triangles.size(), 6u);
  expect_all_facing_up(fan);
  // Points (mode 0) are no surface: a file of only points has no triangles.
  expect_refused(primitive_gltf(disc, {}, 0), "no triangles");
  // A strip's indices are still checked against the vertices.
  try {
    read_gltf_from_memory(primitive_gltf(grid, {0, 1, 2, 9}, 5), "crafted.gltf", "");
    ADD_FAILURE() << "an index past the vertices was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("beyond the"), std::string::npos) << e.what();
  }
}

TEST(VertexNormals, AreUnitAndOutwardOnASphereAndDefinedForLooseVertices) {
  TriMesh sphere = test::sphere(2);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : sphere.positions) centre += p;
  centre /= static_cast<double>(sphere.positions.size());
  sphere.positions.emplace_back(5, 5, 5);  // referenced by no triangle
  const std::vector<Eigen::Vector3d> n = vertex_normals(sphere);
  ASSERT_EQ(n.size(), sphere.positions.size());
  for (std::size_t v = 0; v + 1 < n.size(); ++v) {
    EXPECT_NEAR(n[v].norm(), 1.0, 1e-12) << v;
    EXPECT_GT(n[v].dot((sphere.positions[v] - centre).normalized()), 0.9) << v;
  }
  EXPECT_EQ(n.back(), Eigen::Vector3d(0, 0, 1));
}

// write_mesh's glTF carries the vertex normals, so viewers shade it smoothly.
TEST(GltfIo, WriteMeshAddsVertexNormals) {
  const TriMesh cube = test::cube();
  std::ostringstream out;
  write_mesh(cube, out, MeshFormat::kGltf);
  const auto j = nlohmann::json::parse(out.str());
  const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attributes.contains("NORMAL"));
  EXPECT_EQ(j["accessors"][attributes["NORMAL"].get<int>()]["count"], cube.positions.size());
}

}  // namespace
}  // namespace geomip
