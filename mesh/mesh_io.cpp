#include "mesh/mesh_io.h"

#include "mesh/errors.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/exporter/BaseExporter.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/Mesh/BaseKernel.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

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
  explicit TriMeshExporter(const TriMesh& mesh) : mesh_(mesh) {}

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

  // Attributes geomip does not write.
  Vec3f normal(VertexHandle) const override { return Vec3f(0, 0, 0); }
  Vec3d normald(VertexHandle) const override { return Vec3d(0, 0, 0); }
  bool is_normal_double() const override { return false; }
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
  OpenMesh::BaseKernel empty_kernel_;
};

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InvalidInput(path + ": " + problem);
}

// PLY header, parsed to check the data against it: OpenMesh reads past the end of a short binary file without
// noticing. Only fixed-size vertex data and index lists with the common layouts can be counted exactly.
struct PlyHeader {
  bool binary = false;
  bool ascii = false;
  std::uint64_t header_bytes = 0;
  std::uint64_t vertex_count = 0;
  std::uint64_t face_count = 0;
  std::uint64_t vertex_record_bytes = 0;  // 0 = unknown
  bool vertex_fixed = true;
  int face_count_bytes = 0;  // bytes of the list length
  int face_index_bytes = 0;  // bytes of each index
  bool face_simple = true;   // the face element has only the index list
  std::vector<std::string> elements;      // in file order
  std::vector<std::string> vertex_props;  // names, in record order
};

int ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// Strict header check: OpenMesh's PLY reader crashes on some malformed headers (a property before any
// element, for one), so anything but the grammar below is rejected here with `problem` set.
bool parse_ply_header(std::istream& in, PlyHeader& h, std::string& problem) {
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) {
    problem = "not a PLY file (no 'ply' magic)";
    return false;
  }
  std::string element;
  bool has_format = false;
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
        return bad("unknown format '" + fmt + "'");
      }
      if (version != "1.0") return bad("unknown version '" + version.substr(0, 16) + "' (PLY 1.0 expected)");
      h.binary = fmt != "ascii";
      h.ascii = fmt == "ascii";
      has_format = true;
    } else if (word == "element") {
      long long n = -1;
      if (!(ls >> element >> n) || n < 0) return bad("bad element line '" + line + "'");
      h.elements.push_back(element);
      if (element == "vertex") h.vertex_count = static_cast<std::uint64_t>(n);
      if (element == "face") h.face_count = static_cast<std::uint64_t>(n);
    } else if (word == "property") {
      if (element.empty()) return bad("property before any element");
      std::string type, name;
      ls >> type;
      if (type == "list") {
        std::string count_type, index_type;
        ls >> count_type >> index_type >> name;
        if (ply_type_size(count_type) == 0 || ply_type_size(index_type) == 0 || name.empty()) {
          return bad("bad list property '" + line + "'");
        }
        if (element == "vertex") {
          h.vertex_fixed = false;
        } else if (element == "face" && h.face_count_bytes == 0) {
          h.face_count_bytes = ply_type_size(count_type);
          h.face_index_bytes = ply_type_size(index_type);
        } else if (element == "face") {
          h.face_simple = false;
        }
      } else {
        ls >> name;
        const int size = ply_type_size(type);
        if (size == 0 || name.empty()) return bad("bad property '" + line + "'");
        if (element == "vertex") {
          h.vertex_record_bytes += size;
          h.vertex_props.push_back(name);
        } else if (element == "face") {
          h.face_simple = false;
        }
      }
    } else if (word == "comment" || word == "obj_info" || word.empty()) {
      continue;
    } else if (word == "end_header") {
      if (!has_format) return bad("no format line");
      if (h.elements.empty() || h.elements[0] != "vertex") return bad("the first element is not 'vertex'");
      h.header_bytes = static_cast<std::uint64_t>(in.tellg());
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
    out.push_back(v);
    p = end;
  }
  return true;
}

std::string at_line(std::size_t n) { return "line " + std::to_string(n) + ": "; }

