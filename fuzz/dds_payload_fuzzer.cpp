// DDS samples as any participant on the domain may send them: the first byte picks the unaddressed fix,
// the addressed fix or the dimensions type, the rest is the serialized payload (encapsulation header first). Each is decoded by
// the guarded type the subscribers use; a decoded fix goes through the checks a received one passes.
#include <functional>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "OdometryPubSubTypes.h"
#include "PoseWithCovarianceStampedPubSubTypes.h"
#include "VehicleDimensionsPubSubTypes.h"
#include "coloc/rsu_client/rsu_fix.hpp"
#include "fix_sample.hpp"
#include "guarded_type.hpp"

namespace {

template <typename Generated>
bool decode(const std::uint8_t* data, std::size_t size, typename Generated::type& out) {
  static coloc::rsu_client::AtomicSampleCounters counters;
  static const std::function<void(const std::string&)> quiet;
  coloc::rsu_client::GuardedType<Generated> type("fuzz", &counters, &quiet);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  return type.deserialize(&payload, &out);
}

coloc::rsu_client::FixChecker& checker() {
  static coloc::rsu_client::FixChecker checker(
      coloc::rsu_client::RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [100, -6], lidar_model: VLP-16}\n", "fuzz registry"),
      [] {
        coloc::rsu_client::FixCheckConfig c;
        c.station_id = 7;
        return c;
      }());
  return checker;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if (data[0] % 3 == 0) {
    geometry_msgs::msg::PoseWithCovarianceStamped msg;
    if (!decode<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>(data + 1, size - 1, msg)) return 0;
    const coloc::rsu_client::RsuFix fix = coloc::rsu_client::fixFromSample(msg, "rsu_a");
    checker().check(fix, fix.stamp);  // never throws; refusals are counted
  } else if (data[0] % 3 == 1) {
    nav_msgs::msg::Odometry msg;
    if (!decode<nav_msgs::msg::OdometryPubSubType>(data + 1, size - 1, msg)) return 0;
    const coloc::rsu_client::RsuFix fix = coloc::rsu_client::fixFromSample(msg, "rsu_a");
    checker().check(fix, fix.stamp);
  } else {
    coloc_msgs::msg::VehicleDimensions msg;
    decode<coloc_msgs::msg::VehicleDimensionsPubSubType>(data + 1, size - 1, msg);
  }
  return 0;
}
