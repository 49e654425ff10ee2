// The one zlib function codec/ uses (crc32), for the WASM build: Emscripten's zlib is a port it downloads,
// which an offline build cannot; crc32.cpp implements it (same results: CRC-32/IEEE, reflected 0xEDB88320).
// Only scripts/build-wasm puts this folder on the include path; native builds use the system zlib.
#pragma once

#include <cstddef>

using uLong = unsigned long;
using uInt = unsigned int;
using Bytef = unsigned char;
#define Z_NULL nullptr

extern "C" uLong crc32(uLong crc, const Bytef* buf, uInt len);
