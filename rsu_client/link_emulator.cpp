#include "coloc/rsu_client/link_emulator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "coloc/core/error.hpp"

namespace coloc::rsu_client {

namespace {

std::string shown(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

void checkLinkConfig(const LinkConfig& c) {
  const auto seconds = [](double v, const char* name) {
    if (!(std::isfinite(v) && v >= 0.0)) throw Error(std::string("link: ") + name + " must be a finite number of seconds >= 0 (got " + shown(v) + ")");
  };
  const auto probability = [](double v, const char* name) {
    if (!(v >= 0.0 && v <= 1.0)) throw Error(std::string("link: ") + name + " must be a probability in [0, 1] (got " + shown(v) + ")");
  };
  seconds(c.delay, "delay");
  seconds(c.jitter, "jitter");
  probability(c.loss, "loss");
  probability(c.p_good_to_bad, "p_good_to_bad");
  probability(c.p_bad_to_good, "p_bad_to_good");
  probability(c.loss_in_good, "loss_in_good");
  probability(c.loss_in_bad, "loss_in_bad");
}

LinkEmulator::LinkEmulator(const LinkConfig& config) : config_(config), rng_(config.seed) { checkLinkConfig(config); }

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
