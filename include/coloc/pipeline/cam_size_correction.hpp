#pragma once
// A roadside fix of this vehicle corrected for the size its CAM tells the RSU. ETSI's CAM carries the
// vehicle's length and width in 0.1 m steps; the RSU places its box at the corner it sees and takes
// the centre half the CAM's length and width from it, so a car of 4.88 x 1.84 m sent as 4.9 x 1.8 is
// placed 2 cm towards the RSU's side and 1 cm towards the end it sees, on every fix: a bias that no
// filter averages away and no survey of the RSU should absorb. The vehicle knows its own size and
// what its CAM rounds it to, and from its heading and the RSU's position which side and end the RSU
// sees; it moves the fix back by half the differences. Abeam of the RSU (the RSU within half the
// body's length along it) either end may be the one seen, and the along-body part is left alone.
#include <Eigen/Core>

namespace coloc::pipeline {

struct CamSizeCorrection {
  double length = 0.0;  ///< m, the body's own, bumper to bumper; 0 = no correction
  double width = 0.0;   ///< m, without mirrors
  double step = 0.1;    ///< m, the CAM's size quantum (ETSI EN 302 637-2)
  /// m, what this vehicle's CAMs send, where its V2X stack is known to round otherwise than to the
  /// nearest step (the standard gives the unit, not the rounding); 0 = the size rounded to the nearest step.
  double sent_length = 0.0, sent_width = 0.0;

  bool enabled() const { return length > 0.0 && width > 0.0 && step > 0.0; }
  /// The fix's map position corrected; `rsu` the RSU's map position, `yaw` the vehicle's heading.
  Eigen::Vector2d apply(const Eigen::Vector2d& fix, const Eigen::Vector2d& rsu, double yaw) const;
};

}  // namespace coloc::pipeline
