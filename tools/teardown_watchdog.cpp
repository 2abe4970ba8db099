#include "teardown_watchdog.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace coloc::tools {

struct TeardownWatchdog::State {
  std::string command;
  std::chrono::duration<double> grace;
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<std::chrono::steady_clock::time_point> deadline;
  int status = 0;
};

TeardownWatchdog::TeardownWatchdog(const char* command, double grace_seconds) : state_(std::make_shared<State>()) {
  state_->command = command;
  state_->grace = std::chrono::duration<double>(grace_seconds);
  // Detached, holding the state: it must outlive this object to watch the process's exit.
  std::thread([s = state_] {
    std::unique_lock<std::mutex> lock(s->mutex);
    for (;;) {
      if (!s->deadline) {
        s->changed.wait(lock);
        continue;
      }
      if (s->changed.wait_until(lock, *s->deadline) == std::cv_status::timeout && s->deadline &&
          std::chrono::steady_clock::now() >= *s->deadline) {
        std::fprintf(stderr, "coloc %s: DDS teardown did not finish within %.0f s; exiting without it%s\n", s->command.c_str(),
                     s->grace.count(), s->status ? " (the command had failed)" : "");
        std::fflush(stdout);
        std::fflush(stderr);
        std::_Exit(s->status);
      }
    }
  }).detach();
}

TeardownWatchdog::~TeardownWatchdog() = default;

void TeardownWatchdog::arm(int status) {
  std::lock_guard<std::mutex> lock(state_->mutex);
  state_->status = status;
  state_->deadline = std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(state_->grace);
  state_->changed.notify_all();
}

void TeardownWatchdog::disarm() {
  std::lock_guard<std::mutex> lock(state_->mutex);
  state_->deadline.reset();
  state_->changed.notify_all();
}

TeardownWatchdog::ArmOnExit::~ArmOnExit() { watchdog_.arm(std::uncaught_exceptions() > 0 ? 1 : 0); }

}  // namespace coloc::tools
