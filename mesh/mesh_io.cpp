#include "mesh/mesh_io.h"

#include "mesh/errors.h"
#include "mesh/gltf_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/exporter/BaseExporter.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/Mesh/BaseKernel.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <mutex>
#include <ostream>
#include <sstream>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace geomip {
namespace {

using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;
using OpenMesh::Vec2f;
using OpenMesh::Vec3d;
using OpenMesh::Vec3f;
using OpenMesh::Vec3uc;
using OpenMesh::Vec3ui;
using OpenMesh::Vec4f;
using OpenMesh::Vec4uc;
using OpenMesh::Vec4ui;
using StatusInfo = OpenMesh::Attributes::StatusInfo;

// OpenMesh's readers report problems on its own log streams; geomip reports them itself, once.
void silence_openmesh() {
  static const bool done = [] {
    omerr().disable();
    omlog().disable();
    omout().disable();
    return true;
  }();
  (void)done;
}

// OpenMesh's IOManager is one shared object whose readers and writers keep state, and SilencedCerr swaps
// std::cerr's buffer: one OpenMesh read or write at a time (convert builds several layouts on threads).
std::mutex& openmesh_mutex() {
  static std::mutex m;
  return m;
}

// Some of OpenMesh's readers also write to std::cerr directly (the OFF reader's "Error in file format"):
// while one parses, std::cerr goes nowhere, so that a tool's error stays the one line it prints itself.
class SilencedCerr {
 public:
  SilencedCerr() : saved_(std::cerr.rdbuf(nullptr)) {}
  ~SilencedCerr() {
    std::cerr.rdbuf(saved_);
    std::cerr.clear();
  }
  SilencedCerr(const SilencedCerr&) = delete;
  SilencedCerr& operator=(const SilencedCerr&) = delete;

 private:
  std::streambuf* saved_;
};

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

const char* extension_of(MeshFormat f) {
  switch (f) {
    case MeshFormat::kObj: return "obj";
    case MeshFormat::kPly: return "ply";
    case MeshFormat::kOff: return "off";
    case MeshFormat::kStl: return "stl";
    case MeshFormat::kGltf: return "gltf";
    case MeshFormat::kGlb: return "glb";
  }
  return "";
}

// Records vertices and polygons exactly as the reader delivers them. Face indices are kept raw (even out of
// range) and validated afterwards, so the error message can say what is wrong.
class RecordingImporter final : public OpenMesh::IO::BaseImporter {
 public:
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> polygons;

  VertexHandle add_vertex(const Vec3f& p) override { return add_vertex(Vec3d(p[0], p[1], p[2])); }
  VertexHandle add_vertex(const Vec3d& p) override {
    points.emplace_back(p[0], p[1], p[2]);
    return VertexHandle(static_cast<int>(points.size()) - 1);
  }
  VertexHandle add_vertex() override { return add_vertex(Vec3d(0, 0, 0)); }
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(const VHandles& indices) override {
    std::vector<int> poly;
    poly.reserve(indices.size());
    for (const auto& vh : indices) poly.push_back(vh.idx());
    polygons.push_back(std::move(poly));
    return FaceHandle(static_cast<int>(polygons.size()) - 1);
  }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void set_point(VertexHandle vh, const Vec3f& p) override {
    if (vh.idx() >= 0 && static_cast<std::size_t>(vh.idx()) < points.size()) points[vh.idx()] = {p[0], p[1], p[2]};
  }
  size_t n_vertices() const override { return points.size(); }
  size_t n_faces() const override { return polygons.size(); }
  size_t n_edges() const override { return 0; }
  bool is_triangle_mesh() const override { return false; }
  void reserve(unsigned int nv, unsigned int, unsigned int nf) override {
    // Headers can lie (garbage or hostile files): cap the reservation, the vectors grow as needed anyway.
    points.reserve(std::min(nv, 1u << 22));
    polygons.reserve(std::min(nf, 1u << 22));
  }

