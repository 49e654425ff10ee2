// A terminal progress bar on stderr: drawn only when stderr is a terminal, the user did not ask for --quiet,
// and the work has already taken longer than a second. Silent otherwise (pipes, CI logs, tests).
#pragma once

#include "mesh/mesh.h"

#include <chrono>
#include <string>

namespace geomip::tools {

class ProgressBar {
 public:
  /// `enabled` = false makes every call a no-op (for --quiet and --json).
  ProgressBar(std::string task, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(const char* stage, double fraction);
  /// A callback for the library's Options structs.
  ProgressCallback callback();
  /// Erases the bar (called by the destructor too).
  void finish();

 private:
  std::string task_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

/// True when stderr is an interactive terminal.
bool stderr_is_terminal();

}  // namespace geomip::tools
