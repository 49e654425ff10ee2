#include "mesh/gltf_io.h"

#include "mesh/errors.h"
#include "mesh/view_frame.h"

// Debian ships TinyGLTF as a shared library (libtinygltf); only its declarations are needed here. Images are
// never decoded (geomip reads geometry), so the stb image headers are not needed either.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <draco/attributes/geometry_attribute.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <unordered_map>
#include <vector>

namespace geomip {
namespace {

constexpr double kFloatMax = static_cast<double>(std::numeric_limits<float>::max());
/// How far a NORMAL's length may be from 1: float rounding of a unit vector is ~1e-7; the Khronos validator
/// reports an error from |length − 1| > 0.00674 (gltf-validator 2.0.0-dev.3.10, measured).
constexpr double kUnitTolerance = 1e-3;

template <typename T>
void append_bytes(std::vector<unsigned char>& buffer, const T* data, std::size_t count) {
  const auto* p = reinterpret_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + count * sizeof(T));
}

// Appends a tightly packed buffer view + accessor of `count` elements; returns the accessor's index.
int add_accessor(tinygltf::Model& model, std::size_t offset, std::size_t bytes, std::size_t count, int component,
                 int type, int target) {
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = bytes;
  view.target = target;
  model.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size() - 1);
  accessor.byteOffset = 0;
  accessor.componentType = component;
  accessor.count = count;
  accessor.type = type;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size() - 1);
}

void pad4(std::vector<unsigned char>& buffer) {
  while (buffer.size() % 4) buffer.push_back(0);
}

// KHR_draco_mesh_compression: the primitive's attributes and triangles as one Draco mesh (one point per glTF
// vertex, identity mapping), encoded, decoded back in-process and described by accessors without buffer views
// whose counts and bounds are those of the decode.
constexpr const char* kDracoExtension = "KHR_draco_mesh_compression";

struct DracoAttribute {
  const char* gltf_name;
  draco::GeometryAttribute::Type type;
  int components;
  const float* values;  // components per vertex, tightly packed
  int bits;
};

/// A number for a message: "%g".
std::string short_number(double x) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%g", x);
  return text.data();
}

/// Why Draco cannot quantize `count` tuples of `components` floats, or "" when it can: a value that is not
/// finite, or an extent along an axis (max − min, in float as Draco computes it) that overflows float —
/// Draco's quantizer divides by that extent and crashes (draco 1.5.5) when it is infinite.
std::string draco_range_problem(const float* values, std::size_t count, int components) {
  static constexpr std::array<const char*, 4> kAxis{"x", "y", "z", "w"};
  std::vector<float> lo(static_cast<std::size_t>(components), std::numeric_limits<float>::max());
  std::vector<float> hi(static_cast<std::size_t>(components), -std::numeric_limits<float>::max());
  for (std::size_t i = 0; i < count; ++i) {
    for (int c = 0; c < components; ++c) {
      const float v = values[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)];
      if (!std::isfinite(v)) return "value " + std::to_string(i) + " is not finite";
      lo[static_cast<std::size_t>(c)] = std::min(lo[static_cast<std::size_t>(c)], v);
      hi[static_cast<std::size_t>(c)] = std::max(hi[static_cast<std::size_t>(c)], v);
    }
  }
  for (std::size_t c = 0; c < lo.size() && count > 0; ++c) {
    const auto extent = static_cast<float>(static_cast<double>(hi[c]) - static_cast<double>(lo[c]));
    if (!std::isfinite(extent)) {
      return std::string("the extent along ") + (c < kAxis.size() ? kAxis[c] : "an axis") + " (" +
             short_number(lo[c]) + " to " + short_number(hi[c]) +
             ") overflows float, so Draco cannot quantize it";
    }
  }
  return {};
}

