#pragma once
// Time in coloc is int64 nanoseconds since the epoch of whatever clock stamped the data, as ROS 2's
// builtin_interfaces/Time. Doubles appear only at the edges (printing, TUM files), never in interfaces,
// so that stamp arithmetic and ordering are exact.
#include <cmath>
#include <climits>
#include <cstdint>
#include <string>

namespace coloc {

using Stamp = std::int64_t;     ///< nanoseconds since the clock's epoch
using Duration = std::int64_t;  ///< nanoseconds

constexpr Duration kNanosPerSecond = 1'000'000'000;

constexpr double toSeconds(Duration ns) { return static_cast<double>(ns) * 1e-9; }

/// Seconds to nanoseconds, rounded to the nearest nanosecond.
inline Duration fromSeconds(double seconds) { return static_cast<Duration>(std::llround(seconds * 1e9)); }

/// ROS 2 builtin_interfaces/Time (sec, nanosec) to a stamp.
constexpr Stamp fromRosTime(std::int32_t sec, std::uint32_t nanosec) {
  return static_cast<Stamp>(sec) * kNanosPerSecond + static_cast<Stamp>(nanosec);
}

/// A stamp as ROS 2 builtin_interfaces/Time: seconds floored, so that nanosec stays in [0, 1e9) for
/// stamps before the epoch too. `fits` is false when the seconds do not fit int32.
struct RosTime {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  bool fits = true;
};
constexpr RosTime toRosTime(Stamp stamp) {
  Stamp sec = stamp / kNanosPerSecond, nanosec = stamp % kNanosPerSecond;
  if (nanosec < 0) nanosec += kNanosPerSecond, sec -= 1;
  const bool fits = sec >= INT32_MIN && sec <= INT32_MAX;
  return {fits ? static_cast<std::int32_t>(sec) : 0, static_cast<std::uint32_t>(nanosec), fits};
}

/// "12.345678901" with all nine decimals, for messages and files.
std::string formatSeconds(Stamp stamp);

}  // namespace coloc