  // Attributes geomip does not use.
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const Vec3f&) override {}
  void set_normal(VertexHandle, const Vec3d&) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_texcoord(VertexHandle, const Vec2f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_color(OpenMesh::EdgeHandle, const Vec3uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const Vec4uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const Vec3f&) override {}
  void set_color(OpenMesh::EdgeHandle, const Vec4f&) override {}
  void set_status(OpenMesh::EdgeHandle, const StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
};

// Presents a TriMesh to OpenMesh's writers without building a half-edge structure (which would drop
// non-manifold faces).
class TriMeshExporter final : public OpenMesh::IO::BaseExporter {
 public:
  explicit TriMeshExporter(const TriMesh& mesh, const std::vector<Eigen::Vector3f>* normals = nullptr)
      : mesh_(mesh), normals_(normals) {}

  Vec3f point(VertexHandle vh) const override {
    const auto& p = mesh_.positions[vh.idx()];
    return Vec3f(float(p.x()), float(p.y()), float(p.z()));
  }
  Vec3d pointd(VertexHandle vh) const override {
    const auto& p = mesh_.positions[vh.idx()];
    return Vec3d(p.x(), p.y(), p.z());
  }
  bool is_point_double() const override { return true; }
  unsigned int get_vhandles(FaceHandle fh, std::vector<VertexHandle>& vhandles) const override {
    const auto& t = mesh_.triangles[fh.idx()];
    vhandles = {VertexHandle(t[0]), VertexHandle(t[1]), VertexHandle(t[2])};
    return 3;
  }
  Vec3d normald(FaceHandle fh) const override {
    const auto& t = mesh_.triangles[fh.idx()];
    Eigen::Vector3d n = (mesh_.positions[t[1]] - mesh_.positions[t[0]])
                            .cross(mesh_.positions[t[2]] - mesh_.positions[t[0]]);
    const double len = n.norm();
    if (len > 0) n /= len;
    return Vec3d(n.x(), n.y(), n.z());
  }
  Vec3f normal(FaceHandle fh) const override {
    const Vec3d n = normald(fh);
    return Vec3f(float(n[0]), float(n[1]), float(n[2]));
  }
  size_t n_vertices() const override { return mesh_.positions.size(); }
  size_t n_faces() const override { return mesh_.triangles.size(); }
  size_t n_edges() const override { return 0; }
  bool is_triangle_mesh() const override { return true; }
  // The PLY writer walks the kernel's custom properties unconditionally: give it an empty kernel.
  const OpenMesh::BaseKernel* kernel() override { return &empty_kernel_; }

  // Vertex normals when given (WriteMeshOptions::vertex_normals), else none.
  Vec3f normal(VertexHandle vh) const override {
    if (normals_ == nullptr) return Vec3f(0, 0, 0);
    const Eigen::Vector3f& n = (*normals_)[static_cast<std::size_t>(vh.idx())];
    return Vec3f(n.x(), n.y(), n.z());
  }
  Vec3d normald(VertexHandle vh) const override {
    const Vec3f n = normal(vh);
    return Vec3d(n[0], n[1], n[2]);
  }
  bool is_normal_double() const override { return false; }
  bool has_vertex_normals() const override { return normals_ != nullptr; }

  // Attributes geomip does not write.
  Vec3uc color(VertexHandle) const override { return Vec3uc(0, 0, 0); }
  Vec4uc colorA(VertexHandle) const override { return Vec4uc(0, 0, 0, 0); }
  Vec3ui colori(VertexHandle) const override { return Vec3ui(0, 0, 0); }
  Vec4ui colorAi(VertexHandle) const override { return Vec4ui(0, 0, 0, 0); }
  Vec3f colorf(VertexHandle) const override { return Vec3f(0, 0, 0); }
  Vec4f colorAf(VertexHandle) const override { return Vec4f(0, 0, 0, 0); }
  Vec2f texcoord(VertexHandle) const override { return Vec2f(0, 0); }
  Vec2f texcoord(HalfedgeHandle) const override { return Vec2f(0, 0); }
  StatusInfo status(VertexHandle) const override { return StatusInfo(); }
  HalfedgeHandle getHeh(FaceHandle, VertexHandle) const override { return HalfedgeHandle(); }
  unsigned int get_face_texcoords(std::vector<Vec2f>&) const override { return 0; }
  Vec3uc color(FaceHandle) const override { return Vec3uc(0, 0, 0); }
  Vec4uc colorA(FaceHandle) const override { return Vec4uc(0, 0, 0, 0); }
  Vec3ui colori(FaceHandle) const override { return Vec3ui(0, 0, 0); }
  Vec4ui colorAi(FaceHandle) const override { return Vec4ui(0, 0, 0, 0); }
  Vec3f colorf(FaceHandle) const override { return Vec3f(0, 0, 0); }
  Vec4f colorAf(FaceHandle) const override { return Vec4f(0, 0, 0, 0); }
  StatusInfo status(FaceHandle) const override { return StatusInfo(); }
  Vec3uc color(OpenMesh::EdgeHandle) const override { return Vec3uc(0, 0, 0); }
  Vec4uc colorA(OpenMesh::EdgeHandle) const override { return Vec4uc(0, 0, 0, 0); }
  Vec3ui colori(OpenMesh::EdgeHandle) const override { return Vec3ui(0, 0, 0); }
  Vec4ui colorAi(OpenMesh::EdgeHandle) const override { return Vec4ui(0, 0, 0, 0); }
  Vec3f colorf(OpenMesh::EdgeHandle) const override { return Vec3f(0, 0, 0); }
  Vec4f colorAf(OpenMesh::EdgeHandle) const override { return Vec4f(0, 0, 0, 0); }
  StatusInfo status(OpenMesh::EdgeHandle) const override { return StatusInfo(); }
  int get_halfedge_id(VertexHandle) override { return -1; }
  int get_halfedge_id(FaceHandle) override { return -1; }
  int get_next_halfedge_id(HalfedgeHandle) override { return -1; }
  int get_to_vertex_id(HalfedgeHandle) override { return -1; }
  int get_face_id(HalfedgeHandle) override { return -1; }
  StatusInfo status(HalfedgeHandle) const override { return StatusInfo(); }

 private:
  const TriMesh& mesh_;
  const std::vector<Eigen::Vector3f>* normals_;
  OpenMesh::BaseKernel empty_kernel_;
};

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InvalidInput(path + ": " + problem);
}

// A read-only stream over bytes in memory (std::spanstream is C++23). read_mesh() reads a file once, with a
// size bound, and every validator and OpenMesh's reader parse that copy: no second open of a path that could
// have changed into a FIFO or grown meanwhile.
class MemoryBuffer final : public std::streambuf {
 public:
  explicit MemoryBuffer(std::string_view bytes) {
    char* begin = const_cast<char*>(bytes.data());  // never written: no put area, no putback into it
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type size = egptr() - eback();
    const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : size;
    if (off < -base || off > size - base) return pos_type(off_type(-1));
    setg(eback(), eback() + base + off, egptr());
    return pos_type(base + off);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
  int_type pbackfail(int_type) override { return traits_type::eof(); }
};

class MemoryStream final : public std::istream {
 public:
  explicit MemoryStream(std::string_view bytes) : std::istream(nullptr), buffer_(bytes) { rdbuf(&buffer_); }

 private:
  MemoryBuffer buffer_;
};

// A read-only stream over two byte ranges, one after the other (a rewritten header, then the file's data)
// without copying the second.
class JoinedBuffer final : public std::streambuf {
 public:
  JoinedBuffer(std::string_view first, std::string_view second) : first_(first), second_(second) {
    seek_to(0);
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (in_first_ && !second_.empty()) {
      seek_to(static_cast<off_type>(first_.size()));
      return traits_type::to_int_type(*gptr());
    }
    return traits_type::eof();
  }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const auto size = static_cast<off_type>(first_.size() + second_.size());
    const off_type here = (in_first_ ? 0 : static_cast<off_type>(first_.size())) + (gptr() - eback());
    const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? here : size;
    if (off < -base || off > size - base) return pos_type(off_type(-1));
    seek_to(base + off);
    return pos_type(base + off);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
  int_type pbackfail(int_type) override { return traits_type::eof(); }

 private:
  void seek_to(off_type pos) {
    const auto first_size = static_cast<off_type>(first_.size());
    in_first_ = pos < first_size;
    const std::string_view part = in_first_ ? first_ : second_;
    char* begin = const_cast<char*>(part.data());  // never written
    setg(begin, begin + (in_first_ ? pos : pos - first_size), begin + part.size());
  }

  std::string_view first_, second_;
  bool in_first_ = true;
};

class JoinedStream final : public std::istream {
 public:
  JoinedStream(std::string_view first, std::string_view second)
      : std::istream(nullptr), buffer_(first, second) {
    rdbuf(&buffer_);
  }

 private:
  JoinedBuffer buffer_;
};

// Coordinates are read as 32-bit floats (OpenMesh's text readers, TriMesh consumers): a finite double beyond
// ±FLT_MAX would become infinite, or make the reader drop the vertex (and the error surface as a wrong
// index).
constexpr double kMaxCoordinate = std::numeric_limits<float>::max();

// "" when `v` is a usable coordinate, else the problem, starting with `vertex` ("vertex 12", "vertex").
std::string coordinate_problem(double v, const std::string& vertex) {
  if (!std::isfinite(v)) return vertex + " has a NaN or infinite coordinate";
  if (std::fabs(v) > kMaxCoordinate) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return vertex + " coordinate " + text + " is out of range (beyond ±3.4e38, the 32-bit float range)";
  }
  return {};
}

// PLY header, parsed to walk the data the way OpenMesh's reader will, before it does: that reader trusts
// every count (a list length of 4e9 in a corrupt file is 4e9 push_backs), reads an unknown list property as
// one value (so everything after it is misaligned), and reads past the end of a short binary file.
enum class PlyType { kChar, kUchar, kShort, kUshort, kInt, kUint, kFloat, kDouble };

struct PlyProperty {
  std::string name;
  std::string declaration;         // "float x", "list uchar int vertex_indices": the tokens after "property"
  PlyType type = PlyType::kFloat;  // of the value, or of a list's items
  PlyType count_type = PlyType::kUchar;  // of a list's length
  bool list = false;
};

// The name OpenMesh's reader takes for a value type (it knows every PLY name for values, "char" as well as
// "int8"), one per type.
const char* ply_type_name(PlyType t) {
  switch (t) {
    case PlyType::kChar:
      return "char";
    case PlyType::kUchar:
      return "uchar";
    case PlyType::kShort:
      return "short";
    case PlyType::kUshort:
      return "ushort";
    case PlyType::kInt:
      return "int";
    case PlyType::kUint:
      return "uint";
    case PlyType::kFloat:
      return "float";
    case PlyType::kDouble:
      return "double";
  }
  return "uchar";
}

int ply_size(PlyType t);

// The name OpenMesh's reader takes for a list's length of type `t`. Its header parser knows only "uint8",
// "uint16", "uchar" and "int" there (it refuses the whole file for "char", "short", "ushort", "uint", ...);
// validate_ply() has checked every length to be from 0 to the vertex count, so reading a signed length as
// unsigned of the same size, or a 4-byte unsigned one as int, reads the same numbers. (Its binary reader has
// no 2-byte length: parse_ply_header() refuses those.)
const char* ply_count_type_name(PlyType t) {
  switch (ply_size(t)) {
    case 1:
      return "uchar";
    case 2:
      return "uint16";
    default:
      return "int";
  }
}

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool binary = false;
  bool big_endian = false;
  std::uint64_t header_bytes = 0;
  std::vector<PlyElement> elements;  // in file order