void add_draco_primitive(tinygltf::Model& model, tinygltf::Primitive& prim, std::size_t num_vertices,
                         const std::vector<std::uint32_t>& indices, const std::vector<DracoAttribute>& attributes) {
  for (const DracoAttribute& a : attributes) {
    const std::string problem = draco_range_problem(a.values, num_vertices, a.components);
    if (!problem.empty()) throw InvalidInput(std::string("write_gltf: ") + a.gltf_name + ": " + problem);
  }
  draco::Mesh mesh;
  const auto n = static_cast<draco::PointIndex::ValueType>(num_vertices);
  mesh.set_num_points(n);
  std::vector<int> ids;
  for (const DracoAttribute& a : attributes) {
    draco::GeometryAttribute ga;
    ga.Init(a.type, nullptr, static_cast<std::int8_t>(a.components), draco::DT_FLOAT32, false,
            static_cast<std::int64_t>(sizeof(float)) * a.components, 0);
    const int id = mesh.AddAttribute(ga, /*identity_mapping=*/true, n);
    draco::PointAttribute* att = mesh.attribute(id);
    for (draco::PointIndex::ValueType v = 0; v < n; ++v)
      att->SetAttributeValue(draco::AttributeValueIndex(v), a.values + static_cast<std::size_t>(a.components) * v);
    ids.push_back(id);
  }
  for (std::size_t t = 0; t < indices.size(); t += 3)
    mesh.AddFace({draco::PointIndex(indices[t]), draco::PointIndex(indices[t + 1]), draco::PointIndex(indices[t + 2])});

  draco::Encoder encoder;
  for (const DracoAttribute& a : attributes) encoder.SetAttributeQuantization(a.type, a.bits);
  encoder.SetSpeedOptions(3, 3);  // compression level 7, as draco_encoder's default
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  draco::EncoderBuffer encoded;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &encoded);
  if (!status.ok()) throw SolverFailure("write_gltf: Draco failed to encode the mesh: " + status.error_msg_string());

  // What every glTF loader will see: Draco's own decode of these bytes.
  draco::DecoderBuffer in;
  in.Init(encoded.data(), encoded.size());
  draco::Decoder decoder;
  auto decoded_or = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded_or.ok()) throw SolverFailure("write_gltf: Draco cannot decode its own bytes: " + decoded_or.status().error_msg_string());
  const std::unique_ptr<draco::Mesh> decoded = std::move(decoded_or).value();
  if (3 * static_cast<std::size_t>(decoded->num_faces()) != indices.size())
    throw SolverFailure("write_gltf: Draco's decode has " + std::to_string(decoded->num_faces()) + " triangles, not " +
                        std::to_string(indices.size() / 3));

  std::vector<unsigned char>& buffer = model.buffers[0].data;
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = encoded.size();
  append_bytes(buffer, encoded.data(), encoded.size());
  pad4(buffer);
  model.bufferViews.push_back(view);

  tinygltf::Value::Object ids_by_name;
  for (std::size_t k = 0; k < attributes.size(); ++k) {
    const DracoAttribute& a = attributes[k];
    const draco::PointAttribute* att = decoded->GetAttributeByUniqueId(mesh.attribute(ids[k])->unique_id());
    if (att == nullptr || att->num_components() != a.components)
      throw SolverFailure(std::string("write_gltf: Draco's decode lost the ") + a.gltf_name + " attribute");
    ids_by_name[a.gltf_name] = tinygltf::Value(static_cast<int>(att->unique_id()));
    tinygltf::Accessor accessor;
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    accessor.count = decoded->num_points();
    accessor.type = a.components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC2;
    if (a.type == draco::GeometryAttribute::POSITION) {
      std::array<float, 3> p{};
      accessor.minValues.assign(3, kFloatMax);
      accessor.maxValues.assign(3, -kFloatMax);
      for (draco::PointIndex::ValueType v = 0; v < decoded->num_points(); ++v) {
        att->ConvertValue<float>(att->mapped_index(draco::PointIndex(v)), 3, p.data());
        for (int c = 0; c < 3; ++c) {
          accessor.minValues[c] = std::min(accessor.minValues[c], static_cast<double>(p[c]));
          accessor.maxValues[c] = std::max(accessor.maxValues[c], static_cast<double>(p[c]));
        }
      }
    }
    model.accessors.push_back(accessor);
    prim.attributes[a.gltf_name] = static_cast<int>(model.accessors.size() - 1);
  }
  tinygltf::Accessor index_accessor;
  index_accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  index_accessor.count = indices.size();
  index_accessor.type = TINYGLTF_TYPE_SCALAR;
  model.accessors.push_back(index_accessor);
  prim.indices = static_cast<int>(model.accessors.size() - 1);

  tinygltf::Value::Object extension;
  extension["bufferView"] = tinygltf::Value(static_cast<int>(model.bufferViews.size() - 1));
  extension["attributes"] = tinygltf::Value(std::move(ids_by_name));
  prim.extensions[kDracoExtension] = tinygltf::Value(std::move(extension));
  model.extensionsUsed.emplace_back(kDracoExtension);
  model.extensionsRequired.emplace_back(kDracoExtension);
}

// ---- reading ----

using Matrix4 = Eigen::Matrix4d;

Matrix4 node_matrix(const tinygltf::Node& node) {
  Matrix4 m = Matrix4::Identity();
  if (node.matrix.size() == 16) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m(r, c) = node.matrix[4 * c + r];  // column-major in glTF
    return m;
  }
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  if (node.translation.size() == 3) a.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // glTF: x y z w
    if (q.norm() > 0) a.rotate(q.normalized());
  }
  if (node.scale.size() == 3) a.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
  return a.matrix();
}

class Reader {
 public:
  /// `max_elements`: the most vertices plus triangles all instances together may add (see spend()).
  Reader(const tinygltf::Model& model, const std::string& name, std::size_t max_elements)
      : model_(model), name_(name), max_elements_(max_elements), elements_left_(max_elements) {}

  [[noreturn]] void fail(const std::string& what) const { throw InvalidInput(name_ + ": " + what); }

