// Atomic output files: written to a temporary file beside the target, then renamed over it. A failed or
// interrupted run leaves no partial file under the target name (and removes its temporary file).
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

namespace geomip::tools {

/// Calls `write` with a stream to a temporary file in the target's directory; on success flushes, closes and
/// renames it to `path`. If `write` throws or the stream fails, the temporary file is removed and the
/// exception (or an IoError) propagates; `path` is untouched.
/// \throw IoError when the directory is not writable or the disk is full.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Checks, before any work, that a pack output is not named like a mesh (x.obj, x.glb, ...): a .gip pack
/// under a mesh's extension would be opened as a mesh by other tools. \throw InvalidInput naming `path`.
void check_pack_output_name(const std::string& path);

/// Checks, before any work, that `path` can be written: not empty, its directory exists.
/// \throw InvalidInput naming the missing directory.
void check_output_file(const std::string& path);

/// Checks, before any work, that `dir` can be made an output directory: not empty, and neither it nor a
/// parent exists as something other than a directory.
/// \throw InvalidInput naming what is in the way.
void check_output_directory(const std::string& dir);

/// Creates the output directory `dir` and its parents (nothing when it exists).
/// \throw InvalidInput when it, or a parent, exists and is not a directory; IoError when it cannot be
/// created.
void make_output_directory(const std::string& dir);

}  // namespace geomip::tools