  // The header as OpenMesh's reader is given it: what was validated and nothing else. Its own header parser
  // reads tokens, not lines (a stray word on a line, an obj_info text, white space before end_header would
  // each make it see other elements or start the binary data elsewhere than this check did).
  std::string canonical() const {
    std::string out = "ply\nformat ";
    out += binary ? (big_endian ? "binary_big_endian" : "binary_little_endian") : "ascii";
    out += " 1.0\n";
    for (const auto& e : elements) {
      out += "element " + e.name + " " + std::to_string(e.count) + "\n";
      for (const auto& p : e.properties) {
        out += "property ";
        if (p.list) {
          out += "list ";
          out += ply_count_type_name(p.count_type);
          out += ' ';
        }
        out += ply_type_name(p.type);
        out += ' ' + p.name + "\n";
      }
    }
    return out + "end_header\n";
  }
};

bool ply_type(const std::string& t, PlyType& out) {
  if (t == "char" || t == "int8")
    out = PlyType::kChar;
  else if (t == "uchar" || t == "uint8")
    out = PlyType::kUchar;
  else if (t == "short" || t == "int16")
    out = PlyType::kShort;
  else if (t == "ushort" || t == "uint16")
    out = PlyType::kUshort;
  else if (t == "int" || t == "int32")
    out = PlyType::kInt;
  else if (t == "uint" || t == "uint32")
    out = PlyType::kUint;
  else if (t == "float" || t == "float32")
    out = PlyType::kFloat;
  else if (t == "double" || t == "float64")
    out = PlyType::kDouble;
  else
    return false;
  return true;
}

int ply_size(PlyType t) {
  switch (t) {
    case PlyType::kChar:
    case PlyType::kUchar:
      return 1;
    case PlyType::kShort:
    case PlyType::kUshort:
      return 2;
    case PlyType::kInt:
    case PlyType::kUint:
    case PlyType::kFloat:
      return 4;
    case PlyType::kDouble:
      return 8;
  }
  return 1;
}

bool ply_is_float(PlyType t) {
  return t == PlyType::kFloat || t == PlyType::kDouble;
}

// The list properties OpenMesh's reader reads as lists (everything else it reads as one value).
bool is_face_indices(const std::string& name) {
  return name == "vertex_indices" || name == "vertex_index";
}
bool is_face_texcoords(const std::string& name) {
  return name == "texcoord";
}

// Strict header check: OpenMesh's PLY reader crashes on some malformed headers (a property before any
// element, for one), so anything but the grammar below is rejected here with `problem` set.
bool parse_ply_header(std::istream& in, PlyHeader& h, std::string& problem) {
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) {
    problem = "not a PLY file (no 'ply' magic)";
    return false;
  }
  bool has_format = false;
  std::string integer_coordinates;  // a vertex property that must be float in binary files
  auto bad = [&](const std::string& what) {
    problem = "malformed PLY header: " + what;
    return false;
  };
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string fmt, version;
      ls >> fmt >> version;
      if (fmt != "ascii" && fmt != "binary_little_endian" && fmt != "binary_big_endian") {
        return bad("unknown format '" + fmt.substr(0, 32) + "'");
      }
      if (version != "1.0") return bad("unknown version '" + version.substr(0, 16) + "' (PLY 1.0 expected)");
      h.binary = fmt != "ascii";
      h.big_endian = fmt == "binary_big_endian";
      has_format = true;
    } else if (word == "element") {
      std::string name;
      long long n = -1;
      if (!(ls >> name >> n) || n < 0) return bad("bad element line '" + line.substr(0, 64) + "'");
      for (const auto& e : h.elements) {
        if (e.name == name) return bad("element '" + name.substr(0, 32) + "' declared twice");
      }
      h.elements.push_back({name, static_cast<std::uint64_t>(n), {}});
    } else if (word == "property") {
      if (h.elements.empty()) return bad("property before any element");
      PlyProperty prop;
      std::string type;
      ls >> type;
      if (type == "list") {
        std::string count_type, item_type;
        ls >> count_type >> item_type >> prop.name;
        if (!ply_type(count_type, prop.count_type) || ply_is_float(prop.count_type) ||
            !ply_type(item_type, prop.type) || prop.name.empty()) {
          return bad("bad list property '" + line.substr(0, 64) + "'");
        }
        prop.list = true;
        prop.declaration = "list " + count_type + " " + item_type + " " + prop.name;
      } else {
        ls >> prop.name;
        if (!ply_type(type, prop.type) || prop.name.empty())
          return bad("bad property '" + line.substr(0, 64) + "'");
        prop.declaration = type + " " + prop.name;
      }
      PlyElement& e = h.elements.back();
      // OpenMesh's binary reader converts only float types to its float coordinates, normals and texture
      // coordinates (it prints "unsupported conversion" for the others and reads 0).
      static const char* const kFloatOnly[] = {"x",         "y",         "z",         "nx",       "ny",
                                               "nz",        "u",         "v",         "s",        "t",
                                               "texture_u", "texture_v", "texture_s", "texture_t"};
      if (e.name == "vertex" && !prop.list && !ply_is_float(prop.type) &&
          std::find(std::begin(kFloatOnly), std::end(kFloatOnly), prop.name) != std::end(kFloatOnly)) {
        integer_coordinates = prop.name;
      }
      const bool understood_list =
          e.name == "face" && (is_face_indices(prop.name) || is_face_texcoords(prop.name));
      if (prop.list && !understood_list) {
        return bad("list property '" + prop.name.substr(0, 32) + "' of element '" + e.name.substr(0, 32) +
                   "' is not supported (only the face's vertex_indices and texcoord lists are)");
      }
      e.properties.push_back(prop);
    } else if (word == "comment" || word == "obj_info" || word.empty()) {
      continue;
    } else if (word == "end_header") {
      if (!has_format) return bad("no format line");
      if (h.binary && !integer_coordinates.empty()) {
        return bad("binary vertex property '" + integer_coordinates.substr(0, 32) +
                   "' has an integer type (float or double expected)");
      }
      // OpenMesh's binary reader reads lengths and face indices of 1 or 4 bytes only: a 2-byte one reads as
      // nothing ("unsupported conversion") and the faces come out wrong. Said, not misread.
      for (const auto& e : h.elements) {
        for (const auto& p : e.properties) {
          if (!h.binary || !p.list) continue;
          std::istringstream declared(p.declaration);
          std::string list_word, count_name, item_name;
          declared >> list_word >> count_name >> item_name;
          if (ply_size(p.count_type) == 2) {
            problem = "unsupported binary PLY: list '" + p.name.substr(0, 32) +
                      "' has the 2-byte length type '" + count_name +
                      "' (geomip reads 1- or 4-byte lengths in binary PLY: uchar, int, uint)";
            return false;
          }
          if (e.name == "face" && is_face_indices(p.name) && ply_size(p.type) == 2) {
            problem = "unsupported binary PLY: face indices of the 2-byte type '" + item_name +
                      "' (geomip reads 1- or 4-byte indices in binary PLY: uchar, int, uint)";
            return false;
          }
        }
      }
      if (h.elements.empty() || h.elements[0].name != "vertex")
        return bad("the first element is not 'vertex'");
      for (const auto& e : h.elements) {
        // Items without properties take no bytes: a reader would loop over a count no file size can bound.
        if (e.count > 0 && e.properties.empty()) {
          return bad("element '" + e.name.substr(0, 32) + "' has " + std::to_string(e.count) +
                     " items but no properties");
        }
      }
      const auto end = in.tellg();
      h.header_bytes = end < 0 ? std::numeric_limits<std::uint64_t>::max() : static_cast<std::uint64_t>(end);
      return true;
    } else {
      return bad("unknown keyword '" + word.substr(0, 32) + "'");
    }
  }
  problem = "malformed PLY header: no 'end_header'";
  return false;
}

