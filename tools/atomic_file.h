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

}  // namespace geomip::tools
