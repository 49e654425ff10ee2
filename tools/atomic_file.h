// Atomic output files: written to a temporary file beside the target, then renamed over it. A failed or
// interrupted run leaves no partial file under the target name (and removes its temporary file). A command
// that writes several files writes them as one AtomicFileSet: all of them or none.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace geomip::tools {

/// Calls `write` with a stream to a temporary file in the target's directory; on success flushes, closes and
/// renames it to `path`. If `write` throws or the stream fails, the temporary file is removed and the
/// exception (or an IoError) propagates; `path` is untouched. An existing `path` that is neither a regular
/// file nor a directory (/dev/null, /dev/full, a named pipe) is written in place instead (a rename would
/// replace the device node or the pipe); a failed write there is an IoError.
/// \throw IoError when the directory is not writable or the disk is full.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// The output files of one run, all or nothing: a decoded pack's meshes (one per model), a remesh's
/// .obj/.ply/.glb, a parameterization's .param.obj and .param.json.
///
/// add() writes each file as it comes to a temporary file beside its target (".<name>.tmp-<pid>"), so the
/// files of a set are never all in memory; the targets are not touched. commit() moves them into place
/// only when every add() has succeeded. A set destroyed without commit() (an add() threw, the command failed
/// in between) removes its temporary files: every target stays as it was, new or old.
///
/// Targets that are devices or pipes (/dev/null, /dev/full, a named pipe: written in place, as by
/// write_file_atomically()) are kept in memory by add() and written by commit() before any file is renamed:
/// a full device fails the set while no target has been replaced.
///
/// Not jointly atomic: the renames are one per file. commit() renames in the order of add() and stops at
/// the first that fails; the targets renamed before it stay replaced (the exception's message names them
/// and the ones left as they were). What usually makes a rename fail (a directory created at a target's
/// place since add()) is checked for every target before the first rename. A process killed by a signal
/// leaves its temporary files (hidden names, the pid in them), as write_file_atomically() does.
class AtomicFileSet {
 public:
  AtomicFileSet() = default;
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;
  /// Without a successful commit(): removes the temporary files; the targets are untouched.
  ~AtomicFileSet();

  /// Checks `path` (check_output_file()) and calls `write` with a stream to its temporary file, which is
  /// flushed and closed. Returns the bytes written. If `write` throws or the stream fails, that temporary
  /// file is removed and the exception (or an IoError naming `path`) propagates; the files added before
  /// stay added, to be committed or dropped.
  /// \throw InvalidInput when `path` cannot be written (check_output_file()) or is a file already in the
  /// set (under any name); IoError when the disk is full or the temporary file cannot be created.
  std::uintmax_t add(const std::string& path, const std::function<void(std::ostream&)>& write);

  /// add() for a writer that takes a file name, not a stream (write_geometry_image_exr()): `write` is given
  /// the temporary file's name and must create that file. Returns its size.
  /// \throw as add(); IoError when `write` returns without having created the file.
  std::uintmax_t add_file(const std::string& path, const std::function<void(const std::string& file)>& write);

  /// Writes the devices and pipes, then renames every temporary file over its target in the order added.
  /// Calling it again does nothing.
  /// \throw InvalidInput when a target has become a directory since add() (nothing replaced); IoError when
  /// a device write or a rename fails: its message names the failed target and, when some targets were
  /// replaced before it, lists those replaced and those left as they were.
  void commit();

 private:
  struct Entry {
    std::string path;                 ///< the target as given
    std::filesystem::path identity;   ///< its canonical directory and name; empty for a device or pipe
    std::filesystem::path temporary;  ///< beside it; empty for a device or pipe
    std::string bytes;                ///< a device's or pipe's contents, written by commit()
    bool done = false;                ///< renamed or written by commit()
  };
  /// A new entry for `path`, checked: writable, not in the set yet.
  Entry entry_for(const std::string& path) const;
  std::vector<Entry> entries_;
  bool committed_ = false;
};

/// Checks, before any work, that a pack output is not named like a mesh (x.obj, x.glb, ...) or an EXR image:
/// a .gip pack under such an extension would be opened as one by other tools. \throw InvalidInput naming
/// `path`.
void check_pack_output_name(const std::string& path);

/// Checks, before any work, that `path` can be written: not empty, not an existing directory, its directory
/// exists, is a directory, is writable and takes a file (a probe file is created and removed: /proc passes
/// the permission check and takes none); an existing device or pipe: writable itself. \throw InvalidInput
/// naming what is in the way, or when `path` is a file this run reads (note_input_file(); the same file
/// under any name).
void check_output_file(const std::string& path);

/// Notes that this run reads `path` (a mesh, a pack, a correspondence file): from then on every output
/// checked by check_output_file(), hence every file written by write_file_atomically() or an
/// AtomicFileSet, is refused when it is that file under any name (`repair a.obj -o a.obj`, `convert --points
/// c.json -o c.json`). Thread-safe; for the whole process.
void note_input_file(const std::string& path);

/// File-name parts for models whose names come from files (a pack's manifest, a mesh's stem): each name made
/// safe (no '/', '\\', control bytes or invalid UTF-8, which become '_'; "", "." and ".." become "model<i>")
/// and made unique (a repeated name gets "-<i>", i its index), in the order given.
std::vector<std::string> model_file_names(const std::vector<std::string>& names);

/// Checks, before any work, that `dir` can be made an output directory: not empty, and neither it nor a
/// parent exists as something other than a directory.
/// \throw InvalidInput naming what is in the way.
void check_output_directory(const std::string& dir);

/// Checks, before any work, the files a command will write into its output directory `dir` (each of `paths`,
/// as check_output_file()) when `dir` exists already: a directory or an unwritable file named like an output
/// is found before minutes of work instead of when the files are written. When `dir` does not exist yet,
/// nothing can be in the way (the command makes it after the work).
/// \throw InvalidInput naming the path in the way.
void check_planned_outputs(const std::string& dir, const std::vector<std::string>& paths);

/// The directories make_output_directory() created. When the command fails after that (its destructor runs
/// while an exception unwinds: a full disk, a file that cannot be written), those of them that are empty are
/// removed again, so a failed run leaves no empty output directory behind; a run that ends normally keeps
/// them.
class CreatedDirectories {
 public:
  CreatedDirectories() = default;
  explicit CreatedDirectories(std::vector<std::string> created);
  CreatedDirectories(CreatedDirectories&& other) noexcept;
  CreatedDirectories& operator=(CreatedDirectories&&) = delete;
  CreatedDirectories(const CreatedDirectories&) = delete;
  CreatedDirectories& operator=(const CreatedDirectories&) = delete;
  ~CreatedDirectories();

 private:
  std::vector<std::string> created_;  ///< outermost first
  int exceptions_ = 0;                ///< std::uncaught_exceptions() when made
};

/// Creates the output directory `dir` and its parents (nothing when it exists); keep the result alive until
/// the command's outputs are written (see CreatedDirectories).
/// \throw InvalidInput when it, or a parent, exists and is not a directory; IoError when it cannot be
/// created.
[[nodiscard]] CreatedDirectories make_output_directory(const std::string& dir);

}  // namespace geomip::tools