  /// glTF 2.0 (§3.5.3, node hierarchy): the nodes form disjoint strict trees, so no node has two parents (nor
  /// the same parent twice), and a scene's root nodes have none. Checked before any instance is made: a node
  /// listed twice instances its subtree once per path (60 levels of "the next node, twice" are 2^60
  /// instances).
  void check_node_trees(const std::vector<int>& roots) const {
    const std::size_t n = model_.nodes.size();
    std::vector<int> parent(n, -1);
    for (std::size_t p = 0; p < n; ++p) {
      for (int child : model_.nodes[p].children) {
        if (child < 0 || static_cast<std::size_t>(child) >= n)
          fail("node " + std::to_string(p) + " has a child " + std::to_string(child) +
               " that does not exist");
        const int other = parent[static_cast<std::size_t>(child)];
        if (other == static_cast<int>(p))
          fail("node " + std::to_string(p) + " lists node " + std::to_string(child) +
               " twice as a child (glTF nodes form disjoint trees)");
        if (other >= 0)
          fail("node " + std::to_string(child) + " is a child of both node " + std::to_string(other) +
               " and node " + std::to_string(p) + " (glTF nodes form disjoint trees)");
        parent[static_cast<std::size_t>(child)] = static_cast<int>(p);
      }
    }
    std::vector<bool> listed(n, false);
    for (int root : roots) {
      if (root < 0 || static_cast<std::size_t>(root) >= n) fail("a scene's node reference is out of range");
      if (parent[static_cast<std::size_t>(root)] >= 0)
        fail("scene root node " + std::to_string(root) + " is also a child of node " +
             std::to_string(parent[static_cast<std::size_t>(root)]) + " (glTF nodes form disjoint trees)");
      if (listed[static_cast<std::size_t>(root)])
        fail("node " + std::to_string(root) + " is listed twice among the scene's root nodes");
      listed[static_cast<std::size_t>(root)] = true;
    }
  }

  // The bytes of element i of accessor `a` (validated once by check_accessor()).
  struct View {
    const unsigned char* base = nullptr;
    std::size_t stride = 0;
    std::size_t count = 0;
    int component = 0;
  };

