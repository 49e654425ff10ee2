// Mesh file input and output: OBJ, PLY (ascii and binary), OFF and STL in; OBJ and PLY (and OFF) out.
//
// Parsing is OpenMesh's (its readers and writers), but the data goes through geomip's own importer and
// exporter so that faces are recorded exactly as they are in the file: OpenMesh's half-edge importer drops
// faces that would create a "complex edge", and topology must be judged on the triangles as read
// (see mesh_topology.h).
#pragma once

#include "mesh/mesh.h"

#include <iosfwd>
#include <string>

namespace geomip {

enum class MeshFormat { kObj, kPly, kOff, kStl };

/// Format from the file name's extension (case-insensitive).
/// \throw InvalidInput for an extension geomip does not read or write.
MeshFormat mesh_format_from_path(const std::string& path);

struct ReadMeshOptions {
  /// Reject NaN/Inf coordinates (on by default: nothing downstream can use them).
  bool reject_non_finite = true;
};

/// Reads a mesh file. Polygons with more than three corners are triangulated as fans.
/// Checks: the file exists and is readable, the parser accepts it, it has at least one face, every face index
/// is in range, every referenced coordinate is finite (unless disabled), and the file is not truncated
/// (binary PLY with fewer bytes than its header promises).
/// \throw InvalidInput with a message naming `path` and the problem.
TriMesh read_mesh(const std::string& path, const ReadMeshOptions& options = {});

struct WriteMeshOptions {
  /// PLY only: binary little-endian (default) or ascii.
  bool binary = true;
  /// Significant digits for text formats; 9 round-trips float32 coordinates exactly.
  int precision = 9;
};

/// Writes `mesh` to `out` in `format` (OBJ, PLY or OFF). Writes every triangle as it is: no manifold
/// requirement. Does not open or rename files: tools/ write to a temporary file and rename (atomic output).
/// \throw InvalidInput for STL (not written) or an empty mesh, IoError when the stream fails.
void write_mesh(const TriMesh& mesh, std::ostream& out, MeshFormat format, const WriteMeshOptions& options = {});

}  // namespace geomip
