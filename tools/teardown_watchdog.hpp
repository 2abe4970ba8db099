#pragma once
// Fast DDS can stall while a participant is deleted (its timer and security threads wait on each other;
// several such stalls are known upstream). A command-line tool whose work is done must still exit, so
// the DDS commands arm this guard before their participants are destroyed: if teardown has not finished
// within the grace period, the process says so and exits with the status its work earned.
namespace coloc::tools {

class TeardownWatchdog {
 public:
  /// Declare it after the DDS objects, so that it is destroyed (and armed) before them.
  explicit TeardownWatchdog(const char* command, double grace_seconds = 10.0) : command_(command), grace_(grace_seconds) {}
  ~TeardownWatchdog();
  TeardownWatchdog(const TeardownWatchdog&) = delete;
  TeardownWatchdog& operator=(const TeardownWatchdog&) = delete;

 private:
  const char* command_;
  double grace_;
};

}  // namespace coloc::tools
