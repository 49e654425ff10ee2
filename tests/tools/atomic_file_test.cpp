// AtomicFileSet: a command's output files, all or nothing (tools/atomic_file.h).
#include "tools/atomic_file.h"

#include "mesh/errors.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

namespace geomip::tools {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

class AtomicFileSetTest : public ::testing::Test {
 protected:
  std::string dir_ = test::temp_dir("atomic_file");
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  void put(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }
  /// The names in the directory (recursively, relative to it), temporary files included.
  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      names.insert(e.path().lexically_relative(dir_).string());
    return names;
  }
  static std::function<void(std::ostream&)> text(const std::string& t) {
    return [t](std::ostream& out) { out << t; };
  }
};

// A command that fails after making its output directory (a full disk while writing) left it behind, empty:
// the directories it made go again when empty, those that were there stay, and a run that ends keeps them.
TEST_F(AtomicFileSetTest, AFailedRunLeavesNoEmptyOutputDirectory) {
  fs::create_directories(path("there"));
  try {
    const CreatedDirectories created = make_output_directory(path("there/a/b/c"));
    ASSERT_TRUE(fs::is_directory(path("there/a/b/c")));
    throw IoError("disk full");
  } catch (const IoError&) {
  }
  EXPECT_EQ(listing(), std::set<std::string>{"there"});
  try {  // a directory that holds a file by then stays, with its parents
    const CreatedDirectories created = make_output_directory(path("there/x/y"));
    put("there/x/keep", "k");
    throw IoError("later failure");
  } catch (const IoError&) {
  }
  EXPECT_EQ(listing(), (std::set<std::string>{"there", "there/x", "there/x/keep"}));
  { const CreatedDirectories created = make_output_directory(path("there/ok/d")); }
  EXPECT_TRUE(fs::is_directory(path("there/ok/d")));
  try {  // made while another exception was already being handled: only its own failure counts
    throw std::runtime_error("outer");
  } catch (const std::runtime_error&) {
    const CreatedDirectories created = make_output_directory(path("there/inner"));
  }
  EXPECT_TRUE(fs::is_directory(path("there/inner")));
}

TEST_F(AtomicFileSetTest, CommitReplacesEveryTargetOnlyThen) {
  put("a.obj", "old a");
  fs::create_directory(path("sub"));
  AtomicFileSet files;
  EXPECT_EQ(files.add(path("a.obj"), text("new a")), 5u);
  files.add(path("b.ply"), text("new b"));
  files.add(path("sub/c.glb"), text("new c"));
  // Before commit: the targets as they were, the new bytes in temporaries beside them.
  EXPECT_EQ(slurp(path("a.obj")), "old a");
  EXPECT_FALSE(fs::exists(path("b.ply")));
  EXPECT_FALSE(fs::exists(path("sub/c.glb")));
  EXPECT_EQ(listing().size(), 5u);  // a.obj, sub, three temporaries
  files.commit();
  EXPECT_EQ(slurp(path("a.obj")), "new a");
  EXPECT_EQ(slurp(path("b.ply")), "new b");
  EXPECT_EQ(slurp(path("sub/c.glb")), "new c");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj", "b.ply", "sub", "sub/c.glb"}));
  files.commit();  // again: nothing
  EXPECT_EQ(slurp(path("a.obj")), "new a");
}

TEST_F(AtomicFileSetTest, WithoutCommitTargetsStayAndTemporariesGo) {
  put("a.obj", "old a");
  {
    AtomicFileSet files;
    files.add(path("a.obj"), text("new a"));
    files.add(path("b.ply"), text("new b"));
  }
  EXPECT_EQ(slurp(path("a.obj")), "old a");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj"}));
}

TEST_F(AtomicFileSetTest, AThrowingWriterLeavesNothing) {
  put("a.obj", "old a");
  {
    AtomicFileSet files;
    files.add(path("a.obj"), text("new a"));
    EXPECT_THROW(files.add(path("b.ply"),
                           [](std::ostream& out) {
                             out << "half of b";
                             throw std::runtime_error("the writer failed");
                           }),
                 std::runtime_error);
    EXPECT_EQ(listing().size(), 2u);  // a.obj and a's temporary: b's is gone at once
  }
  EXPECT_EQ(slurp(path("a.obj")), "old a");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj"}));
}

TEST_F(AtomicFileSetTest, ATargetThatCannotBeWrittenFailsItsAddNamingIt) {
  fs::create_directory(path("c.glb"));
  AtomicFileSet files;
  files.add(path("a.obj"), text("a"));
  try {
    files.add(path("c.glb"), text("c"));
    FAIL() << "a directory was taken as a file";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(path("c.glb")), std::string::npos) << e.what();
  }
  EXPECT_THROW(files.add(path("missing/d.obj"), text("d")), InvalidInput);
}

TEST_F(AtomicFileSetTest, OneFileUnderTwoNamesIsRefused) {
  fs::create_directory(path("sub"));
  fs::create_directory_symlink(path("sub"), path("link"));
  AtomicFileSet files;
  files.add(path("sub/a.obj"), text("a"));
  EXPECT_THROW(files.add(path("sub/../sub/a.obj"), text("a again")), InvalidInput);
  EXPECT_THROW(files.add(path("link/a.obj"), text("a again")), InvalidInput);
  files.commit();
  EXPECT_EQ(slurp(path("sub/a.obj")), "a");
}

TEST_F(AtomicFileSetTest, ADirectoryMadeAtATargetBeforeCommitStopsItBeforeAnyRename) {
  put("a.obj", "old a");
  AtomicFileSet files;
  files.add(path("a.obj"), text("new a"));
  files.add(path("b.ply"), text("new b"));
  fs::create_directory(path("b.ply"));
  EXPECT_THROW(files.commit(), InvalidInput);
  EXPECT_EQ(slurp(path("a.obj")), "old a");
}

