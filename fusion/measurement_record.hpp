#pragma once
// Validation of incoming poses and twists and their conversion to update records. This is the door
// through which bad input must not pass: every rejection carries a message that says why.
#include <string>
#include <variant>

#include "coloc/core/types.hpp"
#include "measurement_update.hpp"

namespace coloc::fusion {

/// Either a record or the reason the input cannot be used.
using RecordOrError = std::variant<UpdateRecord, std::string>;

/// (x, y, yaw) feed the EKF, z / roll / pitch the separate 1-D filters; +inf variance = not measured.
RecordOrError makePoseRecord(const PoseMeasurement& measurement);

/// (vx, wz) feed the EKF; the other four components are not used. Below `dead_band` m/s the speed's
/// variance is raised to 10000, as Autoware's threshold_observable_velocity_mps.
RecordOrError makeTwistRecord(const TwistMeasurement& measurement, double dead_band);

/// True if the record measures x, y and yaw, which is what an initial pose needs.
bool measuresPlanarPose(const UpdateRecord& record);

}  // namespace coloc::fusion