  View check_accessor(int index, int type, const char* what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
      fail(std::string(what) + " accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[index];
    if (a.sparse.isSparse) fail(std::string(what) + " accessor " + std::to_string(index) + " is sparse (not supported)");
    if (a.type != type) fail(std::string(what) + " accessor " + std::to_string(index) + " has the wrong type");
    if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= model_.bufferViews.size())
      fail(std::string(what) + " accessor " + std::to_string(index) + " has no buffer view");
    const tinygltf::BufferView& v = model_.bufferViews[a.bufferView];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model_.buffers.size())
      fail(std::string(what) + " buffer view " + std::to_string(a.bufferView) + " has no buffer");
    const std::size_t buffer_bytes = model_.buffers[v.buffer].data.size();
    const int stride = a.ByteStride(v);
    const int component_bytes = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
    if (stride <= 0 || component_bytes <= 0 || components <= 0)
      fail(std::string(what) + " accessor " + std::to_string(index) + " has an invalid layout");
    const std::size_t element = static_cast<std::size_t>(component_bytes) * components;
    // The view inside the buffer and every element inside the view (each difference checked first).
    if (v.byteOffset > buffer_bytes || v.byteLength > buffer_bytes - v.byteOffset || a.byteOffset > v.byteLength)
      fail(std::string(what) + " accessor " + std::to_string(index) + " reaches past its buffer");
    const std::size_t avail = v.byteLength - a.byteOffset;
    if (a.count > 0 && (static_cast<std::size_t>(stride) < element || element > avail ||
                        a.count - 1 > (avail - element) / static_cast<std::size_t>(stride))) {
      fail(std::string(what) + " accessor " + std::to_string(index) + " reaches past its buffer");
    }
    return {model_.buffers[v.buffer].data.data() + v.byteOffset + a.byteOffset, static_cast<std::size_t>(stride),
            a.count, a.componentType};
  }

  std::uint32_t index_at(const View& v, std::size_t i) const {
    const unsigned char* p = v.base + i * v.stride;
    switch (v.component) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t x;
        std::memcpy(&x, p, 2);
        return x;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        std::uint32_t x;
        std::memcpy(&x, p, 4);
        return x;
      }
      default: fail("indices are not unsigned integers");
    }
  }

  /// Counts `elements` (vertices or triangles) an instance is about to add against the budget: trees bound
  /// the instances by the nodes, but many nodes (or primitives) may still reuse one large accessor.
  void spend(std::size_t elements) const {
    if (elements > elements_left_)
      fail("the scene instances more than " + std::to_string(max_elements_) +
           " vertices and triangles (its nodes or primitives reuse the same data too often)");
    elements_left_ -= elements;
  }

  void add_primitive(const tinygltf::Primitive& prim, const Matrix4& xf, TriMesh& out) const {
    const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN)
      return;  // points and lines: no surface
    if (const auto draco = prim.extensions.find(kDracoExtension); draco != prim.extensions.end()) {
      add_draco_primitive(draco->second, xf, out);  // Draco decodes to triangles whatever the mode
      return;
    }
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail("a triangle primitive has no POSITION");
    const View p = check_accessor(pos->second, TINYGLTF_TYPE_VEC3, "POSITION");
    if (p.component != TINYGLTF_COMPONENT_TYPE_FLOAT) fail("POSITION is not float");
    const std::size_t first = out.positions.size();
    if (p.count > static_cast<std::size_t>(std::numeric_limits<int>::max()) - first) fail("too many vertices");
    spend(p.count);
    for (std::size_t i = 0; i < p.count; ++i) {
      float f[3];
      std::memcpy(f, p.base + i * p.stride, sizeof f);
      const Eigen::Vector4d h = xf * Eigen::Vector4d(f[0], f[1], f[2], 1.0);
      const Eigen::Vector3d q = h.head<3>();
      if (!q.allFinite() || q.cwiseAbs().maxCoeff() > kFloatMax)
        fail("vertex " + std::to_string(i) + " has a coordinate that is not finite or beyond float range");
      out.positions.push_back(q);
    }
    // The primitive's vertex sequence: its indices, or 0, 1, ... without them.
    std::optional<View> ix;
    if (prim.indices >= 0) ix = check_accessor(prim.indices, TINYGLTF_TYPE_SCALAR, "index");
    const std::size_t n = ix ? ix->count : p.count;
    const auto vertex = [&](std::size_t i) {
      const std::uint32_t v = ix ? index_at(*ix, i) : static_cast<std::uint32_t>(i);
      if (v >= p.count)
        fail("index " + std::to_string(v) + " is beyond the " + std::to_string(p.count) + " vertices");
      return static_cast<int>(first + v);
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (n % 3)
        fail(ix ? "an index count is not a multiple of 3"
                : "a non-indexed primitive's vertex count is not a multiple of 3");
      spend(n / 3);
      for (std::size_t i = 0; i < n; i += 3)
        out.triangles.push_back({vertex(i), vertex(i + 1), vertex(i + 2)});
      return;
    }
    // Strips and fans (glTF 2.0 §3.7.2.1): triangle i of a strip is (v_i, v_{i+1}, v_{i+2}), its odd ones
    // turned (v_{i+1}, v_i, v_{i+2}) so every triangle keeps the first one's winding; of a fan (v_0, v_{i+1},
    // v_{i+2}). Triangles with a repeated vertex (how strips are joined) are left out.
    if (n < 3) return;
    spend(n - 2);
    const int v0 = vertex(0);
    int a = v0, b = vertex(1);
    for (std::size_t i = 2; i < n; ++i) {
      const int c = vertex(i);
      std::array<int, 3> t{a, b, c};
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP && i % 2 == 1) t = {b, a, c};
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) out.triangles.push_back(t);
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) a = b;
      b = c;
    }
  }

  // KHR_draco_mesh_compression: positions and triangles from Draco's decode of the extension's buffer view
  // (the primitive's accessors only describe the decoded arrays).
  void add_draco_primitive(const tinygltf::Value& ext, const Matrix4& xf, TriMesh& out) const {
    const tinygltf::Value& view_index = ext.Get("bufferView");
    const tinygltf::Value& position_id = ext.Get("attributes").Get("POSITION");
    if (!view_index.IsNumber() || !position_id.IsNumber()) fail("a Draco primitive lacks its bufferView or POSITION id");
    const int vi = view_index.GetNumberAsInt();
    if (vi < 0 || static_cast<std::size_t>(vi) >= model_.bufferViews.size()) fail("a Draco buffer view does not exist");
    const tinygltf::BufferView& v = model_.bufferViews[vi];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model_.buffers.size()) fail("a Draco buffer view has no buffer");
    const std::vector<unsigned char>& data = model_.buffers[v.buffer].data;
    if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset) fail("a Draco buffer view reaches past its buffer");
    draco::DecoderBuffer in;
    in.Init(reinterpret_cast<const char*>(data.data() + v.byteOffset), v.byteLength);
    draco::Decoder decoder;
    auto decoded_or = decoder.DecodeMeshFromBuffer(&in);
    if (!decoded_or.ok()) fail("Draco cannot decode a primitive (" + decoded_or.status().error_msg_string() + ")");
    const std::unique_ptr<draco::Mesh> mesh = std::move(decoded_or).value();
    const draco::PointAttribute* att =
        mesh->GetAttributeByUniqueId(static_cast<std::uint32_t>(position_id.GetNumberAsInt()));
    if (att == nullptr || att->num_components() != 3) fail("a Draco primitive has no 3-component POSITION");
    const std::size_t first = out.positions.size();
    const std::size_t np = mesh->num_points();
    if (np > static_cast<std::size_t>(std::numeric_limits<int>::max()) - first) fail("too many vertices");
    spend(np + mesh->num_faces());
    std::array<float, 3> f{};
    for (draco::PointIndex::ValueType i = 0; i < mesh->num_points(); ++i) {
      if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(i)), 3, f.data()))
        fail("a Draco POSITION value cannot be read");
      const Eigen::Vector3d q = (xf * Eigen::Vector4d(f[0], f[1], f[2], 1.0)).head<3>();
      if (!q.allFinite() || q.cwiseAbs().maxCoeff() > kFloatMax)
        fail("vertex " + std::to_string(i) + " has a coordinate that is not finite or beyond float range");
      out.positions.push_back(q);
    }
    for (draco::FaceIndex::ValueType t = 0; t < mesh->num_faces(); ++t) {
      const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(t));
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        if (face[k].value() >= np) fail("a Draco triangle index is beyond its vertices");
        tri[k] = static_cast<int>(first + face[k].value());
      }
      out.triangles.push_back(tri);
    }
  }

  void add_node(int index, const Matrix4& parent, TriMesh& out, int depth) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.nodes.size()) fail("a node reference is out of range");
    if (depth > 64) fail("the node hierarchy is deeper than 64 (a cycle?)");
    const tinygltf::Node& node = model_.nodes[index];
    const Matrix4 xf = parent * node_matrix(node);
    if (node.mesh >= 0) {
      if (static_cast<std::size_t>(node.mesh) >= model_.meshes.size()) fail("a node references a missing mesh");
      const std::size_t first_triangle = out.triangles.size();
      for (const auto& prim : model_.meshes[node.mesh].primitives) add_primitive(prim, xf, out);
      if (xf.topLeftCorner<3, 3>().determinant() < 0) {  // mirrored instance: keep the triangles outward
        for (std::size_t t = first_triangle; t < out.triangles.size(); ++t) std::swap(out.triangles[t][1], out.triangles[t][2]);
      }
    }
    for (int child : node.children) add_node(child, xf, out, depth + 1);
  }

 private:
  const tinygltf::Model& model_;
  const std::string& name_;
  std::size_t max_elements_;
  mutable std::size_t elements_left_;
};

