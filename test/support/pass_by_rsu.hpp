#pragma once
// A car driving past an RSU through the whole pipeline: from x = -40 m along y = 0 at 10 m/s for 8 s,
// the RSU's fixes every fifth tick (10 Hz) where `fixAt` puts them for the car's true position, each
// with a few millimetres of scatter. Returns the filter's mean y from 2 to 6 s: how far to the left of
// its track the vehicle believes itself while the fixes steer it.
#include <cmath>
#include <functional>
#include <vector>

#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"

namespace coloc::testing {

inline double meanLeftOfTrackPassingRsu(const pipeline::Config& config, const rsu_client::RsuRegistry& registry,
                                        const std::function<Eigen::Vector2d(const Eigen::Vector2d& truth)>& fixAt,
                                        std::uint32_t station = 1001) {
  pipeline::Pipeline pipe(config, pipeline::PipelineOptions{std::nullopt, registry, false, {}, nullptr, nullptr});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  std::vector<fusion::Estimate> estimates;
  pipe.onEstimate([&](const fusion::Estimate& e) { estimates.push_back(e); });
  const auto truth = [&](Stamp t) { return Eigen::Vector2d(-40.0 + 10.0 * toSeconds(t - kStart), 0.0); };
  pipe.pushInitialPose(planarPose(kStart, -40.0, 0.0, 0.0, 0.01, 0.001), kStart);
  for (Stamp t = kStart; t <= kStart + 8'000'000'000; t += kTick) {
    pipe.pushTwist(odom, twist(t, 10.0, 0.0), t + 2'000'000);
    const int k = static_cast<int>((t - kStart) / kTick);
    if (k % 5 == 2) {
      const Eigen::Vector2d p = fixAt(truth(t)) + 0.005 * Eigen::Vector2d(std::sin(k), std::cos(3 * k));
      pipe.pushFix({t, "rsu_a", p.x(), p.y(), std::nullopt, std::nullopt, station}, t + 60'000'000);
    }
    pipe.runUntil(t);
  }
  double sum = 0.0;
  int n = 0;
  for (const fusion::Estimate& e : estimates)
    if (e.stamp >= kStart + 2'000'000'000 && e.stamp <= kStart + 6'000'000'000) sum += e.pose.position.y(), ++n;
  return n ? sum / n : std::nan("");
}

}  // namespace coloc::testing