// Text scanning used to validate what OpenMesh's text readers would silently skip or misread: NaN/Inf
// coordinates (dropped by the OBJ reader, so the error would surface as a wrong face index), truncated
// records, and garbage that makes the OFF reader loop forever.
class LineScanner {
 public:
  LineScanner(std::istream& in, std::size_t first_line) : in_(in), line_no_(first_line) {}
  // Next line that is neither empty nor a '#' comment; false at end of file.
  bool next(std::string& line) {
    while (std::getline(in_, line)) {
      ++line_no_;
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      return true;
    }
    return false;
  }
  std::size_t line_no() const { return line_no_; }

 private:
  std::istream& in_;
  std::size_t line_no_;
};

// Reads `count` numbers from `p` (strtod accepts nan/inf, so they are caught here, not dropped).
bool parse_numbers(const char* p, int count, std::vector<double>& out) {
  out.clear();
  for (int i = 0; i < count; ++i) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    // A number must end at whitespace or the end of the line: "0.1S63" is garbage, not 0.1 (OpenMesh's
    // stream-based ascii readers can loop forever on it).
    if (end == p || (*end != '\0' && !std::isspace(static_cast<unsigned char>(*end)))) return false;
    // Hex floats: strtod reads them, iostreams (OpenMesh) do not.
    if (std::find_if(p, static_cast<const char*>(end), [](char c) { return c == 'x' || c == 'X'; }) != end) {
      return false;
    }
    out.push_back(v);
    p = end;
  }
  return true;
}

std::string at_line(std::size_t n) { return "line " + std::to_string(n) + ": "; }

// An OBJ face corner: v, v/vt, v//vn or v/vt/vn, each an optionally negative integer (v required).
// Returns "" and the vertex index (as written: 1-based, or negative = relative) or the problem. OpenMesh
// reads every index as an int and drops the face silently when one does not fit: "f 1 2
// 99999999999999999999".
std::string parse_obj_corner(const std::string& corner, long long& vertex) {
  std::size_t i = 0;
  for (int field = 0; field < 3; ++field) {
    const std::size_t start = i;
    const bool negative = i < corner.size() && corner[i] == '-';
    if (negative) ++i;
    const std::size_t digits = i;
    long long value = 0;
    bool overflow = false;
    while (i < corner.size() && std::isdigit(static_cast<unsigned char>(corner[i]))) {
      value = value * 10 + (corner[i] - '0');
      if (value > std::numeric_limits<int>::max()) {
        overflow = true;
        value = std::numeric_limits<int>::max();
      }
      ++i;
    }
    const bool empty = i == digits;
    if (empty && (field == 0 || i != start)) return "malformed face corner '" + corner.substr(0, 24) + "'";
    if (overflow) {
      const char* what = field == 0 ? "vertex" : field == 1 ? "texture coordinate" : "normal";
      return std::string("face ") + what + " index '" +
             corner.substr(start, std::min<std::size_t>(i - start, 24)) +
             "' is out of range (more than 2^31 - 1)";
    }
    if (field == 0) {
      if (value == 0)
        return "face corner '" + corner.substr(0, 24) + "' has vertex index 0 (OBJ counts from 1)";
      vertex = negative ? -value : value;
    }
    if (i == corner.size()) return {};
    if (corner[i] != '/') return "malformed face corner '" + corner.substr(0, 24) + "'";
    ++i;
  }
  return "malformed face corner '" + corner.substr(0, 24) + "'";
}

// An OBJ face whose corners repeat a vertex ("f 1 1 2"), which OpenMesh's reader drops without a word: its
// 0-based corners and its place among the file's faces, so that read_mesh keeps it as PLY and OFF do (a
// degenerate triangle that `info` counts and `repair` removes, instead of a face silently lost).
struct RepeatedCornerFace {
  std::size_t ordinal;  // faces of the file before it
  std::vector<int> corners;
};

// `exact` (when not null) gets every vertex's coordinates as written: OpenMesh's reader rounds them to float;
// `repeated` (when not null) the faces with a repeated corner. Returns the number of faces ("f" lines).
std::size_t validate_obj(const std::string& path, std::string_view bytes, std::vector<Eigen::Vector3d>* exact,
                         std::vector<RepeatedCornerFace>* repeated = nullptr) {
  std::size_t faces = 0;  // "f" lines so far
  std::vector<int> resolved, sorted;  // one face's 0-based corners (reused from face to face)
  MemoryStream in(bytes);
  LineScanner lines(in, 0);
  std::string line;
  std::vector<double> xyz;
  long long vertices = 0;   // "v" lines so far
  long long max_index = 0;  // largest positive vertex index of any face, and its line
  std::size_t max_index_line = 0;
  while (lines.next(line)) {
    // The keyword as OpenMesh's reader finds it: the line trimmed of " \t\r\n" (a line that then starts with
    // other white space is skipped), then its first white-space-delimited token.
    const auto first = line.find_first_not_of(" \t\r\n");
    if (first == std::string::npos || std::isspace(static_cast<unsigned char>(line[first]))) continue;
    std::size_t end = first;
    while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end]))) ++end;
    const std::string_view keyword(line.data() + first, end - first);
    if (keyword == "f") {
      // Every corner must start with a (possibly negative) index: OpenMesh asserts on "f /8 2 3".
      std::istringstream corners(line.substr(end));
      std::string corner;
      int count = 0;
      resolved.clear();
      while (corners >> corner) {
        long long index = 0;
        const std::string problem = parse_obj_corner(corner, index);
        if (!problem.empty()) fail(path, at_line(lines.line_no()) + problem);
        if (index < 0 && -index > vertices) {
          fail(path, at_line(lines.line_no()) + "face references vertex " + std::to_string(index) +
                         " (relative), but only " + std::to_string(vertices) + " vertices precede it");
        }
        if (index > max_index) {
          max_index = index;
          max_index_line = lines.line_no();
        }
        ++count;
        if (repeated && resolved.size() < (std::size_t{1} << 16))
          resolved.push_back(static_cast<int>(index < 0 ? vertices + index : index - 1));
      }
      if (count < 3) fail(path, at_line(lines.line_no()) + "face with fewer than 3 corners");
      if (repeated && resolved.size() == static_cast<std::size_t>(count)) {  // (longer faces: as read)
        sorted.assign(resolved.begin(), resolved.end());
        std::sort(sorted.begin(), sorted.end());
        if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) repeated->push_back({faces, resolved});
      }
      ++faces;
      continue;
    }
    if (keyword != "v") continue;
    if (!parse_numbers(line.c_str() + end, 3, xyz)) fail(path, at_line(lines.line_no()) + "malformed vertex");
    for (double v : xyz) {
      const std::string problem = coordinate_problem(v, "vertex");
      if (!problem.empty()) fail(path, at_line(lines.line_no()) + problem);
    }
    if (exact) exact->emplace_back(xyz[0], xyz[1], xyz[2]);
    ++vertices;
  }
  if (max_index > vertices) {
    fail(path, at_line(max_index_line) + "face references vertex " + std::to_string(max_index) +
                   ", but the file has " + std::to_string(vertices) + " vertices (OBJ counts from 1)");
  }
  return faces;
}

