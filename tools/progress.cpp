#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace coloc::tools {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
  if (!enabled_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  if (fraction < 1.0 && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  fraction = std::clamp(fraction, 0.0, 1.0);
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%  %.1f s", label_.c_str(), filled, "##############################",
               kWidth - filled, "", static_cast<int>(fraction * 100.0), elapsed);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!enabled_ || finished_) return;
  update(1.0);
  finished_ = true;
  std::fprintf(stderr, "\n");
}

}  // namespace coloc::tools
