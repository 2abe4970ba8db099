#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/link_emulator.hpp"

namespace coloc::rsu_client {
namespace {

struct LinkRun {
  int lost = 0;
  int bursts = 0;  ///< runs of consecutive losses
  double mean_delay = 0.0;
  double min_delay = 1e9;
};

LinkRun simulate(const LinkConfig& config, int n) {
  LinkEmulator link(config);
  LinkRun r;
  bool previous_lost = false;
  int delivered = 0;
  for (int i = 0; i < n; ++i) {
    const Stamp sent = i * 100'000'000LL;
    const auto delivery = link.transmit(sent);
    if (!delivery) {
      ++r.lost;
      if (!previous_lost) ++r.bursts;
      previous_lost = true;
      continue;
    }
    previous_lost = false;
    const double d = toSeconds(*delivery - sent);
    r.mean_delay += d;
    r.min_delay = std::min(r.min_delay, d);
    ++delivered;
  }
  r.mean_delay /= std::max(delivered, 1);
  return r;
}

TEST(LinkEmulator, SameSeedGivesTheSameDeliveries) {
  LinkConfig config;
  config.delay = 0.03;
  config.jitter = 0.01;
  config.loss = 0.2;
  config.seed = 42;
  LinkEmulator a(config), b(config);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(a.transmit(i * 1000), b.transmit(i * 1000));
  config.seed = 43;
  LinkEmulator c(config), d(LinkConfig{0.03, 0.01, 0.2, false, 0.05, 0.5, 0.0, 0.8, 42});
  int differences = 0;
  for (int i = 0; i < 1000; ++i) differences += c.transmit(i * 1000) != d.transmit(i * 1000);
  EXPECT_GT(differences, 100);
}

TEST(LinkEmulator, IndependentLossAndDelayMatchTheConfiguration) {
  LinkConfig config;
  config.delay = 0.030;
  config.jitter = 0.005;
  config.loss = 0.20;
  const LinkRun r = simulate(config, 20000);
  EXPECT_NEAR(r.lost / 20000.0, 0.20, 0.015);
  EXPECT_NEAR(r.mean_delay, 0.030, 0.001);
  EXPECT_GE(r.min_delay, 0.0);
}

TEST(LinkEmulator, GilbertElliottLossComesInBurstsAtItsLongRunRate) {
  LinkConfig burst;
  burst.burst = true;
  burst.p_good_to_bad = 0.05;
  burst.p_bad_to_good = 0.25;
  burst.loss_in_bad = 1.0;
  const double expected = LinkEmulator(burst).expectedLoss();
  EXPECT_NEAR(expected, 0.05 / 0.30, 1e-12);
  const LinkRun bursty = simulate(burst, 40000);
  EXPECT_NEAR(bursty.lost / 40000.0, expected, 0.02);
  LinkConfig independent;
  independent.loss = expected;
  const LinkRun flat = simulate(independent, 40000);
  // Same loss rate, fewer and longer runs of losses.
  EXPECT_GT(static_cast<double>(bursty.lost) / bursty.bursts, 2.5 * static_cast<double>(flat.lost) / flat.bursts);
}

TEST(LinkEmulator, LargeJitterNeverDeliversBeforeSending) {
  LinkConfig config;
  config.delay = 0.001;
  config.jitter = 0.05;
  EXPECT_GE(simulate(config, 5000).min_delay, 0.0);
}

// A delay or loss outside its range is an error naming the field, not a link that silently delivers
// at once (negative delay), drops everything (loss above 1) or drops nothing (NaN).
TEST(LinkEmulator, RefusesADelayOrProbabilityOutsideItsRangeNamingTheField) {
  const auto message = [](const LinkConfig& c) {
    try {
      LinkEmulator link(c);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const double nan = std::nan("");
  struct Case {
    LinkConfig config;
    const char* field;
  };
  std::vector<Case> cases;
  LinkConfig c;
  c.delay = -0.01, cases.push_back({c, "delay"}), c = LinkConfig();
  c.delay = nan, cases.push_back({c, "delay"}), c = LinkConfig();
  c.jitter = std::numeric_limits<double>::infinity(), cases.push_back({c, "jitter"}), c = LinkConfig();
  c.loss = 1.5, cases.push_back({c, "loss"}), c = LinkConfig();
  c.loss = nan, cases.push_back({c, "loss"}), c = LinkConfig();
  c.p_good_to_bad = -0.1, cases.push_back({c, "p_good_to_bad"}), c = LinkConfig();
  c.loss_in_bad = 2.0, cases.push_back({c, "loss_in_bad"}), c = LinkConfig();
  for (const Case& k : cases) {
    const std::string what = message(k.config);
    EXPECT_NE(what.find(std::string("link: ") + k.field + " must be"), std::string::npos) << k.field << ": '" << what << "'";
  }
  LinkConfig edges;
  edges.delay = 0.0, edges.jitter = 0.0, edges.loss = 1.0, edges.loss_in_good = 0.0, edges.loss_in_bad = 1.0;
  EXPECT_EQ(message(edges), "");  // the bounds themselves are allowed
}

}  // namespace
}  // namespace coloc::rsu_client
