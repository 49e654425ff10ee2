#include "tools/atomic_file.h"

#include "mesh/errors.h"
#include "mesh/mesh_io.h"

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
  if (!fs::is_directory(dir, ec))  // the user's path, not a failure of the machine: exit 2
    throw InvalidInput(path + ": output directory '" + dir.string() + "' does not exist");
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

void check_output_directory(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InvalidInput(dir + " exists and is not a directory");
}

void make_output_directory(const std::string& dir) {
  namespace fs = std::filesystem;
  check_output_directory(dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!ec) return;
  // A parent that is a file is the user's path; anything else (permissions, a full disk) is the machine's.
  for (fs::path p = fs::path(dir).parent_path(); !p.empty() && p != p.root_path(); p = p.parent_path()) {
    std::error_code e;
    if (fs::exists(p, e) && !fs::is_directory(p, e))
      throw InvalidInput(dir + ": " + p.string() + " exists and is not a directory");
  }
  throw IoError(dir + ": cannot create the output directory: " + ec.message());
}

void check_pack_output_name(const std::string& path) {
  bool mesh_name = true;
  try {
    mesh_format_from_path(path);
  } catch (const InvalidInput&) {
    mesh_name = false;  // not a mesh extension: any name will do
  }
  if (mesh_name)
    throw InvalidInput("-o " + path +
                       ": this writes a .gip pack, not a mesh; name it .gip (geomip decode writes meshes)");
}

}  // namespace geomip::tools