/// TinyGLTF's file access for external buffers (images are never loaded: TINYGLTF_NO_EXTERNAL_IMAGE), held
/// to the checks a mesh file given on the command line gets: a regular file (a FIFO blocked the read forever,
/// a directory ended in std::bad_alloc), of at most the largest byteLength an external buffer declares (a
/// buffer's file must have exactly its byteLength: a 3 GB file behind "byteLength": 96 is refused unread),
/// and all of them together at most kMaxExternalBytes. Opened once, not blocking, then checked (fstat).
struct ExternalFiles {
  static constexpr std::uint64_t kMaxExternalBytes = std::uint64_t{4} << 30;  // as ReadMeshOptions
  std::uint64_t max_file_bytes = 0;  ///< the largest byteLength of a buffer with an external URI
  std::uint64_t bytes_read = 0;
  std::string error;  ///< the first refusal, for the one-line message
};

bool external_file_exists(const std::string& path, void*) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;  // no open: a FIFO would block
}

bool read_external_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user) {
  auto& files = *static_cast<ExternalFiles*>(user);
  const auto refuse = [&](const std::string& why) {
    if (files.error.empty()) files.error = "buffer file '" + path + "' " + why;
    if (err != nullptr) *err = why;
    return false;
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return refuse(std::string("cannot be opened (") + std::strerror(errno) + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) return refuse(std::string("cannot be read (") + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) return refuse("is a directory, not a buffer file");
  if (S_ISFIFO(st.st_mode)) return refuse("is a FIFO (named pipe), not a regular file");
  if (!S_ISREG(st.st_mode)) return refuse("is a device or socket, not a regular file");
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > files.max_file_bytes) {
    return refuse("has " + std::to_string(size) + " bytes, more than the " +
                  std::to_string(files.max_file_bytes) + " its buffer declares");
  }
  if (size > ExternalFiles::kMaxExternalBytes - files.bytes_read)
    return refuse("is past the " + std::to_string(ExternalFiles::kMaxExternalBytes) + " bytes geomip reads");
  // What the size said, plus one byte to notice a file that grows meanwhile: never more.
  out->assign(static_cast<std::size_t>(size) + 1, 0);
  std::size_t got = 0;
  while (got < out->size()) {
    const ssize_t n = ::read(fd, out->data() + got, out->size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return refuse(std::string("cannot be read (") + std::strerror(errno) + ")");
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > size) return refuse("grew while it was read");
  out->resize(got);
  files.bytes_read += got;
  return true;
}

/// The largest byteLength of a buffer whose URI names a file (not a data: URI), from the JSON of `bytes`
/// (GLB or not); 0 when there is none or the JSON does not parse (TinyGLTF then says what is wrong).
std::uint64_t largest_external_buffer(std::string_view bytes) {
  std::string_view json_text = bytes;
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
    if (bytes.size() < 20) return 0;
    std::uint32_t json_bytes = 0;
    std::memcpy(&json_bytes, bytes.data() + 12, 4);
    if (json_bytes > bytes.size() - 20) return 0;
    json_text = bytes.substr(20, json_bytes);
  }
  if (json_text.find("\"uri\"") == std::string_view::npos) return 0;
  const nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("buffers") || !j["buffers"].is_array()) return 0;
  std::uint64_t largest = 0;
  for (const nlohmann::json& buffer : j["buffers"]) {
    if (!buffer.is_object() || !buffer.contains("uri") || !buffer["uri"].is_string() ||
        !buffer.contains("byteLength") || !buffer["byteLength"].is_number_unsigned())
      continue;
    if (buffer["uri"].get<std::string>().rfind("data:", 0) == 0) continue;
    largest = std::max(largest, buffer["byteLength"].get<std::uint64_t>());
  }
  return largest;
}

