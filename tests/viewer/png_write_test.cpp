// Screenshots are written atomically: through a temporary file beside the target, renamed over it. A write
// that fails (a full disk, simulated by a file-size limit; a directory that does not exist) leaves an
// existing file as it was and no temporary file, and libpng prints nothing (the viewer says one line).
#include "stream_viewer/png_write.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace geomip::viewer {
namespace {

namespace fs = std::filesystem;

class PngWrite : public ::testing::Test {
 protected:
  fs::path dir_ = fs::temp_directory_path() / ("png_write_test-" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    return names;
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Noise: it does not compress, so the PNG is about the pixels' size.
std::vector<std::uint8_t> noise(int w, int h) {
  std::mt19937 rng(7);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * h * 3);
  for (auto& c : rgb) c = static_cast<std::uint8_t>(rng());
  return rgb;
}

TEST_F(PngWrite, ReplacesAnExistingFileThroughATemporaryOne) {
  const fs::path png = dir_ / "shot.png";
  std::ofstream(png) << "old";
  struct stat before {};
  ASSERT_EQ(::stat(png.c_str(), &before), 0);
  const auto rgb = noise(40, 30);
  std::string error;
  ASSERT_TRUE(write_png(png.string(), 40, 30, rgb, error)) << error;
  int w = 0, h = 0;
  std::vector<std::uint8_t> back;
  ASSERT_TRUE(read_png(png.string(), w, h, back));
  EXPECT_EQ(w, 40);
  EXPECT_EQ(h, 30);
  EXPECT_EQ(back, rgb);
  struct stat after {};
  ASSERT_EQ(::stat(png.c_str(), &after), 0);
  EXPECT_NE(after.st_ino, before.st_ino) << "renamed into place, not written over the old file";
  EXPECT_EQ(files(), std::vector<std::string>{"shot.png"}) << "no temporary file left";
}

// A full disk, simulated by a file-size limit (as `ulimit -f`; SIGXFSZ ignored, so writes fail with EFBIG):
// the old file stays, no temporary file is left, one line in `error`, nothing on stderr.
TEST_F(PngWrite, AFailedWriteLeavesTheOldFileAndPrintsNothing) {
  const fs::path png = dir_ / "shot.png";
  std::ofstream(png) << "old";
  const auto rgb = noise(256, 256);  // ~200 KB: past the limit
  const fs::path err_file = dir_ / "stderr.txt";
  std::fflush(stderr);
  const int saved_stderr = ::dup(2);
  FILE* err = std::fopen(err_file.c_str(), "w");
  ASSERT_NE(err, nullptr);
  ::dup2(::fileno(err), 2);
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = saved;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string error;
  const bool ok = write_png(png.string(), 256, 256, rgb, error);
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);
  std::fflush(stderr);
  ::dup2(saved_stderr, 2);
  ::close(saved_stderr);
  std::fclose(err);
  EXPECT_FALSE(ok);
  EXPECT_NE(error.find(png.string()), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(slurp(png), "old");
  EXPECT_EQ(slurp(err_file), "") << "libpng printed its own message";
  fs::remove(err_file);
  EXPECT_EQ(files(), std::vector<std::string>{"shot.png"}) << "no temporary file left";
}

// A named pipe (or a device such as /dev/null) is written through: a rename would replace the node.
TEST_F(PngWrite, APipeIsWrittenThroughNotReplaced) {
  const fs::path fifo = dir_ / "pipe.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // so the writer's open does not block
  ASSERT_GE(reader, 0);
  std::string error;
  EXPECT_TRUE(check_png_output(fifo.string(), error)) << error;
  const bool ok = write_png(fifo.string(), 8, 8, noise(8, 8), error);  // ~250 bytes: within the pipe's buffer
  std::string received;
  std::array<char, 4096> buffer{};
  for (ssize_t n; (n = ::read(reader, buffer.data(), buffer.size())) > 0;)
    received.append(buffer.data(), static_cast<std::size_t>(n));
  ::close(reader);
  EXPECT_TRUE(ok) << error;
  EXPECT_EQ(received.substr(0, 4), "\x89PNG") << received.size() << " bytes through the pipe";
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe was replaced";
  EXPECT_EQ(files(), std::vector<std::string>{"pipe.png"});
}

// Found by a review on 2026-12-06: a named pipe that nothing reads blocked the write for ever (the viewer
// hung after rendering), and a 255-byte name failed because its temporary ".<name>.tmp-<pid>" was too long.
TEST_F(PngWrite, APipeWithoutAReaderFailsAndALongNameIsWritten) {
  const fs::path fifo = dir_ / "lonely.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string error;
  EXPECT_FALSE(write_png(fifo.string(), 4, 4, noise(4, 4), error));  // returns: no reader, no wait
  EXPECT_NE(error.find("nothing reads"), std::string::npos) << error;
  fs::remove(fifo);
  const fs::path longest = dir_ / (std::string(251, 'a') + ".png");
  EXPECT_TRUE(check_png_output(longest.string(), error)) << error;
  EXPECT_TRUE(write_png(longest.string(), 4, 4, noise(4, 4), error)) << error;
  EXPECT_EQ(slurp(longest).substr(0, 4), "\x89PNG");
  EXPECT_EQ(files(), std::vector<std::string>{longest.filename().string()}) << "no temporary file left";
}

TEST_F(PngWrite, MissingDirectoriesAreSaidBeforeAndNothingIsCreated) {
  const std::string missing = (dir_ / "no-such-dir" / "shot.png").string();
  std::string error;
  EXPECT_FALSE(check_png_output(missing, error));
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
  EXPECT_FALSE(write_png(missing, 4, 4, noise(4, 4), error));
  EXPECT_FALSE(check_png_output(dir_.string(), error));
  EXPECT_NE(error.find("is a directory"), std::string::npos) << error;
  EXPECT_TRUE(check_png_output((dir_ / "shot.png").string(), error)) << error;
  EXPECT_TRUE(files().empty()) << "the probe file is removed";
}

}  // namespace
}  // namespace geomip::viewer
