#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>

namespace geomip {
namespace {

std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string write_mesh_file(const std::string& dir, const std::string& name, const TriMesh& mesh, bool binary = true) {
  const std::string path = dir + "/" + name;
  std::ofstream out(path, std::ios::binary);
  WriteMeshOptions o;
  o.binary = binary;
  write_mesh(mesh, out, mesh_format_from_path(path), o);
  return path;
}

// Expects read_mesh(path) to throw InvalidInput whose message names the file and contains `problem`.
void expect_rejected(const std::string& path, const std::string& problem) {
  try {
    read_mesh(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const InvalidInput& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << "message '" << what << "' lacks '" << problem << "'";
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line expected: " << what;
  }
}

class MeshIo : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("mesh-io");
  void TearDown() override { std::filesystem::remove_all(dir_); }
};

TEST_F(MeshIo, RoundTripsEveryWritableFormatExactly) {
  const TriMesh mesh = test::float32(test::torus(12, 7));  // float32 data, as files hold
  for (const char* name : {"t.obj", "t.ply", "t.off"}) {
    for (bool binary : {true, false}) {
      const TriMesh back = read_mesh(write_mesh_file(dir_, name, mesh, binary));
      ASSERT_EQ(back.positions.size(), mesh.positions.size()) << name;
      ASSERT_EQ(back.triangles, mesh.triangles) << name;
      for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        ASSERT_EQ(back.positions[v], mesh.positions[v]) << name << " vertex " << v;
      }
    }
  }
}

// Vertex normals go out with the mesh in every text/binary format and the positions read back unchanged; a
// normal list of the wrong size is refused before anything is written.
TEST_F(MeshIo, WritesVertexNormalsAndRefusesAWrongCount) {
  const TriMesh mesh = test::tetrahedron();
  WriteMeshOptions o;
  for (const auto& n : vertex_normals(mesh)) o.vertex_normals.push_back(n.cast<float>());
  for (const MeshFormat f : {MeshFormat::kObj, MeshFormat::kPly, MeshFormat::kOff}) {
    std::ostringstream out;
    write_mesh(mesh, out, f, o);
    const TriMesh back = read_mesh_from_memory(out.str(), f, "normals");
    EXPECT_EQ(back.triangles, mesh.triangles);
    ASSERT_EQ(back.positions.size(), mesh.positions.size());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
      EXPECT_LT((back.positions[v] - mesh.positions[v]).norm(), 1e-6);
  }
  std::ostringstream obj;
  write_mesh(mesh, obj, MeshFormat::kObj, o);
  EXPECT_NE(obj.str().find("vn "), std::string::npos);
  o.vertex_normals.pop_back();
  std::ostringstream bad;
  EXPECT_THROW(write_mesh(mesh, bad, MeshFormat::kObj, o), InvalidInput);
  EXPECT_TRUE(bad.str().empty());
}

TEST_F(MeshIo, KeepsNonManifoldFacesAsRead) {
  // Three triangles on one edge: OpenMesh's own half-edge importer would drop one of them.
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  for (const char* name : {"nm.obj", "nm.ply", "nm.off"}) {
    const TriMesh back = read_mesh(write_mesh_file(dir_, name, m));
    EXPECT_EQ(back.triangles, m.triangles) << name;
    const TopologyReport r = analyze_topology(back);
    EXPECT_EQ(r.non_manifold_edges, 1u);
    EXPECT_FALSE(r.manifold);
  }
}

TEST_F(MeshIo, FacesWithARepeatedCornerAreReadAsWrittenInEveryFormat) {
  // OpenMesh's OBJ reader drops "f 1 1 2" and reads "f 1 2 1 3" as the triangle 1 2 3; PLY and OFF keep both
  // as written. Every format gives the file's faces, in order (fans of the polygons), so that `info` counts
  // the degenerate ones and `repair` removes them, instead of one format losing a face without a word.
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  const std::string obj = v + "f 1 2 3\nf 1 1 2\nf 1 2 1 3\nf -4 -2 -1\nf 2 2 2\nf 2 4 3\n";
  const std::string off =
      "OFF\n4 6 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 0 1\n4 0 1 0 2\n3 0 2 3\n3 1 1 1\n3 1 3 2\n";
  const std::vector<std::array<int, 3>> expected = {{0, 1, 2}, {0, 0, 1}, {0, 1, 0}, {0, 0, 2},
                                                    {0, 2, 3}, {1, 1, 1}, {1, 3, 2}};
  const TriMesh from_obj = read_mesh(write_text(dir_, "repeat.obj", obj));
  const TriMesh from_off = read_mesh(write_text(dir_, "repeat.off", off));
  EXPECT_EQ(from_obj.triangles, expected);
  EXPECT_EQ(from_off.triangles, expected);
  EXPECT_EQ(read_mesh(write_mesh_file(dir_, "repeat.ply", from_off)).triangles, expected);
  EXPECT_EQ(analyze_topology(from_obj).degenerate_faces, 4u);
  // A file without repeats reads as before (the fan of a polygon, nothing added).
  EXPECT_EQ(read_mesh(write_text(dir_, "plain.obj", v + "f 1 2 3 4\n")).triangles.size(), 2u);
}

TEST_F(MeshIo, TriangulatesPolygonsAndReadsStl) {
  const auto quad = write_text(dir_, "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nf 1 2 3 5 4\n");
  const TriMesh q = read_mesh(quad);
  EXPECT_EQ(q.triangles.size(), 3u);
  const auto stl = write_text(dir_, "two.stl",
                              "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                              "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
                              "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
  const TriMesh s = read_mesh(stl);
  EXPECT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(analyze_topology(s).vertices, 4u);  // shared corners are merged by position
}

TEST_F(MeshIo, RejectsBadInputWithOneClearLine) {
  expect_rejected(dir_ + "/missing.obj", "no such file");
  expect_rejected(write_text(dir_, "empty.obj", ""), "empty file");
  expect_rejected(write_text(dir_, "nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), "NaN");
  expect_rejected(write_text(dir_, "inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"), "NaN or infinite");
  expect_rejected(write_text(dir_, "oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
                  "line 4: face references vertex 9");
  expect_rejected(write_text(dir_, "nan.off", "OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n"), "NaN");
  expect_rejected(write_text(dir_, "oob.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "references vertex 3");
  expect_rejected(write_text(dir_, "short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), "truncated OFF");
  expect_rejected(write_text(dir_, "lying.off", "OFF\n99999999 1 0\n0 0 0\n"), "impossible");
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_rejected(write_text(dir_, "nan.ply", ply_head + "0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n"), "NaN");
  expect_rejected(write_text(dir_, "short_ascii.ply", ply_head + "0 0 0\n1 0 0\n"), "truncated PLY");
  expect_rejected(write_text(dir_, "mesh.xyz", "1 2 3\n"), "unsupported mesh format");
  expect_rejected(dir_, "is a directory");  // the kind of file is checked before its extension
  std::filesystem::create_directory(dir_ + "/dir.obj");
  expect_rejected(dir_ + "/dir.obj", "is a directory");
}

TEST_F(MeshIo, RefusesNonRegularFilesUnreadAndBoundsTheSize) {
  // Devices, FIFOs and directories are refused before a byte is read: /dev/zero never ends, a FIFO blocks.
  expect_rejected("/dev/zero", "is a device, not a regular file");
  std::filesystem::create_symlink("/dev/zero", dir_ + "/zero.obj");
  expect_rejected(dir_ + "/zero.obj", "is a device, not a regular file");
  ASSERT_EQ(::mkfifo((dir_ + "/pipe.obj").c_str(), 0600), 0);
  expect_rejected(dir_ + "/pipe.obj", "FIFO");
  std::filesystem::create_directory(dir_ + "/dir.ply");
  expect_rejected(dir_ + "/dir.ply", "is a directory");
  // Files above ReadMeshOptions::max_file_bytes are refused by their size (4 GiB by default).
  const std::string tet = write_mesh_file(dir_, "tet.obj", test::tetrahedron());
  const auto size = std::filesystem::file_size(tet);
  ReadMeshOptions small;
  small.max_file_bytes = size - 1;
  try {
    read_mesh(tet, small);
    ADD_FAILURE() << "a file above max_file_bytes was read";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("more than geomip reads"), std::string::npos) << e.what();
  }
  small.max_file_bytes = size;
  EXPECT_EQ(read_mesh(tet, small).triangles.size(), 4u);
  EXPECT_GE(ReadMeshOptions{}.max_file_bytes, std::uint64_t{1} << 32);
}

TEST_F(MeshIo, ObjFaceIndicesThatDoNotFitAreErrorsNamingTheLine) {
  const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // OpenMesh would drop this face silently (the index does not fit an int) and read an empty mesh as fine.
  expect_rejected(write_text(dir_, "big.obj", head + "f 1 2 99999999999999999999\n"),
                  "line 4: face vertex index '99999999999999999999' is out of range");
  expect_rejected(write_text(dir_, "big2.obj", head + "f 1 2 3\nf 1 2 2147483648\n"),
                  "line 5: face vertex index");
  expect_rejected(write_text(dir_, "bigvt.obj", head + "vt 0 0\nf 1/1 2/1 3/99999999999\n"),
                  "line 5: face texture coordinate index");
  expect_rejected(write_text(dir_, "zero.obj", head + "f 1 2 0\n"),
                  "line 4: face corner '0' has vertex index 0");
  expect_rejected(write_text(dir_, "rel.obj", head + "f -1 -2 -4\n"), "line 4: face references vertex -4");
  // Forward references are legal OBJ: checked against the whole file's vertex count.
  EXPECT_EQ(read_mesh(write_text(dir_, "fwd.obj", "f 1 2 3\n" + head)).triangles.size(), 1u);
  EXPECT_EQ(read_mesh(write_text(dir_, "neg.obj", head + "f -3 -2 -1\n")).triangles.size(), 1u);
}

TEST_F(MeshIo, CoordinatesBeyondFloatRangeAreErrorsNamingTheLine) {
  // OpenMesh reads floats: 1e39 used to vanish and surface as "face 0 references vertex 0, but the file has
  // 0".
  expect_rejected(write_text(dir_, "far.obj", "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
                  "line 1: vertex coordinate 1e+39 is out of range");
  expect_rejected(write_text(dir_, "far.off", "OFF\n3 1 0\n0 0 0\n1 -4e38 0\n0 1 0\n3 0 1 2\n"),
                  "line 4: vertex 1 coordinate -4e+38 is out of range");
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_rejected(write_text(dir_, "far.ply", ply_head + "0 0 0\n1 0 0\n0 1 1e39\n3 0 1 2\n"),
                  "line 12: vertex 2 coordinate 1e+39 is out of range");
  expect_rejected(write_text(dir_, "far.stl",
                             "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e39 0 0\n"
                             "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"),
                  "line 5: vertex coordinate 1e+39 is out of range");
  // Binary PLY of doubles: a finite double beyond float range is caught after parsing.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const double xyz[9] = {1e300, 0, 0, 1, 0, 0, 0, 1, 0};
  bin.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  const int face[3] = {0, 1, 2};
  bin.push_back('\3');
  bin.append(reinterpret_cast<const char*>(face), sizeof face);
  expect_rejected(write_text(dir_, "far_bin.ply", bin), "out of range");
  // The largest float itself is fine.
  EXPECT_EQ(
      read_mesh(write_text(dir_, "max.obj", "v 3.4e38 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).triangles.size(),
      1u);
}

TEST_F(MeshIo, ReadsFromMemoryExactlyAsFromAFile) {
  for (const char* name : {"t.obj", "t.ply", "t.off"}) {
    const std::string path = write_mesh_file(dir_, name, test::torus(6, 4));
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const TriMesh a = read_mesh(path);
    const TriMesh b = read_mesh_from_memory(bytes, mesh_format_from_path(path), "memory");
    EXPECT_EQ(a.triangles, b.triangles) << name;
    EXPECT_EQ(a.positions, b.positions) << name;
  }
  try {
    read_mesh_from_memory("v 0 0 0\nf 1 1 9\n", MeshFormat::kObj, "bytes.obj");
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bytes.obj: line 2", 0), 0u) << e.what();
  }
  EXPECT_THROW(read_mesh_from_memory("", MeshFormat::kPly, "empty"), InvalidInput);
}

TEST_F(MeshIo, RejectsTruncatedBinaryPly) {
  const std::string full = write_mesh_file(dir_, "full.ply", test::torus(20, 10));
  std::ifstream in(full, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::size_t header = bytes.find("end_header\n") + 11;
  for (std::size_t cut : {header + 5, bytes.size() / 2, bytes.size() - 1}) {
    expect_rejected(write_text(dir_, "cut.ply", bytes.substr(0, cut)), "truncated PLY");
  }
  // A binary NaN coordinate passes the parser and must be caught after it.
  std::string nan_bytes = bytes;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Vertices are written as doubles or floats depending on the writer; overwrite the first coordinate either way.
  const bool doubles = bytes.find("property double x") != std::string::npos;
  if (doubles) {
    const double d = nan;
    nan_bytes.replace(header, sizeof d, reinterpret_cast<const char*>(&d), sizeof d);
  } else {
    nan_bytes.replace(header, sizeof nan, reinterpret_cast<const char*>(&nan), sizeof nan);
  }
  expect_rejected(write_text(dir_, "nan_bin.ply", nan_bytes), "NaN");
}

// A PLY of a tetrahedron whose face list is declared `list COUNT INDEX vertex_indices`: ascii, or binary
// little endian with float coordinates and the list's length and indices in those types.
std::string tetrahedron_ply(const TriMesh& tet, const std::string& count, const std::string& index,
                            bool binary) {
  std::ostringstream out;
  out << std::setprecision(9);  // float round trip
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\nelement vertex "
      << tet.positions.size() << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
      << tet.triangles.size() << "\nproperty list " << count << " " << index
      << " vertex_indices\nend_header\n";
  const auto size_of = [](const std::string& type) -> std::size_t {
    for (const char* one : {"char", "uchar", "int8", "uint8"})
      if (type == one) return 1;
    for (const char* two : {"short", "ushort", "int16", "uint16"})
      if (type == two) return 2;
    return 4;
  };
  const auto put = [&](std::uint32_t value, std::size_t bytes) {  // little endian
    for (std::size_t k = 0; k < bytes; ++k) out.put(static_cast<char>(value >> (8 * k) & 0xff));
  };
  for (const auto& p : tet.positions) {
    for (int c = 0; c < 3; ++c) {
      const auto f = static_cast<float>(p[c]);
      if (binary) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &f, 4);
        put(bits, 4);
      } else {
        out << f << (c < 2 ? " " : "\n");
      }
    }
  }
  for (const auto& t : tet.triangles) {
    if (binary) {
      put(3, size_of(count));
      for (int v : t) put(static_cast<std::uint32_t>(v), size_of(index));
    } else {
      out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    }
  }
  return out.str();
}

// Every PLY type name may type a list's length; OpenMesh's header parser took only uchar, uint8, uint16 and
// int there and refused the rest ("cannot parse as a .ply mesh"). Now each reads the same faces in ascii;
// in binary, where OpenMesh's reader has no 2-byte lengths or indices, those are refused naming the type.
TEST_F(MeshIo, PlyListsReadWithEveryLengthTypeName) {
  const TriMesh tet = test::float32(test::tetrahedron());
  for (const char* count : {"char", "uchar", "short", "ushort", "int", "uint", "int8", "uint8", "int16",
                            "uint16", "int32", "uint32"}) {
    for (bool binary : {false, true}) {
      const std::string name = std::string(count) + (binary ? "_bin.ply" : ".ply");
      const std::string path = write_text(dir_, name, tetrahedron_ply(tet, count, "int", binary));
      const bool two_bytes = std::string(count).find("short") != std::string::npos ||
                             std::string(count).find("16") != std::string::npos;
      if (binary && two_bytes) {
        expect_rejected(path, std::string("2-byte length type '") + count + "'");
        continue;
      }
      try {
        const TriMesh back = read_mesh(path);
        EXPECT_EQ(back.triangles, tet.triangles) << name;
        EXPECT_EQ(back.positions, tet.positions) << name;
      } catch (const InvalidInput& e) {
        ADD_FAILURE() << name << ": " << e.what();
      }
    }
  }
  // Index types: 1- and 4-byte ones in binary; 2-byte ones in ascii only.
  for (const char* index : {"uchar", "char", "uint", "int32", "ushort", "short"}) {
    for (bool binary : {false, true}) {
      const std::string name = std::string("index_") + index + (binary ? "_bin.ply" : ".ply");
      const std::string path = write_text(dir_, name, tetrahedron_ply(tet, "uchar", index, binary));
      if (binary && std::string(index).find("short") != std::string::npos) {
        expect_rejected(path, std::string("2-byte type '") + index + "'");
        continue;
      }
      EXPECT_EQ(read_mesh(path).triangles, tet.triangles) << name;
    }
  }
}

// OpenMesh's OBJ and PLY readers round coordinates to float: a mesh a million units from its origin (a
// georeferenced scan) lost everything below 0.06 units, and a 1-unit cube at 10^8 read as 12 degenerate
// faces. OBJ and PLY (ascii or binary double properties) are now read as written; a UTF-8 byte-order mark
// before an OBJ's first line no longer hides its first vertex.
TEST_F(MeshIo, ObjAndPlyCoordinatesAreReadAsWritten) {
  const double offset = 123456789.0123;  // float spacing there: 8
  const std::vector<Eigen::Vector3d> corners = {{offset, 0.5, -offset},
                                                {offset + 1.25, 0.5, -offset},
                                                {offset, 1.75, -offset},
                                                {offset, 0.5, -offset + 0.001}};
  std::ostringstream obj, ply;
  obj.precision(17);
  ply.precision(17);
  ply << "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
         "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : corners) {
    obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
    ply << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  obj << "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  ply << "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  // Binary little-endian doubles.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n"
      "property double y\nproperty double z\nelement face 4\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (const auto& p : corners)
    for (int c = 0; c < 3; ++c) bin.append(reinterpret_cast<const char*>(&p[c]), sizeof(double));
  for (const std::array<int, 3>& t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    bin += static_cast<char>(3);
    for (int v : t) bin.append(reinterpret_cast<const char*>(&v), sizeof(int));
  }
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"far.obj", obj.str()},
                                   {"bom.obj", "\xEF\xBB\xBF" + obj.str()},
                                   {"far.ply", ply.str()},
                                   {"far_bin.ply", bin}}) {
    const TriMesh m = read_mesh(write_text(dir_, name, text));
    ASSERT_EQ(m.positions.size(), corners.size()) << name;
    for (std::size_t v = 0; v < corners.size(); ++v)
      EXPECT_EQ(m.positions[v], corners[v]) << name << " " << v;
    EXPECT_EQ(m.triangles.size(), 4u) << name;
  }
  expect_rejected(write_text(dir_, "noz.ply",
                             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n1 0\n"
                             "0 1\n3 0 1 2\n"),
                  "no property 'z'");
}

// Geomview's OFF allows comments from '#' to the end of a line; they were refused ("the vertex count '#' is
// not a count"). Comment lines anywhere after the magic and trailing comments read as if absent; a problem
// after a comment still names its line.
TEST_F(MeshIo, OffCommentsAreSkipped) {
  const std::string plain = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const TriMesh expected = read_mesh(write_text(dir_, "plain.off", plain));
  const std::string commented =
      "OFF # a tetrahedron\n# made by hand\n\n4 4 0 # vertices faces edges\n#\n0 0 0\n1 0 0 # x\n"
      "  # indented\n0 1 0\n0 0 1\n# faces\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3 # last\n# end";
  const TriMesh back = read_mesh(write_text(dir_, "commented.off", commented));
  EXPECT_EQ(back.triangles, expected.triangles);
  EXPECT_EQ(back.positions, expected.positions);
  expect_rejected(write_text(dir_, "bad.off", "OFF\n# one\n# two\n4 4 0\n0 0 0\n1 0 zero\n"),
                  "line 6: malformed vertex 1");
}

TEST_F(MeshIo, GarbageAndMutatedFilesNeverCrashOrHang) {
  // Random bytes, and valid files with random bytes overwritten: each read either succeeds with in-range
  // indices and finite coordinates, or throws InvalidInput. A crash or hang fails the test (ctest timeout).
  // GEOMIP_FUZZ_TRIALS / GEOMIP_FUZZ_SEED widen the search by hand; CI runs the fixed default.
  const char* trials_env = std::getenv("GEOMIP_FUZZ_TRIALS");
  const char* seed_env = std::getenv("GEOMIP_FUZZ_SEED");
  const int trials = trials_env ? std::atoi(trials_env) : 300;
  std::mt19937 rng(seed_env ? static_cast<unsigned>(std::atoi(seed_env)) : 1234u);
  const TriMesh mesh = test::torus(8, 5);
  std::vector<std::string> seeds;
  for (const char* name : {"s.obj", "s.ply", "s.off"}) {
    for (bool binary : {true, false}) {
      std::ifstream in(write_mesh_file(dir_, name, mesh, binary), std::ios::binary);
      seeds.emplace_back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }
  }
  // STL is read but not written by geomip: build an ascii and a binary one here.
  std::ostringstream ascii_stl, binary_stl;
  ascii_stl << "solid torus\n";
  binary_stl << std::string(80, ' ');
  const auto facets = static_cast<std::uint32_t>(mesh.triangles.size());
  binary_stl.write(reinterpret_cast<const char*>(&facets), 4);
  for (const auto& t : mesh.triangles) {
    ascii_stl << "facet normal 0 0 0\nouter loop\n";
    float record[12] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f p = mesh.positions[t[k]].cast<float>();
      ascii_stl << "vertex " << p.x() << " " << p.y() << " " << p.z() << "\n";
      for (int c = 0; c < 3; ++c) record[3 + 3 * k + c] = p[c];
    }
    ascii_stl << "endloop\nendfacet\n";
    binary_stl.write(reinterpret_cast<const char*>(record), sizeof record);
    binary_stl.write("\0\0", 2);
  }
  ascii_stl << "endsolid torus\n";
  seeds.push_back(ascii_stl.str());
  seeds.push_back(binary_stl.str());
  ASSERT_EQ(read_mesh(write_text(dir_, "a.stl", seeds[6])).triangles.size(), mesh.triangles.size());
  ASSERT_EQ(read_mesh(write_text(dir_, "b.stl", seeds[7])).triangles.size(), mesh.triangles.size());
  const char* exts[] = {"obj", "obj", "ply", "ply", "off", "off", "stl", "stl"};
  int accepted = 0, rejected = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const int s = trial % 8;
    std::string bytes = seeds[s];
    if (trial % 5 == 0) {
      bytes.assign(1 + rng() % 2000, '\0');
      for (auto& c : bytes) c = static_cast<char>(rng());
    } else {
      const int flips = 1 + rng() % 8;
      for (int k = 0; k < flips; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng());
      if (trial % 3 == 0) bytes.resize(rng() % bytes.size());
    }
    const std::string path = write_text(dir_, std::string("m.") + exts[s], bytes);
    try {
      const TriMesh m = read_mesh(path);
      for (const auto& t : m.triangles) {
        for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < m.positions.size());
      }
      for (const auto& p : m.positions) ASSERT_TRUE(p.allFinite());
      ++accepted;
    } catch (const InvalidInput&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, trials / 6);  // the mutations do hit the validators
  EXPECT_GT(accepted, 0);   // and harmless ones (e.g. in a coordinate digit) still read
}

TEST(MeshIoFormat, ExtensionsAreCaseInsensitive) {
  EXPECT_EQ(mesh_format_from_path("a/B.OBJ"), MeshFormat::kObj);
  EXPECT_EQ(mesh_format_from_path("x.Ply"), MeshFormat::kPly);
  EXPECT_EQ(mesh_format_from_path("x.off"), MeshFormat::kOff);
  EXPECT_EQ(mesh_format_from_path("x.stl"), MeshFormat::kStl);
  EXPECT_EQ(mesh_format_from_path("x.gltf"), MeshFormat::kGltf);
  EXPECT_EQ(mesh_format_from_path("x.GLB"), MeshFormat::kGlb);
  EXPECT_THROW(mesh_format_from_path("x.fbx"), InvalidInput);
  std::ostringstream out;
  EXPECT_THROW(write_mesh(test::tetrahedron(), out, MeshFormat::kStl), InvalidInput);
  EXPECT_THROW(write_mesh(TriMesh{}, out, MeshFormat::kObj), InvalidInput);
}

// glTF goes through the same entry points as the other formats: a file written by write_mesh() reads back
// with the same triangles and float-exact positions, from .glb and from .gltf.
TEST_F(MeshIo, GltfAndGlbRoundTripThroughReadMesh) {
  const std::string& dir = dir_;
  const TriMesh torus = test::float32(test::torus(9, 5));  // glTF stores float32
  for (const char* name : {"t.glb", "t.gltf"}) {
    const std::string path = write_mesh_file(dir, name, torus);
    const TriMesh back = read_mesh(path);
    EXPECT_EQ(back.triangles, torus.triangles) << name;
    ASSERT_EQ(back.positions.size(), torus.positions.size()) << name;
    for (std::size_t v = 0; v < back.positions.size(); ++v)
      EXPECT_EQ(back.positions[v], torus.positions[v]) << name << " vertex " << v;
  }
  expect_rejected(write_text(dir, "bad.glb", "glTF not really"), "not a readable glTF");
}

}  // namespace
}  // namespace geomip
