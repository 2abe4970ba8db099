#pragma once
// What a V2I radio link does to messages, for experiments: a fixed delay plus jitter, and loss that is
// either independent or bursty (a Gilbert-Elliott channel: a good and a bad state, each with its own
// loss probability). Seeded, so the same seed and the same sequence of sends give the same deliveries,
// on the DDS path and in offline replay alike.
#include <cstdint>
#include <optional>
#include <random>

#include "coloc/core/time.hpp"

namespace coloc::rsu_client {

struct LinkConfig {
  double delay = 0.0;   ///< s, fixed part
  double jitter = 0.0;  ///< s, standard deviation of a normal added to the delay (never below zero in total)
  double loss = 0.0;    ///< independent loss probability (used when burst is off)
  bool burst = false;   ///< Gilbert-Elliott instead of independent loss
  double p_good_to_bad = 0.05;
  double p_bad_to_good = 0.5;
  double loss_in_good = 0.0;
  double loss_in_bad = 0.8;
  std::uint64_t seed = 1;
};

/// Throws coloc::Error naming the field of a delay or jitter that is not a finite number of seconds
/// >= 0, or of a probability outside [0, 1]: a negative delay would be taken as none, a loss above 1
/// would drop everything, a NaN one nothing. LinkEmulator's constructor checks its configuration so.
void checkLinkConfig(const LinkConfig& config);

class LinkEmulator {
 public:
  explicit LinkEmulator(const LinkConfig& config);
  /// The delivery time of a message sent at `sent`, or nullopt if the link drops it.
  std::optional<Stamp> transmit(Stamp sent);
  /// Long-run loss rate of the configured channel.
  double expectedLoss() const;

 private:
  LinkConfig config_;
  std::mt19937_64 rng_;
  bool bad_ = false;
};

}  // namespace coloc::rsu_client