// Whitespace-separated tokens of a text, as `std::istream >> x` sees them, with the line of each.
class Tokens {
 public:
  explicit Tokens(std::string_view text, std::size_t start = 0) : text_(text), pos_(start) {}
  // Next token; empty at the end of the text.
  std::string_view next() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    token_begin_ = begin;
    return text_.substr(begin, pos_ - begin);
  }
  // Skips the rest of the current line, its newline included (std::getline).
  void skip_line() {
    const std::size_t eol = text_.find('\n', pos_);
    pos_ = eol == std::string_view::npos ? text_.size() : eol + 1;
  }
  // 1-based line of the last token (linear: for messages only).
  std::size_t line() const {
    return 1 + static_cast<std::size_t>(std::count(text_.begin(), text_.begin() + token_begin_, '\n'));
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t token_begin_ = 0;
};

// A whole token of decimal digits, at most `max`.
bool parse_count(std::string_view token, long long max, long long& value) {
  if (token.empty() || token.size() > 18) return false;
  value = 0;
  for (char c : token) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    value = value * 10 + (c - '0');
  }
  return value <= max;
}

// A whole token that is a decimal number (strtod alone would also take hex floats, which iostreams do not).
bool parse_number(std::string_view token, double& value) {
  if (token.empty() || token.size() > 64 || token.find_first_of("xX") != std::string_view::npos) return false;
  const std::string text(token);
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

// OFF as Geomview writes it may hold comments: from '#' to the end of the line. OpenMesh's OFF reader does
// not know them (it reads "#" as a count or a coordinate), so they become spaces before validate_off() and
// the reader see the text: lines and columns stay where they were, for the messages.
std::string blank_off_comments(std::string_view bytes) {
  std::string text(bytes);
  for (std::size_t i = text.find('#'); i != std::string::npos; i = text.find('#', i)) {
    while (i < text.size() && text[i] != '\n' && text[i] != '\r') text[i++] = ' ';
  }
  return text;
}

// OpenMesh's ascii OFF reader takes the first line as the keyword line (the rest of it is ignored), then
// reads whitespace-separated tokens: the three counts, per vertex three coordinates and the rest of its line,
// per face a corner count and that many indices (no line structure). This check reads the same tokens the
// same way, so the counts it bounds are the counts the reader loops over.
void validate_off(const std::string& path, std::string_view bytes) {
  const std::size_t eol = std::min(bytes.find('\n'), bytes.size());
  Tokens head(bytes.substr(0, eol));
  const std::string_view magic = head.next();
  const bool is_off = magic.size() >= 3 && magic.substr(magic.size() - 3) == "OFF";
  if (!is_off) fail(path, "not an OFF file (the first line does not start with OFF)");
  if (magic.find_first_of("4n") != std::string_view::npos) {
    fail(path, "'" + std::string(magic) + "': only 3-dimensional OFF is supported");
  }
  for (std::string_view word = head.next(); !word.empty(); word = head.next()) {
    long long ignored = 0;
    if (word == "BINARY") fail(path, "binary OFF is not supported (use ascii OFF, PLY or OBJ)");
    if (parse_count(word, std::numeric_limits<long long>::max(), ignored)) {
      fail(path, "line 1: the vertex and face counts must be on the line after '" + std::string(magic) + "'");
    }
  }
  Tokens tokens(bytes, std::min(eol + 1, bytes.size()));
  const auto size = static_cast<long long>(bytes.size());
  long long nv = 0, nf = 0, ne = 0;
  const char* names[3] = {"vertex", "face", "edge"};
  long long* counts[3] = {&nv, &nf, &ne};
  for (int c = 0; c < 3; ++c) {
    const std::string_view token = tokens.next();
    if (token.empty()) fail(path, "truncated OFF: no " + std::string(names[c]) + " count");
    if (!parse_count(token, std::numeric_limits<long long>::max(), *counts[c])) {
      fail(path, at_line(tokens.line()) + "the " + names[c] + " count '" + std::string(token.substr(0, 24)) +
                     "' is not a count");
    }
    if (*counts[c] > size) {
      fail(path, at_line(tokens.line()) + "OFF " + names[c] + " count " + std::to_string(*counts[c]) +
                     " is impossible for a " + std::to_string(size) + "-byte file");
    }
  }
  for (long long v = 0; v < nv; ++v) {
    for (int c = 0; c < 3; ++c) {
      const std::string_view token = tokens.next();
      if (token.empty()) {
        fail(path, "truncated OFF: the header promises " + std::to_string(nv) +
                       " vertices, the file ends after " + std::to_string(v));
      }
      double x = 0;
      if (!parse_number(token, x)) {
        fail(path, at_line(tokens.line()) + "malformed vertex " + std::to_string(v) + " ('" +
                       std::string(token.substr(0, 24)) + "')");
      }
      const std::string problem = coordinate_problem(x, "vertex " + std::to_string(v));
      if (!problem.empty()) fail(path, at_line(tokens.line()) + problem);
    }
    tokens.skip_line();  // colors, texture coordinates: ignored by the reader too
  }
  for (long long f = 0; f < nf; ++f) {
    std::string_view token = tokens.next();
    if (token.empty()) {
      fail(path, "truncated OFF: the header promises " + std::to_string(nf) + " faces, the file ends after " +
                     std::to_string(f));
    }
    long long k = 0;
    if (!parse_count(token, nv, k) || k < 3) {
      fail(path, at_line(tokens.line()) + "malformed face " + std::to_string(f) + ": '" +
                     std::string(token.substr(0, 24)) + "' is not a corner count from 3 to the " +
                     std::to_string(nv) + " vertices");
    }
    for (long long i = 0; i < k; ++i) {
      token = tokens.next();
      long long index = -1;
      if (!parse_count(token, std::numeric_limits<long long>::max(), index)) {
        fail(path, at_line(tokens.line()) + "malformed face " + std::to_string(f) + " ('" +
                       std::string(token.substr(0, 24)) + "' is not a vertex index)");
      }
      if (index >= nv) {
        fail(path, at_line(tokens.line()) + "face " + std::to_string(f) + " references vertex " +
                       std::to_string(index) + ", but the file has " + std::to_string(nv) + " vertices");
      }
    }
  }
}

// Reads PLY values in file order, ascii (whitespace-separated tokens, as `std::istream >>` sees them) or
// binary.
class PlyValues {
 public:
  PlyValues(std::string_view bytes, const PlyHeader& h)
      : bytes_(bytes),
        pos_(static_cast<std::size_t>(h.header_bytes)),
        binary_(h.binary),
        big_endian_(h.big_endian) {}

  enum class Result { kOk, kEnd, kMalformed };

  // A value of type `t`. Ascii: the whole token must be a number of that type; an integer in its range
  // (iostreams would stop at a fraction or an overflow and misalign everything after; floats are
  // range-checked by the caller, who can name the problem).
  Result read(PlyType t, double& value) {
    if (binary_) {
      const std::size_t n = static_cast<std::size_t>(ply_size(t));
      if (bytes_.size() - pos_ < n) return Result::kEnd;
      unsigned char b[8];
      for (std::size_t k = 0; k < n; ++k)
        b[k] = static_cast<unsigned char>(bytes_[pos_ + (big_endian_ ? n - 1 - k : k)]);
      pos_ += n;
      std::uint64_t u = 0;
      for (std::size_t k = n; k-- > 0;) u = u << 8 | b[k];
      switch (t) {
        case PlyType::kChar:
          value = static_cast<std::int8_t>(u);
          break;
        case PlyType::kUchar:
          value = static_cast<double>(u);
          break;
        case PlyType::kShort:
          value = static_cast<std::int16_t>(u);
          break;
        case PlyType::kUshort:
          value = static_cast<double>(u);
          break;
        case PlyType::kInt:
          value = static_cast<std::int32_t>(u);
          break;
        case PlyType::kUint:
          value = static_cast<double>(u);
          break;
        case PlyType::kFloat: {
          const auto u32 = static_cast<std::uint32_t>(u);
          float f;
          std::memcpy(&f, &u32, 4);
          value = f;
          break;
        }
        case PlyType::kDouble:
          std::memcpy(&value, &u, 8);
          break;
      }
      return Result::kOk;
    }
    const std::string_view token = next_token();
    if (token.empty()) return Result::kEnd;
    if (ply_is_float(t)) return parse_number(token, value) ? Result::kOk : Result::kMalformed;
    const bool negative = token[0] == '-';
    long long magnitude = 0;
    if (!parse_count(negative ? token.substr(1) : token, std::numeric_limits<long long>::max(), magnitude)) {
      return Result::kMalformed;
    }
    value = negative ? -static_cast<double>(magnitude) : static_cast<double>(magnitude);
    const int bits = 8 * ply_size(t);
    const bool is_signed = t == PlyType::kChar || t == PlyType::kShort || t == PlyType::kInt;
    const double max = is_signed ? std::ldexp(1.0, bits - 1) - 1 : std::ldexp(1.0, bits) - 1;
    const double min = is_signed ? -std::ldexp(1.0, bits - 1) : 0;
    return value < min || value > max ? Result::kMalformed : Result::kOk;
  }

  // Line of the last ascii token (linear: for messages only).
  std::string where() const {
    if (binary_) return "byte " + std::to_string(pos_) + ": ";
    return at_line(1 +
                   static_cast<std::size_t>(std::count(bytes_.begin(), bytes_.begin() + token_begin_, '\n')));
  }

 private:
  std::string_view next_token() {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    token_begin_ = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    return bytes_.substr(token_begin_, pos_ - token_begin_);
  }

  std::string_view bytes_;
  std::size_t pos_;
  std::size_t token_begin_ = 0;
  bool binary_;
  bool big_endian_;
};

// Walks every value OpenMesh's PLY reader will read (the elements up to and including "face"), in its order,
// checking counts, coordinates and face indices before it loops over them.
// `exact` (when not null) gets every vertex's x, y, z as stored (doubles stay doubles): OpenMesh's reader
// rounds them to float.
PlyHeader validate_ply(const std::string& path, std::string_view bytes, std::vector<Eigen::Vector3d>* exact) {
  MemoryStream in(bytes);
  PlyHeader h;
  std::string problem;
  if (!parse_ply_header(in, h, problem)) fail(path, problem);
  const std::uint64_t size = bytes.size();
  h.header_bytes = std::min(h.header_bytes, size);  // tellg() says -1 when end_header ends the file
  // Every item of an element takes at least one byte: larger counts are lies, and would make the reader
  // loop that many times.
  std::uint64_t vertices = 0;
  for (const auto& e : h.elements) {
    if (e.count > size - h.header_bytes) {
      fail(path, "truncated PLY: the header promises " + std::to_string(e.count) + " items of element '" +
                     e.name.substr(0, 32) + "', more than the " + std::to_string(size - h.header_bytes) +
                     " bytes after it can hold");
    }
    if (e.name == "vertex") {
      vertices = e.count;
      // Without them OpenMesh's reader leaves every point at the origin.
      for (const char* axis : {"x", "y", "z"}) {
        const bool found = std::any_of(e.properties.begin(), e.properties.end(),
                                       [&](const PlyProperty& p) { return !p.list && p.name == axis; });
        if (!found) fail(path, std::string("the PLY vertex element has no property '") + axis + "'");
      }
    }
  }
  PlyValues values(bytes, h);
  auto truncated = [&](const PlyElement& e, std::uint64_t item) {
    fail(path, "truncated PLY: the header promises " + std::to_string(e.count) + " " + e.name.substr(0, 32) +
                   (e.count == 1 ? "" : "s") + ", the file ends in item " + std::to_string(item));
  };
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    if (is_vertex && exact) exact->assign(static_cast<std::size_t>(e.count), Eigen::Vector3d::Zero());
    for (std::uint64_t item = 0; item < e.count; ++item) {
      for (const PlyProperty& prop : e.properties) {
        double value = 0;
        if (!prop.list) {
          const auto r = values.read(prop.type, value);
          if (r == PlyValues::Result::kEnd) truncated(e, item);
          if (r == PlyValues::Result::kMalformed) {
            fail(path, values.where() + "malformed value of property '" + prop.name.substr(0, 32) + "' of " +
                           e.name.substr(0, 32) + " " + std::to_string(item));
          }
          const bool coordinate = is_vertex && (prop.name == "x" || prop.name == "y" || prop.name == "z");
          if (coordinate && exact) (*exact)[static_cast<std::size_t>(item)][prop.name[0] - 'x'] = value;
          // Coordinates: NaN, infinite or beyond float range, in either encoding. Other ascii floats too: the
          // reader's `>> float` would fail there and misalign the rest (binary ones it just converts).
          if (ply_is_float(prop.type) && (coordinate || !h.binary)) {
            const std::string bad =
                coordinate_problem(value, coordinate ? "vertex " + std::to_string(item)
                                                     : "property '" + prop.name.substr(0, 32) + "' of " +
                                                           e.name.substr(0, 32) + " " + std::to_string(item));
            if (!bad.empty()) fail(path, values.where() + bad);
          }
          continue;
        }
        double length = 0;
        auto r = values.read(prop.count_type, length);
        if (r == PlyValues::Result::kEnd) truncated(e, item);
        const bool indices = is_face && is_face_indices(prop.name);
        if (r == PlyValues::Result::kMalformed || length < 0 ||
            (indices && (length < 3 || length > vertices))) {
          fail(path, values.where() + "malformed " + e.name.substr(0, 32) + " " + std::to_string(item) +
                         ": " +
                         (indices ? "its corner count is not from 3 to the number of vertices"
                                  : "bad length of list '" + prop.name.substr(0, 32) + "'"));
        }
        for (double k = 0; k < length; ++k) {
          r = values.read(prop.type, value);
          if (r == PlyValues::Result::kEnd) truncated(e, item);
          if (r == PlyValues::Result::kMalformed || (indices && ply_is_float(prop.type))) {
            fail(path, values.where() + "malformed " + e.name.substr(0, 32) + " " + std::to_string(item));
          }
          if (indices && (value < 0 || value >= static_cast<double>(vertices))) {
            fail(path, values.where() + "face " + std::to_string(item) + " references vertex " +
                           std::to_string(static_cast<long long>(value)) + ", but the file has " +
                           std::to_string(vertices) + " vertices");
          }
        }
      }
    }
    if (is_face) break;  // the reader stops after the faces
  }
  return h;
}

