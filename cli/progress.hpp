#pragma once
// A progress line on stderr for long work: "\rinterpatch: building  42%", shown
// only when stderr is a terminal and the work has lasted long enough to deserve
// it; silent otherwise (pipes, files, tests).

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "interpatch/progress.hpp"

namespace interpatch::cli {

class ProgressLine {
 public:
  explicit ProgressLine(std::string label, bool enabled = ::isatty(STDERR_FILENO) != 0)
      : label_(std::move(label)), enabled_(enabled), start_(std::chrono::steady_clock::now()) {}
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  ~ProgressLine() { clear(); }

  // The callback to hand to the library; empty (no reports at all) when silent.
  // It refers to this object, which must outlive the work.
  [[nodiscard]] progress_callback callback() {
    if (!enabled_) return {};
    return [this](double fraction) { update(fraction); };
  }

  void update(double fraction) {
    if (!enabled_) return;
    const int percent = std::clamp(static_cast<int>(fraction * 100.0), 0, 100);
    if (percent == last_) return;
    // Work that ends within half a second never shows a line.
    if (!shown_ && std::chrono::steady_clock::now() - start_ < std::chrono::milliseconds(500)) return;
    std::fprintf(stderr, "\rinterpatch: %s %3d%%", label_.c_str(), percent);
    std::fflush(stderr);
    shown_ = true;
    last_ = percent;
  }

  // Erases the line, so that what follows (an error, the shell prompt) starts clean.
  void clear() {
    if (!shown_) return;
    std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size()) + 18, "");
    std::fflush(stderr);
    shown_ = false;
    last_ = -1;
  }

 private:
  std::string label_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  bool shown_ = false;
  int last_ = -1;
};

}  // namespace interpatch::cli
