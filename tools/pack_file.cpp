#include "tools/pack_file.h"

#include "mesh/errors.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace geomip::tools {

std::vector<std::uint8_t> read_pack_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InvalidInput(path + ": is a directory, not a pack");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInput(path + ": cannot open (" + std::strerror(errno) + ")");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InvalidInput(path + ": read error");
  return bytes;
}

}  // namespace geomip::tools