bool skip_images(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

}  // namespace

void write_gltf(const TriMesh& mesh, const MeshAttributes& attributes, std::ostream& out,
                const GltfWriteOptions& options) {
  if (mesh.triangles.empty() || mesh.positions.empty()) throw InvalidInput("write_gltf: empty mesh");
  const std::size_t n = mesh.positions.size();
  if (!attributes.normals.empty() && attributes.normals.size() != n)
    throw InvalidInput("write_gltf: " + std::to_string(attributes.normals.size()) + " normals for " + std::to_string(n) + " vertices");
  if (!attributes.uv.empty() && attributes.uv.size() != n)
    throw InvalidInput("write_gltf: " + std::to_string(attributes.uv.size()) + " texture coordinates for " + std::to_string(n) + " vertices");
  // glTF requires unit NORMALs (the Khronos validator: an error past 1 ± 0.00674) and finite floats.
  for (std::size_t v = 0; v < attributes.normals.size(); ++v) {
    const double length = attributes.normals[v].cast<double>().norm();
    if (!std::isfinite(length) || std::abs(length - 1.0) > kUnitTolerance)
      throw InvalidInput("write_gltf: normal " + std::to_string(v) + " is not of unit length (" +
                         short_number(length) + ")");
  }
  for (std::size_t v = 0; v < attributes.uv.size(); ++v)
    if (!attributes.uv[v].allFinite())
      throw InvalidInput("write_gltf: texture coordinate " + std::to_string(v) + " is not finite");
  if (options.draco_position_bits < 0 || options.draco_position_bits > 30)
    throw InvalidInput("write_gltf: Draco position bits must be in 1..30 (0 = no Draco), got " +
                       std::to_string(options.draco_position_bits));
  if (!is_rotation(options.node_rotation))
    throw InvalidInput("write_gltf: the node rotation is not a rotation");

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = options.generator;
  std::vector<unsigned char>& buffer = model.buffers.emplace_back().data;

  std::vector<float> positions(3 * n);
  std::array<double, 3> lo{kFloatMax, kFloatMax, kFloatMax}, hi{-kFloatMax, -kFloatMax, -kFloatMax};
  for (std::size_t v = 0; v < n; ++v) {
    for (int c = 0; c < 3; ++c) {
      const double x = mesh.positions[v][c];
      if (!std::isfinite(x) || std::abs(x) > kFloatMax) throw InvalidInput("write_gltf: vertex " + std::to_string(v) + " is not finite or beyond float range");
      positions[3 * v + c] = static_cast<float>(x);
      lo[c] = std::min(lo[c], static_cast<double>(positions[3 * v + c]));
      hi[c] = std::max(hi[c], static_cast<double>(positions[3 * v + c]));
    }
  }
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (int v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= n) throw InvalidInput("write_gltf: a triangle index is out of range");
      indices.push_back(static_cast<std::uint32_t>(v));
    }
  }

  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  if (options.draco_position_bits != 0) {
    std::vector<DracoAttribute> draco_attributes{
        {"POSITION", draco::GeometryAttribute::POSITION, 3, positions.data(), options.draco_position_bits}};
    if (!attributes.normals.empty())
      draco_attributes.push_back({"NORMAL", draco::GeometryAttribute::NORMAL, 3, attributes.normals.front().data(), 10});
    if (!attributes.uv.empty())
      draco_attributes.push_back({"TEXCOORD_0", draco::GeometryAttribute::TEX_COORD, 2, attributes.uv.front().data(), 12});
    add_draco_primitive(model, prim, n, indices, draco_attributes);
  } else {
    std::size_t offset = buffer.size();
    append_bytes(buffer, positions.data(), positions.size());
    prim.attributes["POSITION"] = add_accessor(model, offset, buffer.size() - offset, n, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                               TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
    model.accessors.back().minValues.assign(lo.begin(), lo.end());
    model.accessors.back().maxValues.assign(hi.begin(), hi.end());
    if (!attributes.normals.empty()) {
      offset = buffer.size();
      for (const auto& nv : attributes.normals) append_bytes(buffer, nv.data(), 3);
      prim.attributes["NORMAL"] = add_accessor(model, offset, buffer.size() - offset, n, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                               TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
    }
    if (!attributes.uv.empty()) {
      offset = buffer.size();
      for (const auto& t : attributes.uv) append_bytes(buffer, t.data(), 2);
      prim.attributes["TEXCOORD_0"] = add_accessor(model, offset, buffer.size() - offset, n,
                                                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2,
                                                   TINYGLTF_TARGET_ARRAY_BUFFER);
    }
    pad4(buffer);
    offset = buffer.size();
    append_bytes(buffer, indices.data(), indices.size());
    prim.indices = add_accessor(model, offset, buffer.size() - offset, indices.size(),
                                TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }

  model.meshes.emplace_back().primitives.push_back(prim);
  tinygltf::Node node;
  node.mesh = 0;
  const auto& r = options.node_rotation;
  if (r != std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}) {
    node.matrix.assign(16, 0.0);  // column-major
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col)
        node.matrix[static_cast<std::size_t>(4 * col + row)] = r[3 * row + col];
    node.matrix[15] = 1;
  }
  model.nodes.push_back(node);
  model.scenes.emplace_back().nodes.push_back(0);
  model.defaultScene = 0;

  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!options.binary, options.binary) || !out)
    throw IoError("write_gltf: writing the glTF stream failed");
}

