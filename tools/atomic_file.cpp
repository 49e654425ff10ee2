#include "tools/atomic_file.h"

#include "codec/status.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <mutex>
#include <sstream>

namespace geomip::tools {

namespace {

/// An existing target that is neither a regular file nor a directory (a device such as /dev/null or
/// /dev/full, a named pipe): renaming a temporary file over it would replace the device node (as root) or
/// the pipe, so it is written in place.
bool writes_in_place(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  return !ec && fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st);
}

/// Opens `file`, calls `write` with it, flushes and closes it; an IoError naming `path` (the target) on any
/// failure of the stream.
void write_stream(const std::filesystem::path& file, const std::string& path,
                  const std::function<void(std::ostream&)>& write) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(path + ": cannot create '" + file.string() + "': " + std::strerror(errno));
  try {
    write(out);
  } catch (const std::exception&) {
    // A serializer that checks its stream (write_mesh: "writing the obj stream failed") throws before the
    // checks below: the same message, with the path and the reason, when the stream is what failed.
    if (out.fail()) {
      const int error = errno;
      throw IoError(path + ": write failed (" + std::strerror(error) + ")");
    }
    throw;
  }
  out.flush();
  if (!out) throw IoError(path + ": write failed (" + std::strerror(errno) + ")");
  out.close();
  if (out.fail()) throw IoError(path + ": closing the file failed");
}

/// The temporary file of target `path`: ".<name>.tmp-<pid>" in its directory (a rename within one file
/// system); for a name too long to take that suffix within the file system's limit on a name (255 bytes
/// on most), ".<first bytes of the name>-<hash of the name>.tmp-<pid>".
std::filesystem::path temporary_beside(const std::string& path) {
  const std::filesystem::path target(path);
  const std::filesystem::path dir = target.parent_path().empty() ? "." : target.parent_path();
  const std::string filename = target.filename().string();
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  long limit = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (limit <= 0) limit = 255;
  std::string name(1, '.');
  name.append(filename);
  name.append(suffix);
  if (name.size() > static_cast<std::size_t>(limit)) {
    char hash[24];
    std::snprintf(hash, sizeof hash, "-%016zx", std::hash<std::string>{}(filename));
    name.assign(1, '.');
    name.append(filename, 0, std::min<std::size_t>(filename.size(), 64));
    name.append(hash);
    name.append(suffix);
  }
  return dir / name;
}

std::mutex& inputs_mutex() {
  static std::mutex m;
  return m;
}

std::vector<std::string>& noted_inputs() {
  static std::vector<std::string> inputs;
  return inputs;
}

void rename_into_place(const std::filesystem::path& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw IoError(path + ": cannot rename the temporary file into place: " + ec.message());
}

// The output `path` is none of `inputs` (the same file under any name); inputs that do not exist are skipped.
void check_output_is_not_an_input(const std::string& path, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return;
  for (const std::string& input : inputs) {
    if (fs::exists(input, ec) && fs::equivalent(path, input, ec))
      throw InvalidInput(path + " is the input " + input + ": writing it would destroy the input");
  }
}

}  // namespace