// Binary STL: 80-byte header, uint32 facet count, 50 bytes per facet. OpenMesh's stream reader cannot tell
// binary from ascii by itself, so the size decides (an ascii file matching it by chance is vanishingly rare).
bool is_binary_stl(const std::string& path, std::string_view bytes) {
  const std::uint64_t size = bytes.size();
  if (size < 84) return false;
  const auto* c = reinterpret_cast<const unsigned char*>(bytes.data()) + 80;
  const std::uint64_t facets = c[0] | (c[1] << 8) | (c[2] << 16) | (std::uint64_t(c[3]) << 24);
  if (size == 84 + 50 * facets) return true;
  if (bytes.substr(0, 5) != "solid") {
    fail(path, "neither ascii STL (no 'solid') nor binary STL (" + std::to_string(facets) + " facets need " +
                   std::to_string(84 + 50 * facets) + " bytes, the file has " + std::to_string(size) + ")");
  }
  return false;
}

// Ascii STL as OpenMesh's reader walks it: every line containing "outer" (or "OUTER") starts a facet whose
// next three lines are "<word> x y z". The coordinates must be usable numbers: the reader parses them with
// `>> float` (1e39 fails and leaves a stale value) and keys its vertex map on them (NaN breaks its ordering).
void validate_ascii_stl(const std::string& path, std::string_view bytes) {
  MemoryStream in(bytes);
  std::string line;
  std::size_t line_no = 0;
  std::vector<double> xyz;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find("outer") == std::string::npos && line.find("OUTER") == std::string::npos) continue;
    for (int corner = 0; corner < 3; ++corner) {
      if (!std::getline(in, line))
        fail(path, "truncated STL: the file ends inside the facet of line " + std::to_string(line_no));
      ++line_no;
      const auto first = line.find_first_not_of(" \t\r\n");
      std::size_t end = first == std::string::npos ? line.size() : first;
      while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end]))) ++end;
      if (first == std::string::npos || !parse_numbers(line.c_str() + end, 3, xyz)) {
        fail(path, at_line(line_no) + "malformed vertex (expected 'vertex x y z' after 'outer loop')");
      }
      for (double v : xyz) {
        const std::string problem = coordinate_problem(v, "vertex");
        if (!problem.empty()) fail(path, at_line(line_no) + problem);
      }
    }
  }
}