void check_draco_positions(const std::vector<Eigen::Vector3d>& positions, const std::string& who) {
  std::vector<float> values;
  values.reserve(3 * positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    for (int c = 0; c < 3; ++c) {
      const double x = positions[v][c];
      if (!std::isfinite(x) || std::abs(x) > kFloatMax)
        throw InvalidInput(who + ": vertex " + std::to_string(v) + " is not finite or beyond float range");
      values.push_back(static_cast<float>(x));
    }
  }
  const std::string problem = draco_range_problem(values.data(), positions.size(), 3);
  if (!problem.empty()) throw InvalidInput(who + ": " + problem);
}

namespace {

/// A library's message cut for a one-line error: at most about 160 bytes, at the last space before that
/// (a word is not cut in two), with "…" when something was left out.
std::string shortened(const std::string& message) {
  constexpr std::size_t kMax = 160;
  if (message.size() <= kMax) return message;
  std::size_t cut = message.rfind(' ', kMax);
  if (cut == std::string::npos || cut < kMax / 2) cut = kMax;
  while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80)
    --cut;  // not inside a character
  return message.substr(0, cut) + " …";
}

/// Merges vertices at bit-identical positions into the first of them (glTF splits a vertex wherever one of
/// its attributes changes — texture seams, hard edges — and geomip reads positions only).
void weld_identical_positions(TriMesh& mesh) {
  struct KeyHash {
    std::size_t operator()(const std::array<std::uint64_t, 3>& k) const {
      return std::hash<std::uint64_t>()(k[0] * 0x9e3779b97f4a7c15ull ^ (k[1] + 0x632be59bd9b4e019ull) * 31 ^ k[2]);
    }
  };
  std::unordered_map<std::array<std::uint64_t, 3>, int, KeyHash> first;
  first.reserve(mesh.positions.size());
  std::vector<int> to(mesh.positions.size());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    std::array<std::uint64_t, 3> key{};
    for (int c = 0; c < 3; ++c) std::memcpy(&key[c], &mesh.positions[v][c], sizeof(double));
    const auto [it, inserted] = first.try_emplace(key, static_cast<int>(kept.size()));
    if (inserted) kept.push_back(mesh.positions[v]);
    to[v] = it->second;
  }
  if (kept.size() == mesh.positions.size()) return;
  for (auto& t : mesh.triangles)
    for (int& v : t) v = to[static_cast<std::size_t>(v)];
  mesh.positions = std::move(kept);
}

