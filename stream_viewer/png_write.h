// Screenshot output of geomip-view (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace geomip::viewer {

/// Writes width×height RGB8 pixels (rows top to bottom) as a PNG, atomically: into the temporary file
/// ".NAME.tmp-PID" beside `path`, flushed and closed, then renamed over `path`. Returns false with `error`
/// set (one line, naming `path`) on failure; then `path` is as it was (an existing file intact, none created)
/// and the temporary file is removed. An existing `path` that is neither a regular file nor a directory (a
/// device such as /dev/null, a named pipe) is written in place instead: a rename would replace the node.
/// libpng prints nothing: its messages end up in `error`.
bool write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb,
               std::string& error);

/// Checks, before any rendering, that a PNG can be written to `path`: not empty, not a directory, its
/// directory exists, is a directory and takes files (a probe file is created and removed); an existing
/// device or pipe: writable itself. Returns false with `error` set (one line, naming what is in the way).
bool check_png_output(const std::string& path, std::string& error);

/// Reads an 8-bit RGB/RGBA PNG into RGB8 (rows top to bottom), for tests. Returns false on failure.
bool read_png(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgb);

}  // namespace geomip::viewer