// An OBJ face corner: v, v/vt, v//vn or v/vt/vn, each an optionally negative integer (v required).
bool is_obj_corner(const std::string& corner) {
  std::size_t i = 0;
  for (int field = 0; field < 3; ++field) {
    if (i < corner.size() && corner[i] == '-') ++i;
    const std::size_t digits = i;
    while (i < corner.size() && std::isdigit(static_cast<unsigned char>(corner[i]))) ++i;
    if (field == 0 && i == digits) return false;  // the vertex index is required
    if (i == corner.size()) return true;
    if (corner[i] != '/') return false;
    ++i;
  }
  return false;
}

void validate_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  LineScanner lines(in, 0);
  std::string line;
  std::vector<double> xyz;
  while (lines.next(line)) {
    const auto first = line.find_first_not_of(" \t");
    const bool is_face = line.compare(first, 2, "f ") == 0 || line.compare(first, 2, "f\t") == 0;
    if (is_face) {
      // Every corner must start with a (possibly negative) index: OpenMesh asserts on "f /8 2 3".
      std::istringstream corners(line.substr(first + 1));
      std::string corner;
      int count = 0;
      while (corners >> corner) {
        if (!is_obj_corner(corner)) {
          fail(path, at_line(lines.line_no()) + "malformed face corner '" + corner.substr(0, 16) + "'");
        }
        ++count;
      }
      if (count < 3) fail(path, at_line(lines.line_no()) + "face with fewer than 3 corners");
      continue;
    }
    if (line.compare(first, 2, "v ") != 0 && line.compare(first, 2, "v\t") != 0) continue;
    if (!parse_numbers(line.c_str() + first + 1, 3, xyz)) fail(path, at_line(lines.line_no()) + "malformed vertex");
    for (double v : xyz) {
      if (!std::isfinite(v)) fail(path, at_line(lines.line_no()) + "vertex has a NaN or infinite coordinate");
    }
  }
}

void validate_off(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  LineScanner lines(in, 0);
  std::string line;
  if (!lines.next(line)) fail(path, "empty OFF file");
  std::istringstream head(line);
  std::string magic;
  head >> magic;
  if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0) {
    fail(path, "not an OFF file (the first word is not OFF)");
  }
  std::string word;
  if (head >> word && word == "BINARY") fail(path, "binary OFF is not supported (use ascii OFF, PLY or OBJ)");
  long long nv = -1, nf = -1;
  std::istringstream counts(word + " " + std::string(std::istreambuf_iterator<char>(head), {}));
  if (!(counts >> nv >> nf)) {
    if (!lines.next(line)) fail(path, "truncated OFF: no vertex and face counts");
    std::istringstream c(line);
    if (!(c >> nv >> nf)) fail(path, at_line(lines.line_no()) + "expected the vertex and face counts");
  }
  const auto file_size = static_cast<long long>(std::filesystem::file_size(path));
  if (nv < 0 || nf < 0 || nv > file_size || nf > file_size) {
    fail(path, "OFF counts " + std::to_string(nv) + " vertices, " + std::to_string(nf) + " faces are impossible for a " +
                   std::to_string(file_size) + "-byte file");
  }
  std::vector<double> xyz;
  for (long long v = 0; v < nv; ++v) {
    if (!lines.next(line)) {
      fail(path, "truncated OFF: the header promises " + std::to_string(nv) + " vertices, the file ends after " +
                     std::to_string(v));
    }
    if (!parse_numbers(line.c_str(), 3, xyz)) fail(path, at_line(lines.line_no()) + "malformed vertex");
    for (double x : xyz) {
      if (!std::isfinite(x)) {
        fail(path, at_line(lines.line_no()) + "vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
      }
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!lines.next(line)) {
      fail(path, "truncated OFF: the header promises " + std::to_string(nf) + " faces, the file ends after " +
                     std::to_string(f));
    }
    std::istringstream face(line);
    // Whole-token integers: "5S" must not pass as 5 (OpenMesh's OFF reader can loop forever on it).
    auto next_integer = [&](long long& value) {
      std::string token;
      if (!(face >> token)) return false;
      char* end = nullptr;
      value = std::strtoll(token.c_str(), &end, 10);
      return end != token.c_str() && *end == '\0';
    };
    long long k = 0;
    if (!next_integer(k) || k < 3 || k > nv) fail(path, at_line(lines.line_no()) + "malformed face");
    for (long long i = 0; i < k; ++i) {
      long long index = -1;
      if (!next_integer(index)) fail(path, at_line(lines.line_no()) + "malformed face");
      if (index < 0 || index >= nv) {
        fail(path, at_line(lines.line_no()) + "face " + std::to_string(f) + " references vertex " +
                       std::to_string(index) + ", but the file has " + std::to_string(nv) + " vertices");
      }
    }
  }
}

