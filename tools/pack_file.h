// Reading a whole pack file for the command line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace geomip::tools {

/// The bytes of `path`. \throw InvalidInput naming the file when it is missing, unreadable or a directory.
std::vector<std::uint8_t> read_pack_file(const std::string& path);

}  // namespace geomip::tools
