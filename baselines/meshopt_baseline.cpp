#include "baselines/meshopt_baseline.h"

#include "mesh/errors.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

namespace geomip {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

constexpr std::size_t kHeaderBytes = 28;  // vertex count, index count (u32 each), origin xyz, step (f32 each)

}  // namespace

MeshoptCodecResult meshopt_encode(const TriMesh& mesh, const MeshoptCodecOptions& options) {
  const std::string fn = "meshopt_encode: ";
  if (mesh.triangles.empty()) throw InvalidInput(fn + "the mesh has no triangles");
  if (options.quantization_bits < 1 || options.quantization_bits > 16)
    throw InvalidInput(fn + "quantization_bits must be in 1..16, got " +
                       std::to_string(options.quantization_bits));
  const auto nv = mesh.positions.size();

  // Referenced vertices, compacted in first-use order.
  std::vector<unsigned int> indices;
  indices.reserve(3 * mesh.triangles.size());
  std::vector<int> remap(nv, -1);
  std::vector<Eigen::Vector3d> used;
  for (const auto& t : mesh.triangles)
    for (int i : t) {
      if (i < 0 || static_cast<std::size_t>(i) >= nv) throw InvalidInput(fn + "triangle index out of range");
      if (remap[i] < 0) {
        if (!mesh.positions[i].allFinite()) throw InvalidInput(fn + "non-finite vertex coordinate");
        remap[i] = static_cast<int>(used.size());
        used.push_back(mesh.positions[i]);
      }
      indices.push_back(static_cast<unsigned>(remap[i]));
    }
  const std::size_t vertex_count = used.size();

  MeshoptCodecResult result;
  const auto encode_start = Clock::now();
  Eigen::Vector3d lo = used[0], hi = used[0];
  for (const auto& p : used) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent = (hi - lo).maxCoeff();
  const double levels = std::ldexp(1.0, options.quantization_bits) - 1;
  // Store origin and step as float32 (the header's precision), and quantize against exactly those values.
  const std::array<float, 3> origin{static_cast<float>(lo.x()), static_cast<float>(lo.y()),
                                    static_cast<float>(lo.z())};
  const float step = extent > 0 ? static_cast<float>(extent / levels) : 1.0f;
  std::vector<std::array<std::uint16_t, 4>> quantized(vertex_count);
  for (std::size_t v = 0; v < vertex_count; ++v)
    for (int k = 0; k < 3; ++k) {
      const double q = std::round((used[v][k] - origin[k]) / step);
      quantized[v][k] = static_cast<std::uint16_t>(std::clamp(q, 0.0, levels));
      quantized[v][3] = 0;
    }

  meshopt_optimizeVertexCache(indices.data(), indices.data(), indices.size(), vertex_count);
  meshopt_optimizeVertexFetch(quantized.data(), indices.data(), indices.size(), quantized.data(),
                              vertex_count, sizeof(quantized[0]));
  std::vector<unsigned char> index_stream(meshopt_encodeIndexBufferBound(indices.size(), vertex_count));
  index_stream.resize(
      meshopt_encodeIndexBuffer(index_stream.data(), index_stream.size(), indices.data(), indices.size()));
  std::vector<unsigned char> vertex_stream(
      meshopt_encodeVertexBufferBound(vertex_count, sizeof(quantized[0])));
  vertex_stream.resize(meshopt_encodeVertexBuffer(vertex_stream.data(), vertex_stream.size(),
                                                  quantized.data(), vertex_count, sizeof(quantized[0])));
  result.encode_ms = ms_since(encode_start);
  result.index_bytes = index_stream.size();
  result.vertex_bytes = vertex_stream.size();
  result.bytes = kHeaderBytes + result.index_bytes + result.vertex_bytes;

  std::vector<unsigned int> decoded_indices(indices.size());
  std::vector<std::array<std::uint16_t, 4>> decoded_vertices(vertex_count);
  std::vector<float> xyz(3 * vertex_count);
  result.decode_ms = INFINITY;
  for (int run = 0; run < std::max(1, options.decode_runs); ++run) {
    const auto start = Clock::now();
    const int ri = meshopt_decodeIndexBuffer(decoded_indices.data(), decoded_indices.size(),
                                             sizeof(unsigned int), index_stream.data(), index_stream.size());
    const int rv =
        meshopt_decodeVertexBuffer(decoded_vertices.data(), vertex_count, sizeof(decoded_vertices[0]),
                                   vertex_stream.data(), vertex_stream.size());
    if (ri != 0 || rv != 0) throw SolverFailure("meshopt_encode: meshoptimizer rejected its own stream");
    for (std::size_t v = 0; v < vertex_count; ++v)
      for (int k = 0; k < 3; ++k)
        xyz[3 * v + k] = origin[k] + step * static_cast<float>(decoded_vertices[v][k]);
    result.decode_ms = std::min(result.decode_ms, ms_since(start));
  }
  TriMesh& out = result.decoded;
  out.positions.resize(vertex_count);
  for (std::size_t v = 0; v < vertex_count; ++v)
    out.positions[v] = Eigen::Vector3f(&xyz[3 * v]).cast<double>();
  out.triangles.resize(decoded_indices.size() / 3);
  for (std::size_t f = 0; f < out.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) out.triangles[f][k] = static_cast<int>(decoded_indices[3 * f + k]);
  return result;
}

}  // namespace geomip
