// Mesh file input and output: OBJ, PLY (ascii and binary), OFF, STL and glTF 2.0 (.gltf/.glb) in; OBJ, PLY,
// OFF and glTF out (glTF through mesh/gltf_io.h).
//
// Parsing is OpenMesh's (its readers and writers), but the data goes through geomip's own importer and
// exporter so that faces are recorded exactly as they are in the file: OpenMesh's half-edge importer drops
// faces that would create a "complex edge", and topology must be judged on the triangles as read
// (see mesh_topology.h).
#pragma once

#include "mesh/mesh.h"

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace geomip {

enum class MeshFormat { kObj, kPly, kOff, kStl, kGltf, kGlb };

/// Format from the file name's extension (case-insensitive).
/// \throw InvalidInput for an extension geomip does not read or write.
MeshFormat mesh_format_from_path(const std::string& path);

struct ReadMeshOptions {
  /// Reject NaN/Inf coordinates and finite ones beyond the 32-bit float range (±3.4e38) (on by default:
  /// nothing downstream can use them).
  bool reject_non_finite = true;
  /// Largest file read, in bytes (default 4 GiB, about 80 million triangles of binary PLY). read_mesh() holds
  /// the whole file in memory while it parses, so this bounds its memory; larger files are refused unread.
  std::uint64_t max_file_bytes = std::uint64_t{4} << 30;
};

/// Reads a mesh file. Polygons with more than three corners are triangulated as fans.
/// Checks: the path is a regular file (not a directory, device such as /dev/zero, FIFO or socket: those are
/// refused before a byte is read) of at most `options.max_file_bytes` bytes, the parser accepts it, it has at
/// least one face, every face index is in range and fits an int (OBJ: the message names the line), every
/// referenced coordinate is finite and within float range (unless disabled; text formats name the line), and
/// the file is not truncated (binary PLY with fewer bytes than its header promises).
/// OBJ and PLY coordinates that hold more than float precision (one of them more than 1e-8 (relative) from
/// its float) are read as written, as doubles (OpenMesh's readers round them to float, so geomip takes them
/// from its own pass over the file); float data written with 9 significant digits, OFF and STL as floats.
/// Text outputs keep 9 significant digits and PLY outputs floats (WriteMeshOptions): a mesh far from its
/// origin loses precision when written. The file is read once into memory, then parsed as
/// read_mesh_from_memory() does. \throw InvalidInput with a message naming `path` and the problem.
TriMesh read_mesh(const std::string& path, const ReadMeshOptions& options = {});

/// Parses the bytes of a mesh file already in memory (`name` only labels the messages): the same checks as
/// read_mesh() after its file checks. Before OpenMesh's reader sees the bytes, geomip walks them the way that
/// reader will (its tokens, its counts, its list lengths) and refuses what it would misread, so work and
/// memory stay bounded by `bytes.size()` (O(n log n): the STL reader's vertex map). The entry point of the mesh
/// readers' fuzzer (tests/fuzz/mesh_fuzzer.cpp).
/// \throw InvalidInput with a message naming `name` and the problem.
TriMesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                              const ReadMeshOptions& options = {});

struct WriteMeshOptions {
  /// PLY only: binary little-endian (default) or ascii.
  bool binary = true;
  /// Significant digits for text formats; 9 round-trips float32 coordinates exactly.
  int precision = 9;
  /// Per-vertex normals to write with the mesh (OBJ `vn` with `v//vn` corners, PLY nx/ny/nz, OFF as NOFF;
  /// glTF: these instead of the area-weighted ones), one per vertex; empty: none (glTF: computed).
  std::vector<Eigen::Vector3f> vertex_normals;
};

/// Writes `mesh` to `out` in `format` (OBJ, PLY, OFF, or glTF/GLB with area-weighted vertex normals
/// (vertex_normals()) for smooth shading). Writes every triangle as it is: no manifold
/// requirement. Does not open or rename files: tools/ write to a temporary file and rename (atomic output).
/// \throw InvalidInput for STL (not written), an empty mesh or a `vertex_normals` of the wrong size (for glTF
///   also one not of unit length, as write_gltf()), IoError when the stream fails.
void write_mesh(const TriMesh& mesh, std::ostream& out, MeshFormat format, const WriteMeshOptions& options = {});

}  // namespace geomip