void validate_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  PlyHeader h;
  std::string problem;
  if (!parse_ply_header(in, h, problem)) fail(path, problem);
  const std::uint64_t size = std::filesystem::file_size(path);
  if (h.binary && h.vertex_fixed) {
    const std::uint64_t need_vertices = h.header_bytes + h.vertex_count * h.vertex_record_bytes;
    if (size < need_vertices) {
      fail(path, "truncated PLY: the header promises " + std::to_string(h.vertex_count) + " vertices (" +
                     std::to_string(need_vertices) + " bytes) but the file has " + std::to_string(size) + " bytes");
    }
    if (h.face_simple && h.face_count_bytes > 0 && h.face_index_bytes > 0 && h.face_count > 0) {
      // Lower bound: every face has at least 3 indices.
      const std::uint64_t min_face = std::uint64_t(h.face_count_bytes) + 3ull * std::uint64_t(h.face_index_bytes);
      if ((size - need_vertices) / min_face < h.face_count) {
        fail(path, "truncated PLY: the header promises " + std::to_string(h.face_count) +
                       " faces but the file ends after at most " + std::to_string((size - need_vertices) / min_face));
      }
    }
    return;
  }
  if (!h.ascii || h.elements.empty() || h.elements[0] != "vertex" || !h.vertex_fixed) return;
  if (h.vertex_count > size || h.face_count > size) fail(path, "PLY element counts are impossible for the file size");
  int xyz_index[3] = {-1, -1, -1};
  for (std::size_t i = 0; i < h.vertex_props.size(); ++i) {
    if (h.vertex_props[i] == "x") xyz_index[0] = int(i);
    if (h.vertex_props[i] == "y") xyz_index[1] = int(i);
    if (h.vertex_props[i] == "z") xyz_index[2] = int(i);
  }
  LineScanner lines(in, 0);
  std::string line;
  std::vector<double> record;
  for (std::uint64_t v = 0; v < h.vertex_count; ++v) {
    if (!lines.next(line)) {
      fail(path, "truncated PLY: the header promises " + std::to_string(h.vertex_count) +
                     " vertices, the file ends after " + std::to_string(v));
    }
    if (!parse_numbers(line.c_str(), int(h.vertex_props.size()), record)) {
      fail(path, "malformed vertex " + std::to_string(v) + " in the ascii PLY data");
    }
    for (int k : xyz_index) {
      if (k >= 0 && !std::isfinite(record[k])) {
        fail(path, "vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
      }
    }
  }
  if (h.elements.size() >= 2 && h.elements[1] == "face") {
    for (std::uint64_t f = 0; f < h.face_count; ++f) {
      if (!lines.next(line)) {
        fail(path, "truncated PLY: the header promises " + std::to_string(h.face_count) +
                       " faces, the file ends after " + std::to_string(f));
      }
      if (!h.face_simple) continue;
      // "k i1 ... ik" and nothing else, all integers.
      std::istringstream face(line);
      std::string token;
      std::vector<long long> values;
      while (face >> token) {
        char* end = nullptr;
        const long long value = std::strtoll(token.c_str(), &end, 10);
        if (*end != '\0') fail(path, "malformed face " + std::to_string(f) + " in the ascii PLY data");
        values.push_back(value);
      }
      if (values.empty() || values[0] < 3 || static_cast<long long>(values.size()) != values[0] + 1) {
        fail(path, "malformed face " + std::to_string(f) + " in the ascii PLY data");
      }
      for (std::size_t k = 1; k < values.size(); ++k) {
        if (values[k] < 0 || static_cast<std::uint64_t>(values[k]) >= h.vertex_count) {
          fail(path, "face " + std::to_string(f) + " references vertex " + std::to_string(values[k]) +
                         ", but the file has " + std::to_string(h.vertex_count) + " vertices");
        }
      }
    }
  }
}

