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
  /// An addressed fix (nav_msgs/msg/Odometry): its child_frame_id as sent, which must be the station id
  /// of the vehicle it is for in decimal; unset for an unaddressed fix (PoseWithCovarianceStamped).
  std::optional<std::string> child_frame_id;
};

struct RsuFix {
  Stamp stamp = 0;       ///< LiDAR capture time of the frame the vehicle was detected in
  std::string rsu_id;
  double x = 0.0, y = 0.0;    ///< vehicle reference point, map frame
  std::optional<double> yaw;  ///< heading from the L-shape fit, if sent (not fused: see README)
  std::optional<SentFields> sent;
  /// The connected vehicle the fix is for: the station id its CAM carries (ETSI EN 302 637-2). Unset:
  /// an unaddressed fix, which any vehicle that hears it could take for its own.
  std::optional<std::uint32_t> station_id;
};

/// The station id an addressed fix's child_frame_id names: decimal digits only, 0 to 4294967295.
std::optional<std::uint32_t> parseStationId(const std::string& text);

enum class FixRejection : std::uint8_t {
  kNone, kUnknownRsu, kNonFinite, kOutOfCoverage, kStale, kFromFuture, kDuplicate, kWrongFrame, kBadCovariance, kBadStamp,
  kBadAddress,          ///< an addressed fix whose child_frame_id is not a station id
  kAddressedToAnother,  ///< addressed to another connected vehicle
  kUnaddressed          ///< names no vehicle, and the configuration does not take such fixes
};
const char* toString(FixRejection reason);

struct FixCheckConfig {
  double max_age = 1.0;           ///< s; older fixes cannot be applied by the filter anyway
  double future_tolerance = 0.05; ///< s of clock disagreement tolerated
  /// This vehicle's station id (its CAM's): only fixes addressed to it are taken. Unset: every
  /// addressed fix is someone else's.
  std::optional<std::uint32_t> station_id;
  /// Take fixes that name no vehicle (the unaddressed topic): only where one connected vehicle can be
  /// seen by the RSU, since another car's fix would otherwise be taken for this one's.
  bool accept_unaddressed = false;
};

/// A fix is received, then refused by one check or passed on; what the filter then made of the ones
/// passed on (applied, gated, not initialised, ...) is the pipeline's to add (FilterOutcomes).
struct FixCounters {
  std::uint64_t received = 0, passed_checks = 0, unknown_rsu = 0, non_finite = 0, out_of_coverage = 0, stale = 0, from_future = 0,
                duplicate = 0, wrong_frame = 0, bad_covariance = 0, bad_stamp = 0, bad_address = 0, addressed_to_another = 0,
                unaddressed = 0;
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
  /// Forgets the stamps kept for the duplicate check (the clock went back: a replayed stamp is new).
  void forgetRecent() { recent_.clear(); }

 private:
  /// What the message said (frame, covariance, stamp field) against the registry; kNone if it agrees.
  FixVerdict checkSent(const RsuFix& fix, const RsuInfo& rsu, FixCounters& counters) const;
  /// Whether the fix is for this vehicle (its station id), or unaddressed and taken by the configuration.
  FixVerdict checkAddress(const RsuFix& fix, FixCounters& counters) const;
  /// The checks after the RSU is known and its calibration applied.
  FixVerdict checkKnown(const RsuFix& fix, Stamp now, const RsuInfo& rsu, FixCounters& counters);
  RsuRegistry registry_;
  FixCheckConfig config_;
  std::map<std::string, FixCounters> counters_;
  /// Stamps seen per RSU and addressee within max_age, for duplicates.
  std::map<std::pair<std::string, std::optional<std::uint32_t>>, std::deque<Stamp>> recent_;
};

}  // namespace coloc::rsu_client
