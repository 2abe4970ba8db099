#pragma once
// A roadside unit's 2-D fix of the vehicle and its checks on the way to the filter. The fix becomes a
// pose measurement with the RSU's variance on x and y and +infinity on z, roll, pitch and yaw: the
// filter then updates x and y only.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "coloc/core/types.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::rsu_client {

struct RsuFix {
  Stamp stamp = 0;       ///< LiDAR capture time of the frame the vehicle was detected in
  std::string rsu_id;
  double x = 0.0, y = 0.0;    ///< vehicle reference point, map frame
  std::optional<double> yaw;  ///< heading from the L-shape fit, if sent (not fused: see README)
};

enum class FixRejection : std::uint8_t { kNone, kUnknownRsu, kNonFinite, kOutOfCoverage, kStale, kFromFuture, kDuplicate };
const char* toString(FixRejection reason);

struct FixCheckConfig {
  double max_age = 1.0;           ///< s; older fixes cannot be applied by the filter anyway
  double future_tolerance = 0.05; ///< s of clock disagreement tolerated
};

struct FixCounters {
  std::uint64_t received = 0, accepted = 0, unknown_rsu = 0, non_finite = 0, out_of_coverage = 0, stale = 0, from_future = 0,
                duplicate = 0;
};

struct FixVerdict {
  FixRejection rejection = FixRejection::kNone;
  std::string detail;           ///< names the fix and the reason
  PoseMeasurement measurement;  ///< valid when accepted
  bool accepted() const { return rejection == FixRejection::kNone; }
};

class FixChecker {
 public:
  FixChecker(RsuRegistry registry, FixCheckConfig config = {});

  /// Checks a fix received at `now` (vehicle clock) and converts it. Never throws.
  FixVerdict check(const RsuFix& fix, Stamp now);

  /// Counters per RSU id; fixes naming an unknown RSU are counted under that (unknown) id too.
  const std::map<std::string, FixCounters>& counters() const { return counters_; }
  const RsuRegistry& registry() const { return registry_; }

 private:
  /// The checks after the RSU is known and its calibration applied.
  FixVerdict checkKnown(const RsuFix& fix, Stamp now, const RsuInfo& rsu, FixCounters& counters);
  RsuRegistry registry_;
  FixCheckConfig config_;
  std::map<std::string, FixCounters> counters_;
  std::map<std::string, std::deque<Stamp>> recent_;  ///< stamps seen per RSU within max_age, for duplicates
};

}  // namespace coloc::rsu_client