// Renames are one per file: when one fails midway, the message says which targets were replaced already and
// which were left as they were.
TEST_F(AtomicFileSetTest, ARenameFailingMidwayNamesWhatWasReplaced) {
  put("a.obj", "old a");
  put("b.ply", "old b");
  put("c.glb", "old c");
  {
    AtomicFileSet files;
    files.add(path("a.obj"), text("new a"));
    files.add(path("b.ply"), text("new b"));
    files.add(path("c.glb"), text("new c"));
    // b's temporary taken away behind the set's back: its rename fails.
    for (const std::string& name : listing())
      if (name.rfind(".b.ply.tmp-", 0) == 0) fs::remove(path(name));
    try {
      files.commit();
      FAIL() << "the rename of a missing temporary file succeeded";
    } catch (const IoError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind(path("b.ply") + ": ", 0), 0u) << message;
      EXPECT_NE(message.find("written already: " + path("a.obj")), std::string::npos) << message;
      EXPECT_NE(message.find("left as they were: " + path("c.glb")), std::string::npos) << message;
    }
  }
  EXPECT_EQ(slurp(path("a.obj")), "new a");
  EXPECT_EQ(slurp(path("b.ply")), "old b");
  EXPECT_EQ(slurp(path("c.glb")), "old c");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj", "b.ply", "c.glb"}));
}

// A device is written in place (never replaced), by commit() and before any rename: a full one fails the set
// while every file target is as it was.
TEST_F(AtomicFileSetTest, ADeviceIsWrittenFirstByCommit) {
  if (!fs::is_character_file("/dev/full") || !fs::is_character_file("/dev/null"))
    GTEST_SKIP() << "no /dev/full or /dev/null";
  put("a.obj", "old a");
  fs::create_symlink("/dev/full", path("full.ply"));
  {
    AtomicFileSet files;
    files.add(path("a.obj"), text("new a"));
    files.add(path("full.ply"), text("bytes"));  // kept in memory: nothing failed yet
    try {
      files.commit();
      FAIL() << "/dev/full took the bytes";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path("full.ply") + ": write failed"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(slurp(path("a.obj")), "old a");
  EXPECT_TRUE(fs::is_symlink(path("full.ply")));
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj", "full.ply"}));
  AtomicFileSet files;
  files.add(path("a.obj"), text("new a"));
  files.add("/dev/null", text("x"));
  files.add("/dev/null", text("y"));  // a device twice is no conflict
  files.commit();
  EXPECT_EQ(slurp(path("a.obj")), "new a");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

// add_file(): writers that take a file name (the EXR writer) write the temporary file themselves.
TEST_F(AtomicFileSetTest, FileWritersWriteTheTemporaryFile) {
  put("a.exr", "old a");
  {
    AtomicFileSet files;
    EXPECT_EQ(files.add_file(path("a.exr"), [](const std::string& file) { std::ofstream(file) << "new a"; }),
              5u);
    EXPECT_THROW(files.add_file(path("b.exr"), [](const std::string&) {}), IoError);  // no file made
    EXPECT_THROW(files.add_file(path("c.exr"),
                                [](const std::string& file) {
                                  std::ofstream(file) << "half";
                                  throw IoError("out of space");
                                }),
                 IoError);
    EXPECT_EQ(slurp(path("a.exr")), "old a");
  }
  EXPECT_EQ(listing(), (std::set<std::string>{"a.exr"}));
  AtomicFileSet files;
  files.add_file(path("a.exr"), [](const std::string& file) { std::ofstream(file) << "new a"; });
  if (fs::is_character_file("/dev/null"))
    files.add_file("/dev/null", [](const std::string& file) { std::ofstream(file) << "to a device"; });
  files.commit();
  EXPECT_EQ(slurp(path("a.exr")), "new a");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.exr"}));
}

// write_file_atomically(), for one file, as before.
TEST_F(AtomicFileSetTest, WriteFileAtomicallyStillReplacesOrKeeps) {
  put("a.obj", "old a");
  EXPECT_THROW(write_file_atomically(path("a.obj"),
                                     [](std::ostream& out) {
                                       out << "half";
                                       throw std::runtime_error("failed");
                                     }),
               std::runtime_error);
  EXPECT_EQ(slurp(path("a.obj")), "old a");
  write_file_atomically(path("a.obj"), text("new a"));
  EXPECT_EQ(slurp(path("a.obj")), "new a");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.obj"}));
}

// check_planned_outputs(): remesh, param and gimage check every file they will write before the work, so a
// directory named like an output is found at once, not after the parameterization (those commands left
// nothing behind either way, but spent the minutes first).
TEST_F(AtomicFileSetTest, PlannedOutputsInTheWayAreFoundBeforeTheWork) {
  fs::create_directory(path("bunny.M6.glb"));  // a directory where an output file goes
  try {
    check_planned_outputs(dir_, {path("bunny.M6.obj"), path("bunny.M6.glb")});
    ADD_FAILURE() << "a directory named like an output was not found";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(path("bunny.M6.glb")), std::string::npos) << e.what();
  }
  check_planned_outputs(dir_, {path("bunny.M6.obj"), path("bunny.M6.ply")});  // nothing in the way
  EXPECT_EQ(listing(), (std::set<std::string>{"bunny.M6.glb"})) << "the check creates nothing";
  // An output directory that does not exist yet holds nothing in the way (the command makes it later).
  check_planned_outputs(path("later"), {path("later/bunny.M6.obj")});
  EXPECT_FALSE(fs::exists(path("later")));
}

}  // namespace
}  // namespace geomip::tools
