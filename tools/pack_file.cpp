#include "tools/pack_file.h"

#include "mesh/errors.h"
#include "tools/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace geomip::tools {

std::vector<std::uint8_t> read_pack_file(const std::string& path) {
  namespace fs = std::filesystem;
  note_input_file(path);
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) throw InvalidInput(path + ": no such file");
  if (status.type() == fs::file_type::directory) throw InvalidInput(path + ": is a directory, not a pack");
  // A device (/dev/zero), FIFO or socket could stream forever: only regular files are read, and whole.
  if (status.type() != fs::file_type::regular) {
    throw InvalidInput(path +
                       ": is not a regular file (a device, FIFO or socket): geomip reads pack files only");
  }
  const std::uint64_t size = fs::file_size(path, ec);
  if (ec) throw InvalidInput(path + ": cannot read (" + ec.message() + ")");
  if (size > kMaxPackFileBytes) {
    throw InvalidInput(path + ": the file has " + std::to_string(size) +
                       " bytes, more than a pack may have (" + std::to_string(kMaxPackFileBytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInput(path + ": cannot open (" + std::strerror(errno) + ")");
  // The size said, plus one byte to notice a file that grows meanwhile: never more.
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size) + 1);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (in.bad()) throw InvalidInput(path + ": read error");
  const auto got = static_cast<std::size_t>(in.gcount());
  if (got > size) throw InvalidInput(path + ": the file grew while it was read");
  bytes.resize(got);
  return bytes;
}

}  // namespace geomip::tools
