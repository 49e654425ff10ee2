#include "tools/atomic_file.h"

#include "mesh/errors.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace geomip::tools {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(path + ": output directory '" + dir.string() + "' does not exist");
  std::string tmp_name = ".";
  tmp_name += target.filename().string();
  tmp_name += ".tmp-";
  tmp_name += std::to_string(::getpid());
  const fs::path tmp = dir / tmp_name;
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path + ": cannot create '" + tmp.string() + "': " + std::strerror(errno));
    write(out);
    out.flush();
    if (!out) throw IoError(path + ": write failed (disk full?)");
    out.close();
    if (out.fail()) throw IoError(path + ": closing the file failed");
    fs::rename(tmp, target, ec);
    if (ec) throw IoError(path + ": cannot rename the temporary file into place: " + ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace geomip::tools
