#pragma once
// What connected vehicles tell a roadside unit, as coloc's RSU node takes it over DDS:
// coloc_msgs/msg/Cam, the part of an ETSI CAM (EN 302 637-2) the perception uses, in the map frame.
// A V2X stack's bridge fills it from the CAMs it receives (WGS84 projected into the map). The
// reference position is the CAM's: the ground point at the centre of the front of the body. Length and
// width are as a CAM carries them, in steps of 0.1 m. Codec as in ros_messages.hpp: XCDR1 with its
// encapsulation header, little endian written, either read; anything truncated or malformed throws
// coloc::Error naming the type and the field.
//
//   std_msgs/Header header   # the CAM's generation time; frame_id: the map frame
//   uint32 station_id
//   float64 x                # m, reference position (front centre), map frame
//   float64 y
//   float64 heading          # rad, map frame, counter-clockwise from x
//   float64 speed            # m/s
//   float64 yaw_rate         # rad/s
//   float64 length           # m
//   float64 width            # m, without mirrors
#include <cstdint>

#include <Eigen/Core>

#include "coloc/io/ros_messages.hpp"

namespace coloc::io {

inline constexpr const char* kCamType = "coloc_msgs/msg/Cam";

struct Cam {
  Header header;
  std::uint32_t station_id = 0;
  Eigen::Vector2d reference = Eigen::Vector2d::Zero();
  double heading = 0.0, speed = 0.0, yaw_rate = 0.0;
  double length = 0.0, width = 0.0;
  /// The centre of the body's footprint, where the perception looks for the vehicle.
  Eigen::Vector2d centre() const;
};

/// The length or width a CAM carries for a body of `size` (m): ETSI EN 302 637-2 gives the unit, 0.1 m,
/// and this rounds to the nearest step, at least one step; `step` 0: the size exact (the ideal twin).
double camSizeSent(double size, double step = 0.1);

Bytes encodeCam(const Cam& cam);
/// Also refuses non-finite numbers and a size that is not positive.
Cam decodeCam(const std::uint8_t* data, std::size_t size);

}  // namespace coloc::io
