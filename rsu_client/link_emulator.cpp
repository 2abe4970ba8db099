#include "coloc/rsu_client/link_emulator.hpp"

#include <algorithm>

namespace coloc::rsu_client {

LinkEmulator::LinkEmulator(const LinkConfig& config) : config_(config), rng_(config.seed) {}

std::optional<Stamp> LinkEmulator::transmit(Stamp sent) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  // Draw the same number of random numbers per message whatever happens, so that the loss pattern
  // does not depend on the delays drawn and vice versa.
  const double u_state = uniform(rng_), u_loss = uniform(rng_);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double z = normal(rng_);
  bool lost;
  if (config_.burst) {
    bad_ = bad_ ? !(u_state < config_.p_bad_to_good) : (u_state < config_.p_good_to_bad);
    lost = u_loss < (bad_ ? config_.loss_in_bad : config_.loss_in_good);
  } else {
    lost = u_loss < config_.loss;
  }
  if (lost) return std::nullopt;
  const double delay = std::max(0.0, config_.delay + config_.jitter * z);
  return sent + fromSeconds(delay);
}

double LinkEmulator::expectedLoss() const {
  if (!config_.burst) return config_.loss;
  const double to_bad = config_.p_good_to_bad, to_good = config_.p_bad_to_good;
  if (to_bad + to_good <= 0.0) return config_.loss_in_good;
  const double share_bad = to_bad / (to_bad + to_good);
  return share_bad * config_.loss_in_bad + (1.0 - share_bad) * config_.loss_in_good;
}

}  // namespace coloc::rsu_client
