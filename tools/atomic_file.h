// Atomic output files: written to a temporary file beside the target, then renamed over it. A failed or
// interrupted run leaves no partial file under the target name (and removes its temporary file).
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace geomip::tools {

/// Calls `write` with a stream to a temporary file in the target's directory; on success flushes, closes and
/// renames it to `path`. If `write` throws or the stream fails, the temporary file is removed and the
/// exception (or an IoError) propagates; `path` is untouched. An existing `path` that is neither a regular
/// file nor a directory (/dev/null, /dev/full, a named pipe) is written in place instead (a rename would
/// replace the device node or the pipe); a failed write there is an IoError.
/// \throw IoError when the directory is not writable or the disk is full.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Checks, before any work, that a pack output is not named like a mesh (x.obj, x.glb, ...) or an EXR image:
/// a .gip pack under such an extension would be opened as one by other tools. \throw InvalidInput naming
/// `path`.
void check_pack_output_name(const std::string& path);

/// Checks, before any work, that `path` can be written: not empty, not an existing directory, its directory
/// exists, is a directory, is writable and takes a file (a probe file is created and removed: /proc passes
/// the permission check and takes none); an existing device or pipe: writable itself. \throw InvalidInput
/// naming what is in the way.
void check_output_file(const std::string& path);

/// Checks, before any work, that the output `path` is none of `inputs` (the same file under any name): an
/// output written over an input would destroy the data it came from. Inputs that do not exist are skipped.
/// \throw InvalidInput naming both.
void check_output_is_not_an_input(const std::string& path, const std::vector<std::string>& inputs);

/// File-name parts for models whose names come from files (a pack's manifest, a mesh's stem): each name made
/// safe (no '/', '\\', control bytes or invalid UTF-8, which become '_'; "", "." and ".." become "model<i>")
/// and made unique (a repeated name gets "-<i>", i its index), in the order given.
std::vector<std::string> model_file_names(const std::vector<std::string>& names);

/// Checks, before any work, that `dir` can be made an output directory: not empty, and neither it nor a
/// parent exists as something other than a directory.
/// \throw InvalidInput naming what is in the way.
void check_output_directory(const std::string& dir);

/// Creates the output directory `dir` and its parents (nothing when it exists).
/// \throw InvalidInput when it, or a parent, exists and is not a directory; IoError when it cannot be
/// created.
void make_output_directory(const std::string& dir);

}  // namespace geomip::tools