void check_output_file(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InvalidInput("-o: the output path is empty");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InvalidInput(path + ": is a directory, not a file to write");
  {
    std::vector<std::string> inputs;
    {
      const std::lock_guard<std::mutex> lock(inputs_mutex());
      inputs = noted_inputs();
    }
    check_output_is_not_an_input(path, inputs);
  }
  if (writes_in_place(path)) {  // a device or a pipe: written through, its directory is not touched
    if (::access(path.c_str(), W_OK) != 0) throw InvalidInput(path + ": is not writable");
    return;
  }
  if (!fs::is_directory(dir, ec)) {  // the user's path, not a failure of the machine: exit 2
    throw InvalidInput(path + ": output directory '" + dir.string() + "' " +
                       (fs::exists(dir, ec) ? "is not a directory" : "does not exist"));
  }
  // Found now, not after minutes of work when the temporary file cannot be created.
  if (::access(dir.c_str(), W_OK) != 0)
    throw InvalidInput(path + ": output directory '" + dir.string() + "' is not writable");
  // Some directories pass that check and still take no files (/proc, a read-only mount seen by root): try.
  const fs::path probe = dir / (".geomip-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) {
    const int error = errno;
    if (error != EEXIST)
      throw InvalidInput(path + ": cannot create files in '" + dir.string() + "': " + std::strerror(error));
    return;  // a probe of this process already there: the directory takes files
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

void note_input_file(const std::string& path) {
  const std::lock_guard<std::mutex> lock(inputs_mutex());
  if (std::find(noted_inputs().begin(), noted_inputs().end(), path) == noted_inputs().end())
    noted_inputs().push_back(path);
}

std::vector<std::string> model_file_names(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string name = codec::one_line(names[i], 120);  // control bytes and invalid UTF-8 → '?'
    for (char& c : name)
      if (c == '/' || c == '\\' || c == '?') c = '_';
    if (name.empty() || name == "." || name == "..") name = "model" + std::to_string(i);
    // Unique among those before it (a literal "spot-1" before a second "spot" is stepped over too).
    std::string unique = name;
    for (int k = 0; std::find(out.begin(), out.end(), unique) != out.end(); ++k) {
      unique = name;
      unique += '-';
      unique += std::to_string(i);
      if (k > 0) {
        unique += '-';
        unique += std::to_string(k);
      }
    }
    out.push_back(unique);
  }
  return out;
}

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  check_output_file(path);
  if (writes_in_place(path)) {
    write_stream(path, path, write);
    return;
  }
  const std::filesystem::path tmp = temporary_beside(path);
  try {
    write_stream(tmp, path, write);
    rename_into_place(tmp, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

AtomicFileSet::~AtomicFileSet() {
  for (const Entry& e : entries_) {
    std::error_code ignored;
    if (!e.done && !e.temporary.empty()) std::filesystem::remove(e.temporary, ignored);
  }
}

AtomicFileSet::Entry AtomicFileSet::entry_for(const std::string& path) const {
  namespace fs = std::filesystem;
  check_output_file(path);
  Entry e;
  e.path = path;
  if (writes_in_place(path)) return e;  // a device written twice is no conflict (both maps to /dev/null)
  // Two names of one file (x.obj, ./x.obj, a link to the directory) would share one temporary file.
  const fs::path dir = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  std::error_code ec;
  const fs::path canonical_dir = fs::canonical(dir, ec);
  e.identity = (ec ? fs::absolute(dir).lexically_normal() : canonical_dir) / fs::path(path).filename();
  for (const Entry& other : entries_) {
    if (other.identity == e.identity)
      throw InvalidInput(path + ": named twice among the outputs (as " + other.path + " before)");
  }
  e.temporary = temporary_beside(path);
  return e;
}

std::uintmax_t AtomicFileSet::add(const std::string& path, const std::function<void(std::ostream&)>& write) {
  Entry e = entry_for(path);
  if (e.temporary.empty()) {
    std::ostringstream bytes;
    write(bytes);
    e.bytes = std::move(bytes).str();
    entries_.push_back(std::move(e));
    return entries_.back().bytes.size();
  }
  try {
    write_stream(e.temporary, path, write);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(e.temporary, ignored);
    throw;
  }
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(e.temporary, ec);
  entries_.push_back(std::move(e));
  return ec ? 0 : size;
}

std::uintmax_t AtomicFileSet::add_file(const std::string& path,
                                       const std::function<void(const std::string& file)>& write) {
  namespace fs = std::filesystem;
  Entry e = entry_for(path);
  // A device or pipe: the writer writes a file in the temporary directory, which is read back and removed.
  const bool in_place = e.temporary.empty();
  const fs::path file = in_place ? fs::temp_directory_path() / (".geomip-" + std::to_string(::getpid()) +
                                                                "-" + std::to_string(entries_.size()))
                                 : e.temporary;
  try {
    try {
      write(file.string());
    } catch (const IoError& error) {  // a message that names the temporary file only: the target too
      if (std::string(error.what()).find(path) == std::string::npos)
        throw IoError(path + ": " + error.what());
      throw;
    }
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      throw IoError(path + ": the writer created no file '" + file.string() + "'");
    const std::uintmax_t size = fs::file_size(file);
    if (in_place) {
      std::ifstream in(file, std::ios::binary);
      e.bytes.assign(std::istreambuf_iterator<char>(in), {});
      if (!in.good() && !in.eof()) throw IoError(path + ": cannot read back '" + file.string() + "'");
      fs::remove(file, ec);
    }
    entries_.push_back(std::move(e));
    return size;
  } catch (...) {
    std::error_code ignored;
    fs::remove(file, ignored);
    throw;
  }
}

void AtomicFileSet::commit() {
  namespace fs = std::filesystem;
  if (committed_) return;
  // What most often stops a rename, found before any target is replaced.
  for (const Entry& e : entries_) {
    std::error_code ec;
    if (!e.temporary.empty() && fs::is_directory(e.path, ec))
      throw InvalidInput(e.path + ": is a directory, not a file to write");
  }
  // Devices and pipes first: a full one fails while every file target is still as it was.
  std::vector<Entry*> order;
  for (Entry& e : entries_)
    if (e.temporary.empty()) order.push_back(&e);
  for (Entry& e : entries_)
    if (!e.temporary.empty()) order.push_back(&e);
  for (Entry* e : order) {
    try {
      if (e->temporary.empty()) {
        write_stream(e->path, e->path, [&](std::ostream& out) {
          out.write(e->bytes.data(), static_cast<std::streamsize>(e->bytes.size()));
        });
      } else {
        rename_into_place(e->temporary, e->path);
      }
    } catch (const std::exception& error) {
      std::string replaced, kept;
      for (const Entry* other : order) {
        if (other == e) continue;
        std::string& list = other->done ? replaced : kept;
        list += (list.empty() ? "" : ", ") + other->path;
      }
      if (replaced.empty()) throw;  // nothing replaced: the message says all
      throw IoError(std::string(error.what()) + "; written already: " + replaced +
                    (kept.empty() ? std::string() : "; left as they were: " + kept));
    }
    e->done = true;
  }
  committed_ = true;
}

void check_output_directory(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw InvalidInput("-o: the output directory is empty");
  // The directory itself or any parent that exists and is a file (x.gip, x.gip/sub) can never be made.
  for (fs::path p(dir); !p.empty(); p = p.parent_path()) {
    std::error_code ec;
    if (fs::exists(p, ec) && !fs::is_directory(p, ec))
      throw InvalidInput(p.string() == dir ? dir + " exists and is not a directory"
                                           : dir + ": " + p.string() + " exists and is not a directory");
    if (p == p.parent_path()) break;
  }
}

void check_planned_outputs(const std::string& dir, const std::vector<std::string>& paths) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  for (const std::string& path : paths) check_output_file(path);
}

CreatedDirectories::CreatedDirectories(std::vector<std::string> created)
    : created_(std::move(created)), exceptions_(std::uncaught_exceptions()) {}

CreatedDirectories::CreatedDirectories(CreatedDirectories&& other) noexcept
    : created_(std::move(other.created_)), exceptions_(other.exceptions_) {
  other.created_.clear();
}

CreatedDirectories::~CreatedDirectories() {
  if (std::uncaught_exceptions() <= exceptions_) return;  // the command ended normally
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    std::error_code ignored;
    std::filesystem::remove(*it, ignored);  // only an empty directory goes
  }
}

CreatedDirectories make_output_directory(const std::string& dir) {
  namespace fs = std::filesystem;
  check_output_directory(dir);  // a file in the way is the user's path
  std::vector<std::string> missing;  // outermost first
  std::error_code ec;
  for (fs::path p = fs::path(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.insert(missing.begin(), p.string());
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  if (!ec) return CreatedDirectories(std::move(missing));
  check_output_directory(
      dir);  // it may have appeared since; anything else (permissions, a full disk) is the machine's
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
  // Nor like a geometry image: `encode DIR -o DIR/x.geometry.exr` would replace its own input.
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".exr")
    throw InvalidInput("-o " + path + ": this writes a .gip pack, not an EXR image; name it .gip");
}

}  // namespace geomip::tools
