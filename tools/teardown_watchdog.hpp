#pragma once
// Fast DDS can stall while a participant is deleted (its timer, discovery and security threads wait
// on one another; several such stalls are known upstream), and a participant that fails to come up is
// deleted at once. A command-line tool whose work is done, or has failed, must still exit: while the
// watchdog is armed, the process has a grace period to end, after which it says so and exits with the
// status it had earned.
#include <memory>

namespace coloc::tools {

class TeardownWatchdog {
 public:
  explicit TeardownWatchdog(const char* command, double grace_seconds = 10.0);
  TeardownWatchdog(const TeardownWatchdog&) = delete;
  TeardownWatchdog& operator=(const TeardownWatchdog&) = delete;
  /// Leaves the watchdog armed: teardown continues after this object, down to the process's exit.
  ~TeardownWatchdog();

  /// From now on the process has the grace period to end; `status` is its exit status if it does not.
  void arm(int status);
  void disarm();

  /// Declare after the DDS objects: arms as they are about to be destroyed, by return or by exception.
  class ArmOnExit {
   public:
    explicit ArmOnExit(TeardownWatchdog& watchdog) : watchdog_(watchdog) {}
    ~ArmOnExit();
    ArmOnExit(const ArmOnExit&) = delete;
    ArmOnExit& operator=(const ArmOnExit&) = delete;

   private:
    TeardownWatchdog& watchdog_;
  };

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace coloc::tools
