#pragma once
// A one-line progress bar on stderr, drawn only when stderr is a terminal, so logs and CI output
// stay clean.
#include <chrono>
#include <string>

namespace coloc::tools {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  /// fraction in [0, 1]; redraws at most ten times a second.
  void update(double fraction);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point last_draw_{};
  std::chrono::steady_clock::time_point start_;
};

}  // namespace coloc::tools