// Binary STL: the vertex coordinates must be finite (NaN breaks the reader's vertex map ordering).
void validate_binary_stl(const std::string& path, std::string_view bytes) {
  for (std::size_t offset = 84; offset + 50 <= bytes.size(); offset += 50) {
    for (int k = 3; k < 12; ++k) {
      float v;
      std::memcpy(&v, bytes.data() + offset + 4 * k, 4);
      if (!std::isfinite(v)) {
        fail(path,
             "facet " + std::to_string((offset - 84) / 50) + " has a NaN or infinite vertex coordinate");
      }
    }
  }
}

// Only a regular file (or a link to one) is read: a device (/dev/zero), FIFO or socket would never end or
// block, a directory is no file. Checked before the extension, so the message names the real problem.
void check_regular_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) fail(path, "no such file");
  if (ec) fail(path, "cannot read (" + ec.message() + ")");
  switch (status.type()) {
    case fs::file_type::regular:
      break;
    case fs::file_type::directory:
      fail(path, "is a directory, not a mesh file");
    case fs::file_type::fifo:
      fail(path, "is a FIFO (named pipe), not a regular file: geomip reads mesh files only");
    case fs::file_type::socket:
      fail(path, "is a socket, not a regular file: geomip reads mesh files only");
    case fs::file_type::character:
    case fs::file_type::block:
      fail(path, "is a device, not a regular file: geomip reads mesh files only");
    default:
      fail(path, "is not a regular file: geomip reads mesh files only");
  }
}

// The file's bytes, read once, at most `max_bytes` of them (check_regular_file() first).
std::string read_file_bounded(const std::string& path, std::uint64_t max_bytes) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read (" + ec.message() + ")");
  if (size == 0) fail(path, "empty file");
  if (size > max_bytes) {
    fail(path, "the file has " + std::to_string(size) + " bytes, more than geomip reads (" +
                   std::to_string(max_bytes) + " bytes; ReadMeshOptions::max_file_bytes)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open for reading (") + std::strerror(errno) + ")");
  // Read what the size said, plus one byte to notice a file that grows meanwhile: never more.
  std::string bytes(static_cast<std::size_t>(size) + 1, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const auto got = static_cast<std::uint64_t>(in.gcount());
  if (in.bad()) fail(path, "read error");
  if (got > size) fail(path, "the file grew while it was read");
  bytes.resize(static_cast<std::size_t>(got));
  if (bytes.empty()) fail(path, "empty file");
  return bytes;
}

}  // namespace

MeshFormat mesh_format_from_path(const std::string& path) {
  const std::string ext = extension_of(path);
  if (ext == "obj") return MeshFormat::kObj;
  if (ext == "ply") return MeshFormat::kPly;
  if (ext == "off") return MeshFormat::kOff;
  if (ext == "stl" || ext == "stla" || ext == "stlb") return MeshFormat::kStl;
  if (ext == "gltf") return MeshFormat::kGltf;
  if (ext == "glb") return MeshFormat::kGlb;
  if (ext.empty())
    throw InvalidInput(path + ": no file extension (geomip reads .obj .ply .off .stl .gltf .glb)");
  throw InvalidInput(path + ": unsupported mesh format '." + ext + "' (geomip reads .obj .ply .off .stl .gltf .glb)");
}

TriMesh read_mesh(const std::string& path, const ReadMeshOptions& options) {
  check_regular_file(path);
  const MeshFormat format = mesh_format_from_path(path);
  const std::string bytes = read_file_bounded(path, options.max_file_bytes);
  return read_mesh_from_memory(bytes, format, path, options);
}

TriMesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& path,
                              const ReadMeshOptions& options) {
  silence_openmesh();
  if (bytes.empty()) fail(path, "empty file");
  if (bytes.size() > options.max_file_bytes) {
    fail(path, "the file has " + std::to_string(bytes.size()) + " bytes, more than geomip reads (" +
                   std::to_string(options.max_file_bytes) + " bytes; ReadMeshOptions::max_file_bytes)");
  }
  if (format == MeshFormat::kGltf || format == MeshFormat::kGlb) {
    // JSON or binary, told by the bytes (a .gltf holding GLB still reads); external buffers beside the file.
    const std::string base_dir = std::filesystem::path(path).parent_path().string();
    return read_gltf_from_memory(bytes, path, base_dir.empty() ? "." : base_dir);
  }
  bool binary_stl = false;
  std::string ply_header;  // PLY: the validated header, rewritten (PlyHeader::canonical())
  std::string off_text;    // OFF with '#' comments: the text with them blanked (blank_off_comments())
  // A UTF-8 byte-order mark (some Windows editors write one) is not part of the first line.
  if ((format == MeshFormat::kObj || format == MeshFormat::kOff) && bytes.substr(0, 3) == "\xEF\xBB\xBF")
    bytes.remove_prefix(3);
  std::string_view data = bytes;
  std::vector<Eigen::Vector3d> exact;  // OBJ and PLY: the coordinates as written (the reader rounds to float)
  std::vector<RepeatedCornerFace> repeated;  // OBJ: faces OpenMesh's reader may drop
  std::size_t obj_faces = 0;
  switch (format) {
    case MeshFormat::kObj:
      obj_faces = validate_obj(path, bytes, &exact, &repeated);
      break;
    case MeshFormat::kOff:
      if (bytes.find('#') != std::string_view::npos) {
        off_text = blank_off_comments(bytes);
        data = off_text;
      }
      validate_off(path, data);
      break;
    case MeshFormat::kPly: {
      const PlyHeader h = validate_ply(path, bytes, &exact);
      ply_header = h.canonical();
      data = bytes.substr(static_cast<std::size_t>(h.header_bytes));
      break;
    }
    case MeshFormat::kStl:
      binary_stl = is_binary_stl(path, bytes);  // the facet count is checked against the size
      (binary_stl ? validate_binary_stl : validate_ascii_stl)(path, bytes);
      break;
    case MeshFormat::kGltf:
    case MeshFormat::kGlb:
      break;  // read above
  }

  RecordingImporter importer;
  OpenMesh::IO::Options io_options;
  if (binary_stl) io_options += OpenMesh::IO::Options::Binary;
  bool ok = false;
  try {
    JoinedStream in(ply_header, data);
    const std::lock_guard<std::mutex> lock(openmesh_mutex());
    const SilencedCerr quiet;
    // OpenMesh picks the reader by extension; STL variants all go through "stl".
    ok = OpenMesh::IO::IOManager().read(in, extension_of(format), importer, io_options);
  } catch (const std::exception& e) {
    fail(path, std::string("parse error: ") + e.what());
  }
  if (!ok) fail(path, std::string("cannot parse as a .") + extension_of(format) + " mesh");
  // OBJ faces with a repeated corner as the file has them: OpenMesh's reader drops each later repeat of a
  // corner and then the face if fewer than 3 corners are left ("f 1 1 2" lost, "f 1 2 1 3" read as the
  // triangle 1 2 3, an area the file does not have). Left as the reader gave them if its faces are not
  // exactly that.
  if (!repeated.empty()) {
    auto without_repeats = [](const std::vector<int>& corners) {
      std::vector<int> kept;
      std::unordered_set<int> seen;
      for (int v : corners)
        if (seen.insert(v).second) kept.push_back(v);
      return kept;
    };
    // First check that the reader's faces are exactly that, then put the file's back in their places.
    std::size_t next_kept = 0;
    bool same = true;
    for (std::size_t f = 0, r = 0; f < obj_faces && same; ++f) {
      if (r < repeated.size() && repeated[r].ordinal == f) {
        const std::vector<int> read = without_repeats(repeated[r++].corners);
        if (read.size() >= 3)  // the reader kept it without its repeats
          same = next_kept < importer.polygons.size() && importer.polygons[next_kept++] == read;
      } else {
        same = next_kept++ < importer.polygons.size();
      }
    }
    if (same && next_kept == importer.polygons.size()) {
      std::vector<std::vector<int>> merged;
      merged.reserve(obj_faces);
      next_kept = 0;
      for (std::size_t f = 0, r = 0; f < obj_faces; ++f) {
        if (r < repeated.size() && repeated[r].ordinal == f) {
          if (without_repeats(repeated[r].corners).size() >= 3) ++next_kept;
          merged.push_back(std::move(repeated[r++].corners));
        } else {
          merged.push_back(std::move(importer.polygons[next_kept++]));
        }
      }
      importer.polygons = std::move(merged);
    }
  }
  if (importer.polygons.empty()) fail(path, std::string("no faces found (empty, or not a mesh in .") + extension_of(format) + " format)");

  TriMesh mesh;
  mesh.positions = std::move(importer.points);
  // The same vertices in the same order, read without the float rounding when the file holds more than float
  // precision (a mesh 10^6 units from its origin keeps its millimetres). A file of float data written with 9
  // significant digits (geomip's own outputs, most exporters) is within 5e-9 of its floats everywhere and
  // reads as those floats, as OFF, STL, glTF and binary PLY floats do: one mesh, the same points in any
  // format.
  if (exact.size() == mesh.positions.size()) {
    bool same = true, finer = false;
    for (std::size_t v = 0; v < exact.size() && same; ++v) {
      for (int c = 0; c < 3;
           ++c) {  // within float rounding of each other (strtof and a rounded strtod may differ)
        const double gap = std::abs(exact[v][c] - mesh.positions[v][c]);
        same = same && gap <= 1e-6 * std::abs(exact[v][c]) + 1e-37;
        finer = finer || gap > 1e-8 * std::abs(exact[v][c]);
      }
    }
    if (same && finer) mesh.positions = std::move(exact);
  }
  const auto n = static_cast<long long>(mesh.positions.size());
  mesh.triangles.reserve(importer.polygons.size());
  for (std::size_t f = 0; f < importer.polygons.size(); ++f) {
    const auto& poly = importer.polygons[f];
    if (poly.size() < 3) fail(path, "face " + std::to_string(f) + " has fewer than 3 vertices");
    for (int v : poly) {
      if (v < 0 || v >= n) {
        fail(path, "face " + std::to_string(f) + " references vertex " + std::to_string(v) +
                       " (0-based), but the file has " + std::to_string(n) + " vertices");
      }
    }
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) mesh.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  }
  if (options.reject_non_finite) {
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      for (int c = 0; c < 3; ++c) {
        const std::string problem = coordinate_problem(mesh.positions[v][c], "vertex " + std::to_string(v));
        if (!problem.empty()) fail(path, problem);
      }
    }
  }
  return mesh;
}

void write_mesh(const TriMesh& mesh, std::ostream& out, MeshFormat format, const WriteMeshOptions& options) {
  silence_openmesh();
  if (format == MeshFormat::kStl) throw InvalidInput("write_mesh: STL output is not supported (use OBJ or PLY)");
  if (mesh.triangles.empty()) throw InvalidInput("write_mesh: the mesh has no triangles");
  if (!options.vertex_normals.empty() && options.vertex_normals.size() != mesh.positions.size())
    throw InvalidInput("write_mesh: " + std::to_string(options.vertex_normals.size()) + " normals for " +
                       std::to_string(mesh.positions.size()) + " vertices");
  if (format == MeshFormat::kGltf || format == MeshFormat::kGlb) {
    GltfWriteOptions gltf;
    gltf.binary = format == MeshFormat::kGlb;
    MeshAttributes attributes;  // smooth shading in glTF viewers: area-weighted vertex normals
    if (!options.vertex_normals.empty())
      attributes.normals = options.vertex_normals;
    else
      for (const auto& n : vertex_normals(mesh)) attributes.normals.push_back(n.cast<float>());
    write_gltf(mesh, attributes, out, gltf);
    return;
  }
  const bool normals = !options.vertex_normals.empty();
  TriMeshExporter exporter(mesh, normals ? &options.vertex_normals : nullptr);
  OpenMesh::IO::Options io_options;
  if (normals) io_options += OpenMesh::IO::Options::VertexNormal;
  if (format == MeshFormat::kPly && options.binary) {
    io_options += OpenMesh::IO::Options::Binary;
    io_options += OpenMesh::IO::Options::LSB;
  }
  const std::lock_guard<std::mutex> lock(openmesh_mutex());
  if (!OpenMesh::IO::IOManager().write(out, extension_of(format), exporter, io_options, options.precision) || !out) {
    throw IoError("write_mesh: writing the " + std::string(extension_of(format)) + " stream failed");
  }
}

}  // namespace geomip
