#include "stream_viewer/png_write.h"

#include <fcntl.h>
#include <png.h>
#include <unistd.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace geomip::viewer {

namespace {

/// libpng's error and warning handlers: nothing printed (its default error handler writes to stderr, and the
/// viewer says one line itself); the error message is kept for that line.
[[noreturn]] void on_png_error(png_structp png, png_const_charp message) {
  auto* error = static_cast<std::string*>(png_get_error_ptr(png));
  if (error != nullptr && message != nullptr) *error = message;
  png_longjmp(png, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

/// The whole PNG into the open file `f`; false with `error` set (libpng's message) when libpng fails.
bool write_png_stream(FILE* f, int width, int height, const std::vector<std::uint8_t>& rgb,
                      std::string& error) {
  std::string png_error;
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &png_error, &on_png_error, &on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    error = "libpng: out of memory";
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    error = "libpng: " + (png_error.empty() ? std::string("write failed") : png_error);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(rgb.data() + static_cast<std::size_t>(y) * width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

/// An existing `path` that is neither a regular file nor a directory (a device such as /dev/null, a named
/// pipe): renaming a temporary file over it would replace the node, so it is written in place.
bool writes_in_place(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  return !ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) &&
         !std::filesystem::is_directory(st);
}

/// Writes the PNG into `file` (created or truncated: `opened`), flushed and closed; false with `problem` set.
bool write_png_file(const std::string& file, int width, int height, const std::vector<std::uint8_t>& rgb,
                    std::string& problem, bool& opened) {
  // Opened without blocking: a named pipe that nothing reads fails now (ENXIO) instead of waiting for ever
  // (probing it beforehand would hand a reader an end of file); then written as usual.
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NONBLOCK | O_CLOEXEC, 0666);
  if (fd < 0) {
    opened = false;
    problem = errno == ENXIO ? "'" + file + "' is a named pipe that nothing reads"
                             : "cannot create '" + file + "' (" + std::strerror(errno) + ")";
    return false;
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  FILE* f = ::fdopen(fd, "wb");
  opened = true;
  if (f == nullptr) {
    problem = "cannot write '" + file + "' (" + std::strerror(errno) + ")";
    ::close(fd);
    return false;
  }
  bool ok = write_png_stream(f, width, height, rgb, problem);
  if (ok && std::fflush(f) != 0) {
    ok = false;
    problem = std::strerror(errno);
  }
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    problem = std::strerror(errno);
  }
  return ok;
}

std::filesystem::path directory_of(const std::string& path) {
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  return dir.empty() ? std::filesystem::path(".") : dir;
}

}  // namespace

bool write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb,
               std::string& error) {
  namespace fs = std::filesystem;
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3) {
    error = "write_png: bad image size";
    return false;
  }
  std::string problem;
  bool opened = false;
  if (writes_in_place(path)) {
    if (write_png_file(path, width, height, rgb, problem, opened)) return true;
    error = "cannot write " + path + ": " + problem;
    return false;
  }
  const std::string filename = fs::path(path).filename().string();
  std::string suffix = ".tmp-";
  suffix += std::to_string(::getpid());
  std::string tmp_name = ".";  // appended, not "." + ...: GCC 12's -Wrestrict misfires on that
  tmp_name += filename;
  tmp_name += suffix;
  long name_max = ::pathconf(directory_of(path).c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = 255;
  if (tmp_name.size() > static_cast<std::size_t>(name_max)) {  // a name near the limit: a shorter temporary
    char hash[24];
    std::snprintf(hash, sizeof hash, "-%016zx", std::hash<std::string>{}(filename));
    tmp_name.assign(1, '.');
    tmp_name.append(filename, 0, std::min<std::size_t>(filename.size(), 64));
    tmp_name.append(hash);
    tmp_name.append(suffix);
  }
  const fs::path tmp = directory_of(path) / tmp_name;
  bool ok = write_png_file(tmp.string(), width, height, rgb, problem, opened);
  std::error_code ec;
  if (ok) {
    fs::rename(tmp, path, ec);
    if (ec) {
      ok = false;
      problem = "cannot rename the temporary file into place: " + ec.message();
    }
  }
  if (!ok) {
    if (opened) fs::remove(tmp, ec);  // ours only
    error = "cannot write " + path + ": " + problem;
  }
  return ok;
}

bool check_png_output(const std::string& path, std::string& error) {
  namespace fs = std::filesystem;
  if (path.empty()) {
    error = "the output path is empty";
    return false;
  }
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    error = path + ": is a directory, not a file to write";
    return false;
  }
  if (writes_in_place(path)) {  // a device or a pipe: written through, its directory is not touched
    if (::access(path.c_str(), W_OK) != 0) {
      error = path + ": is not writable";
      return false;
    }
    return true;
  }
  const fs::path dir = directory_of(path);
  if (!fs::is_directory(dir, ec)) {
    error = path + ": output directory '" + dir.string() + "' " +
            (fs::exists(dir, ec) ? "is not a directory" : "does not exist");
    return false;
  }
  // The same as the temporary file write_png() creates: a directory that takes no files although its
  // permissions say so (/proc, a read-only mount seen by root) is found now, not after the rendering.
  const fs::path probe = dir / (".geomip-view-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) {
    if (errno == EEXIST) return true;
    error = path + ": cannot create files in '" + dir.string() + "' (" + std::strerror(errno) + ")";
    return false;
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return true;
}

bool read_png(const std::string& path, int& width, int& height, std::vector<std::uint8_t>& rgb) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return false;
  image.format = PNG_FORMAT_RGB;
  width = static_cast<int>(image.width);
  height = static_cast<int>(image.height);
  rgb.assign(PNG_IMAGE_SIZE(image), 0);
  if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) {
    png_image_free(&image);
    return false;
  }
  return true;
}

}  // namespace geomip::viewer
