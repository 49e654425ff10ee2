// Reading a whole pack file for the command line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace geomip::tools {

/// Largest pack file read (4 GiB): packs are read whole into memory.
inline constexpr std::uint64_t kMaxPackFileBytes = std::uint64_t{4} << 30;

/// The bytes of `path`, a regular file of at most kMaxPackFileBytes.
/// \throw InvalidInput naming the file when it is missing, unreadable, larger, or not a regular file (a
///   directory, a device such as /dev/zero, a FIFO or socket: refused before a byte is read).
std::vector<std::uint8_t> read_pack_file(const std::string& path);

}  // namespace geomip::tools
