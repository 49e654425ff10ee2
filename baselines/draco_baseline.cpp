#include "baselines/draco_baseline.h"

#include "mesh/errors.h"
#include "mesh/gltf_io.h"

#include <draco/attributes/geometry_attribute.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

namespace geomip {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void check_input(const TriMesh& mesh, const DracoOptions& options) {
  const char* fn = "draco_encode: ";
  if (mesh.triangles.empty()) throw InvalidInput(std::string(fn) + "the mesh has no triangles");
  if (options.quantization_bits < 1 || options.quantization_bits > 30)
    throw InvalidInput(std::string(fn) + "quantization_bits must be in 1..30, got " +
                       std::to_string(options.quantization_bits));
  if (options.compression_level < 0 || options.compression_level > 10)
    throw InvalidInput(std::string(fn) + "compression_level must be in 0..10, got " +
                       std::to_string(options.compression_level));
  const int nv = static_cast<int>(mesh.positions.size());
  for (const auto& t : mesh.triangles)
    for (int i : t)
      if (i < 0 || i >= nv) throw InvalidInput(std::string(fn) + "triangle index out of range");
  for (const auto& p : mesh.positions)
    if (!p.allFinite()) throw InvalidInput(std::string(fn) + "non-finite vertex coordinate");
  check_draco_positions(mesh.positions, "draco_encode");  // an extent beyond float range crashes Draco
}

// Positions as one float32 attribute with identity point mapping (one point per vertex, as draco's own OBJ
// reader produces after deduplication), triangles as point-index faces.
std::unique_ptr<draco::Mesh> to_draco(const TriMesh& mesh) {
  auto out = std::make_unique<draco::Mesh>();
  const auto nv = static_cast<draco::PointIndex::ValueType>(mesh.positions.size());
  out->set_num_points(nv);
  draco::GeometryAttribute ga;
  ga.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
  const int att_id = out->AddAttribute(ga, true, nv);
  draco::PointAttribute* att = out->attribute(att_id);
  for (draco::PointIndex::ValueType i = 0; i < nv; ++i) {
    const Eigen::Vector3d& p = mesh.positions[i];
    const std::array<float, 3> v{static_cast<float>(p.x()), static_cast<float>(p.y()),
                                 static_cast<float>(p.z())};
    att->SetAttributeValue(draco::AttributeValueIndex(i), v.data());
  }
  for (const auto& t : mesh.triangles) {
    draco::Mesh::Face f;
    for (int k = 0; k < 3; ++k) f[k] = draco::PointIndex(static_cast<std::uint32_t>(t[k]));
    out->AddFace(f);
  }
  return out;
}

bool from_draco(const draco::Mesh& mesh, TriMesh& out) {
  const draco::PointAttribute* att = mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (att == nullptr || att->num_components() != 3) return false;
  const auto np = mesh.num_points();
  out.positions.resize(np);
  std::array<float, 3> v{};
  for (draco::PointIndex::ValueType i = 0; i < np; ++i) {
    if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(i)), 3, v.data())) return false;
    out.positions[i] = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  out.triangles.resize(mesh.num_faces());
  for (draco::FaceIndex::ValueType f = 0; f < mesh.num_faces(); ++f) {
    const auto& face = mesh.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const auto idx = face[k].value();
      if (idx >= np) return false;
      out.triangles[f][k] = static_cast<int>(idx);
    }
  }
  return true;
}

// Draco's own decode: bitstream → draco::Mesh (what the decode time measures); null when Draco rejects it.
std::unique_ptr<draco::Mesh> decode_draco_mesh(const std::uint8_t* data, std::size_t size) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return nullptr;
  return std::move(decoded).value();
}

}  // namespace

bool draco_decode(const std::uint8_t* data, std::size_t size, TriMesh& out) {
  out = TriMesh{};
  if (data == nullptr || size == 0) return false;
  std::unique_ptr<draco::Mesh> mesh = decode_draco_mesh(data, size);
  if (mesh == nullptr || !from_draco(*mesh, out)) {
    out = TriMesh{};
    return false;
  }
  return true;
}

DracoResult draco_encode(const TriMesh& mesh, const DracoOptions& options) {
  check_input(mesh, options);
  const std::unique_ptr<draco::Mesh> dmesh = to_draco(mesh);

  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.quantization_bits);
  const int speed = 10 - options.compression_level;
  encoder.SetSpeedOptions(speed, speed);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);

  DracoResult result;
  draco::EncoderBuffer buffer;
  const auto encode_start = Clock::now();
  const draco::Status status = encoder.EncodeMeshToBuffer(*dmesh, &buffer);
  result.encode_ms = ms_since(encode_start);
  if (!status.ok()) throw SolverFailure("draco_encode: Draco failed to encode: " + status.error_msg_string());
  const auto* begin = reinterpret_cast<const std::uint8_t*>(buffer.data());
  result.bytes.assign(begin, begin + buffer.size());

  result.decode_ms = INFINITY;
  std::unique_ptr<draco::Mesh> decoded;
  for (int run = 0; run < std::max(1, options.decode_runs); ++run) {
    const auto start = Clock::now();
    decoded = decode_draco_mesh(result.bytes.data(), result.bytes.size());
    result.decode_ms = std::min(result.decode_ms, ms_since(start));
    if (decoded == nullptr) throw SolverFailure("draco_encode: Draco failed to decode its own stream");
  }
  if (!from_draco(*decoded, result.decoded))
    throw SolverFailure("draco_encode: Draco's decoded mesh has no usable positions");
  return result;
}

}  // namespace geomip
