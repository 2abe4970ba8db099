#include "teardown_watchdog.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <thread>

namespace coloc::tools {

TeardownWatchdog::~TeardownWatchdog() {
  // Armed while unwinding from an error too: the error has not been printed yet, so say it failed.
  const int status = std::uncaught_exceptions() > 0 ? 1 : 0;
  std::thread([command = command_, grace = grace_, status] {
    std::this_thread::sleep_for(std::chrono::duration<double>(grace));
    std::fprintf(stderr, "coloc %s: DDS teardown did not finish within %.0f s; exiting without it%s\n", command, grace,
                 status ? " (the command had failed)" : "");
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(status);
  }).detach();
}

}  // namespace coloc::tools