// Binary STL: 80-byte header, uint32 facet count, 50 bytes per facet. OpenMesh's stream reader cannot tell
// binary from ascii by itself, so the size decides (an ascii file matching it by chance is vanishingly rare).
bool is_binary_stl(const std::string& path) {
  const std::uint64_t size = std::filesystem::file_size(path);
  if (size < 84) return false;
  std::ifstream in(path, std::ios::binary);
  in.seekg(80);
  unsigned char c[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(c), 4);
  const std::uint64_t facets = c[0] | (c[1] << 8) | (c[2] << 16) | (std::uint64_t(c[3]) << 24);
  if (size == 84 + 50 * facets) return true;
  std::string head(5, '\0');
  in.seekg(0);
  in.read(head.data(), 5);
  if (head != "solid") {
    fail(path, "neither ascii STL (no 'solid') nor binary STL (" + std::to_string(facets) + " facets need " +
                   std::to_string(84 + 50 * facets) + " bytes, the file has " + std::to_string(size) + ")");
  }
  return false;
}

}  // namespace

MeshFormat mesh_format_from_path(const std::string& path) {
  const std::string ext = extension_of(path);
  if (ext == "obj") return MeshFormat::kObj;
  if (ext == "ply") return MeshFormat::kPly;
  if (ext == "off") return MeshFormat::kOff;
  if (ext == "stl" || ext == "stla" || ext == "stlb") return MeshFormat::kStl;
  throw InvalidInput(path + ": unsupported mesh format '." + ext + "' (geomip reads .obj .ply .off .stl)");
}

TriMesh read_mesh(const std::string& path, const ReadMeshOptions& options) {
  silence_openmesh();
  const MeshFormat format = mesh_format_from_path(path);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "no such file");
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a mesh file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) fail(path, "cannot open for reading");
  }
  if (std::filesystem::file_size(path, ec) == 0) fail(path, "empty file");
  switch (format) {
    case MeshFormat::kObj: validate_obj(path); break;
    case MeshFormat::kOff: validate_off(path); break;
    case MeshFormat::kPly: validate_ply(path); break;
    case MeshFormat::kStl: break;  // the facet count is checked against the size below
  }

  RecordingImporter importer;
  OpenMesh::IO::Options io_options;
  if (format == MeshFormat::kStl && is_binary_stl(path)) io_options += OpenMesh::IO::Options::Binary;
  bool ok = false;
  try {
    std::ifstream in(path, std::ios::binary);
    // OpenMesh picks the reader by extension; STL variants all go through "stl".
    ok = OpenMesh::IO::IOManager().read(in, extension_of(format), importer, io_options);
  } catch (const std::exception& e) {
    fail(path, std::string("parse error: ") + e.what());
  }
  if (!ok) fail(path, std::string("cannot parse as a .") + extension_of(format) + " mesh");
  if (importer.polygons.empty()) fail(path, std::string("no faces found (empty, or not a mesh in .") + extension_of(format) + " format)");

  TriMesh mesh;
  mesh.positions = std::move(importer.points);
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
      if (!mesh.positions[v].allFinite()) {
        fail(path, "vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
      }
    }
  }
  return mesh;
}

void write_mesh(const TriMesh& mesh, std::ostream& out, MeshFormat format, const WriteMeshOptions& options) {
  silence_openmesh();
  if (format == MeshFormat::kStl) throw InvalidInput("write_mesh: STL output is not supported (use OBJ or PLY)");
  if (mesh.triangles.empty()) throw InvalidInput("write_mesh: the mesh has no triangles");
  TriMeshExporter exporter(mesh);
  OpenMesh::IO::Options io_options;
  if (format == MeshFormat::kPly && options.binary) {
    io_options += OpenMesh::IO::Options::Binary;
    io_options += OpenMesh::IO::Options::LSB;
  }
  if (!OpenMesh::IO::IOManager().write(out, extension_of(format), exporter, io_options, options.precision) || !out) {
    throw IoError("write_mesh: writing the " + std::string(extension_of(format)) + " stream failed");
  }
}

}  // namespace geomip
