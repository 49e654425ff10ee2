// glTF 2.0 input and output (.gltf with the buffer embedded as a data URI, or binary .glb), through TinyGLTF
// (Debian's libtinygltf-dev): what three.js's GLTFLoader, Blender, assimp and every glTF viewer open.
//
// Output: one mesh, one triangle primitive: POSITION (float VEC3, with the min/max the specification
// requires), optional NORMAL (float VEC3, unit length) and TEXCOORD_0 (float VEC2), 32-bit indices; or, with
// GltfWriteOptions::draco_position_bits, the same primitive compressed by Draco (KHR_draco_mesh_compression,
// listed in extensionsRequired: accessors without buffer views, one buffer view of Draco bytes), which
// three.js (DRACOLoader), Blender, Babylon.js and gltf-transform decode.
// Input: every triangle primitive (modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN, indexed or not; strips
// and fans split into triangles of the first one's winding, those with a repeated vertex left out; points and
// lines skipped) of every mesh reachable from the default
// scene (all nodes when the file has no scene), node transforms applied, merged into one TriMesh, vertices at
// bit-identical positions merged into one (glTF splits a vertex wherever an attribute changes — texture
// seams, hard edges — and geomip reads positions only). Accessors
// are checked against their buffers before a byte is read; sparse accessors are refused.
#pragma once

#include "mesh/mesh.h"

#include <Eigen/Core>

#include <array>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace geomip {

/// Per-vertex attributes written with a mesh; an empty vector is not written.
struct MeshAttributes {
  std::vector<Eigen::Vector3f> normals;  ///< #V unit normals, or empty
  std::vector<Eigen::Vector2f> uv;       ///< #V texture coordinates (TEXCOORD_0), or empty
};

struct GltfWriteOptions {
  bool binary = true;          ///< GLB (one file) or JSON .gltf with the buffer as a base64 data URI
  std::string generator = "geomip";
  /// 0: plain accessors. 1..30: KHR_draco_mesh_compression with positions quantized to this many bits over
  /// the bounding box (normals 10 bits, texture coordinates 12), Draco's edgebreaker at compression level 7.
  int draco_position_bits = 0;
  /// Row-major 3×3 rotation put on the scene's node (glTF's `matrix`), so that viewers show the mesh turned
  /// while its positions stay as given: e.g. a pack's view frame, up +Y and front +Z as glTF has them. The
  /// identity (default) writes no matrix. \throw InvalidInput when it is not a rotation (orthonormal,
  /// determinant +1, within 1e-6).
  std::array<double, 9> node_rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

/// Writes `mesh` (positions as float32) with `attributes` as glTF 2.0 to `out`. Does not open or rename
/// files: tools/ write to a temporary file and rename (atomic output).
/// With Draco the accessors' counts and POSITION min/max are those of Draco's own decode of the bytes written
/// (checked in-process before a byte is written: same triangle count, every attribute present).
/// \throw InvalidInput for an empty mesh, attributes of the wrong size, a normal that is not finite or not of
///   unit length (within 1e-3), a texture coordinate that is not finite, an index out of range, a coordinate
///   outside float range, draco_position_bits outside 0..30 or, with Draco, values whose extent along an
///   axis overflows float (check_draco_positions()); SolverFailure when Draco fails to encode or
///   its decode disagrees; IoError when the stream fails.
void write_gltf(const TriMesh& mesh, const MeshAttributes& attributes, std::ostream& out,
                const GltfWriteOptions& options = {});

/// Checks, before any work, that Draco can quantize `positions`: every coordinate finite and within float
/// range, and the bounding box's extent along each axis (max − min of the float coordinates, rounded to
/// float as Draco computes it) finite. Draco (1.5.5) crashes on an extent that overflows float, e.g. a mesh
/// spanning −3e38..3e38. `who` starts the message ("write_gltf", "draco_encode", a file name).
/// \throw InvalidInput naming `who` and the axis.
void check_draco_positions(const std::vector<Eigen::Vector3d>& positions, const std::string& who);

/// Parses glTF 2.0 bytes (GLB when they start with the "glTF" magic, JSON otherwise). External buffers of a
/// JSON file are looked up in `base_dir`; `name` only labels the messages. Work and memory are linear in
/// the bytes and the buffers they reference: the nodes must form disjoint trees (as glTF 2.0 requires: no
/// node with two parents, no scene root with one), and all instances together may add at most 16 vertices
/// plus triangles per byte of the file and its buffers (at least 2^24).
/// \throw InvalidInput naming `name` and the problem: not glTF, no triangle primitive, an accessor outside
///   its buffer, an index out of range, a non-finite coordinate, nodes that are not trees, too many
///   instanced vertices and triangles.
TriMesh read_gltf_from_memory(std::string_view bytes, const std::string& name, const std::string& base_dir);

}  // namespace geomip
