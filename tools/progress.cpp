#include "tools/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace geomip::tools {

bool stderr_is_terminal() { return isatty(fileno(stderr)) == 1; }

ProgressBar::ProgressBar(std::string task, bool enabled)
    : task_(std::move(task)),
      enabled_(enabled && stderr_is_terminal()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(const char* stage, double fraction) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < std::chrono::seconds(1)) return;              // short work: no bar
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;  // 10 Hz at most
  last_draw_ = now;
  drawn_ = true;
  constexpr int kWidth = 30;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const double seconds = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stderr, "\r\033[K%s [%.*s%*s] %3d%% %s (%.0f s)", task_.c_str(), filled,
               "==============================", kWidth - filled, "", static_cast<int>(fraction * 100 + 0.5),
               stage ? stage : "", seconds);
  std::fflush(stderr);
}

ProgressCallback ProgressBar::callback() {
  if (!enabled_) return {};
  return [this](const char* stage, double fraction) { update(stage, fraction); };
}

void ProgressBar::finish() {
  if (drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
  }
}

}  // namespace geomip::tools
