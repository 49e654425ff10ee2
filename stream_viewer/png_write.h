// Screenshot output of geomip-view (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace geomip::viewer {

/// Writes width×height RGB8 pixels (rows top to bottom) as a PNG. Returns false with `error` set on failure.
bool write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb,
               std::string& error);

/// Reads an 8-bit RGB/RGBA PNG into RGB8 (rows top to bottom), for tests. Returns false on failure.
bool read_png(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgb);

}  // namespace geomip::viewer
