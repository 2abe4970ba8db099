#pragma once
// A roadside unit's 2-D fix of the vehicle and its checks on the way to the filter. The fix becomes a
// pose measurement with the RSU's variance on x and y and +infinity on z, roll, pitch and yaw: the
// filter then updates x and y only.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::rsu_client {

/// What a fix message said beside its position: a fix that came from a message (over DDS or from a
/// log) carries it and is checked against it; a fix made in-process (the twin, a vehicle stack's own
/// RSU code) has none, its frame and covariance being the registry's by construction.
struct SentFields {
  std::string frame_id;                       ///< header.frame_id as sent
  Matrix6d covariance = Matrix6d::Zero();     ///< pose.covariance as sent, row-major x y z roll pitch yaw
  std::uint32_t nanosec = 0;                  ///< header.stamp.nanosec as sent (a valid stamp has < 1e9)
};

struct RsuFix {
  Stamp stamp = 0;       ///< LiDAR capture time of the frame the vehicle was detected in
  std::string rsu_id;
  double x = 0.0, y = 0.0;    ///< vehicle reference point, map frame
  std::optional<double> yaw;  ///< heading from the L-shape fit, if sent (not fused: see README)
  std::optional<SentFields> sent;
};

enum class FixRejection : std::uint8_t {
  kNone, kUnknownRsu, kNonFinite, kOutOfCoverage, kStale, kFromFuture, kDuplicate, kWrongFrame, kBadCovariance, kBadStamp
};
const char* toString(FixRejection reason);

struct FixCheckConfig {
  double max_age = 1.0;           ///< s; older fixes cannot be applied by the filter anyway
  double future_tolerance = 0.05; ///< s of clock disagreement tolerated
};

struct FixCounters {
  std::uint64_t received = 0, accepted = 0, unknown_rsu = 0, non_finite = 0, out_of_coverage = 0, stale = 0, from_future = 0,
                duplicate = 0, wrong_frame = 0, bad_covariance = 0, bad_stamp = 0;
};

/// Each refusal reason's name (toString of its FixRejection) with its count, in enum order: what
/// reports and summaries list, so that a new reason appears in all of them.
std::vector<std::pair<const char*, std::uint64_t>> refusals(const FixCounters& counters);

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
  /// What the message said (frame, covariance, stamp field) against the registry; kNone if it agrees.
  FixVerdict checkSent(const RsuFix& fix, const RsuInfo& rsu, FixCounters& counters) const;
  /// The checks after the RSU is known and its calibration applied.
  FixVerdict checkKnown(const RsuFix& fix, Stamp now, const RsuInfo& rsu, FixCounters& counters);
  RsuRegistry registry_;
  FixCheckConfig config_;
  std::map<std::string, FixCounters> counters_;
  std::map<std::string, std::deque<Stamp>> recent_;  ///< stamps seen per RSU within max_age, for duplicates
};

}  // namespace coloc::rsu_client