/// TinyGLTF (as Debian builds it, without Draco) refuses an index accessor without a buffer view, which is
/// how KHR_draco_mesh_compression files describe their indices. Such accessors get the primitive's Draco
/// buffer view (never read through them: add_draco_primitive() decodes the view itself). Returns the bytes
/// unchanged when no primitive needs it; GLB or JSON alike.
std::string point_draco_indices_at_their_view(std::string_view bytes, const std::string& name) {
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::string_view json_text = bytes;
  std::size_t json_end = bytes.size();
  if (binary) {  // header (magic, version, length) + JSON chunk (length, "JSON", text) + the rest
    if (bytes.size() < 20 || std::memcmp(bytes.data() + 16, "JSON", 4) != 0) return std::string(bytes);
    std::uint32_t json_bytes = 0;
    std::memcpy(&json_bytes, bytes.data() + 12, 4);
    if (json_bytes > bytes.size() - 20) return std::string(bytes);  // TinyGLTF says what is wrong
    json_text = bytes.substr(20, json_bytes);
    json_end = 20 + json_bytes;
  }
  nlohmann::json j = nlohmann::json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object() || !j.contains("meshes") || !j.contains("accessors")) return std::string(bytes);
  nlohmann::json& accessors = j["accessors"];
  bool changed = false;
  for (nlohmann::json& mesh : j["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (nlohmann::json& prim : mesh["primitives"]) {
      if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object() ||
          !prim["extensions"].contains(kDracoExtension) || !prim.contains("indices"))
        continue;
      const nlohmann::json& ext = prim["extensions"][kDracoExtension];
      const nlohmann::json& ix = prim["indices"];
      if (!ext.is_object() || !ext.contains("bufferView") || !ext["bufferView"].is_number_unsigned() ||
          !ix.is_number_unsigned() || ix.get<std::uint64_t>() >= accessors.size())
        continue;
      nlohmann::json& accessor = accessors[ix.get<std::size_t>()];
      if (accessor.is_object() && !accessor.contains("bufferView")) {
        accessor["bufferView"] = ext["bufferView"];
        changed = true;
      }
    }
  }
  if (!changed) return std::string(bytes);
  std::string text = j.dump();
  if (!binary) return text;
  while (text.size() % 4) text.push_back(' ');
  if (text.size() > std::numeric_limits<std::uint32_t>::max() - bytes.size())
    throw InvalidInput(name + ": too large for glTF (4 GiB)");
  std::string out(bytes.substr(0, 12));
  const auto json_bytes = static_cast<std::uint32_t>(text.size());
  out.append(reinterpret_cast<const char*>(&json_bytes), 4);
  out.append("JSON", 4);
  out += text;
  out.append(bytes.substr(json_end));
  const auto total = static_cast<std::uint32_t>(out.size());
  std::memcpy(out.data() + 8, &total, 4);
  return out;
}

}  // namespace

TriMesh read_gltf_from_memory(std::string_view original, const std::string& name, const std::string& base_dir) {
  if (original.size() > std::numeric_limits<unsigned int>::max()) throw InvalidInput(name + ": too large for glTF (4 GiB)");
  std::string patched;
  if (original.find(kDracoExtension) != std::string_view::npos) patched = point_draco_indices_at_their_view(original, name);
  const std::string_view bytes = patched.empty() ? original : std::string_view(patched);
  tinygltf::TinyGLTF gltf;
  gltf.SetImageLoader(&skip_images, nullptr);
  ExternalFiles files;
  files.max_file_bytes = largest_external_buffer(bytes);
  gltf.SetFsCallbacks({&external_file_exists, &tinygltf::ExpandFilePath, &read_external_file,
                       &tinygltf::WriteWholeFile, &files});
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  if (!binary) {
    // A .gltf is a JSON object (after an optional UTF-8 byte-order mark and white space); anything else is
    // named as such instead of by the JSON parser's complaint about its first byte.
    std::string_view text = bytes.substr(bytes.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0);
    const std::size_t start = text.find_first_not_of(" \t\r\n");
    if (start == std::string_view::npos || text[start] != '{')
      throw InvalidInput(
          name + ": not a glTF file (neither a binary glTF, which starts with 'glTF', nor a JSON object)");
  }
  bool ok = false;
  try {
    ok = binary ? gltf.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                            static_cast<unsigned int>(bytes.size()), base_dir)
                : gltf.LoadASCIIFromString(&model, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()),
                                           base_dir);
  } catch (const std::exception& e) {
    throw InvalidInput(name + ": not a readable glTF file (" + shortened(e.what()) + ")");
  }
  if (!ok && !files.error.empty()) throw InvalidInput(name + ": " + files.error);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    const std::size_t nl = err.find('\n');
    throw InvalidInput(name + ": not a readable glTF file" +
                       (err.empty() ? std::string() : " (" + shortened(err.substr(0, nl)) + ")"));
  }
  // Instances may add at most 16 vertices plus triangles per byte of the file and its buffers (at least
  // 2^24): read once, a primitive adds at most a third of one per byte (3 one-byte indices make a triangle),
  // Draco's decode about 2 per byte; this leaves real files room for instances and bounds a crafted one's
  // memory by its size (a 2 KB file: 2^24 elements, a few hundred MB).
  std::size_t data_bytes = bytes.size();
  for (const auto& buffer : model.buffers) data_bytes += buffer.data.size();
  const Reader reader(model, name, std::max<std::size_t>(std::size_t{1} << 24, 16 * data_bytes));
  TriMesh out;
  if (!model.scenes.empty()) {
    const int s = model.defaultScene >= 0 && static_cast<std::size_t>(model.defaultScene) < model.scenes.size() ? model.defaultScene : 0;
    reader.check_node_trees(model.scenes[s].nodes);
    for (int node : model.scenes[s].nodes) reader.add_node(node, Matrix4::Identity(), out, 0);
  } else {
    for (const auto& mesh : model.meshes) {
      for (const auto& prim : mesh.primitives) reader.add_primitive(prim, Matrix4::Identity(), out);
    }
  }
  if (out.triangles.empty()) throw InvalidInput(name + ": no triangles in the glTF file's scene");
  weld_identical_positions(out);
  return out;
}

}  // namespace geomip
