#include "measurement_record.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>

#include "motion_model.hpp"

namespace coloc::fusion {

namespace {

const char* const kPoseNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
const char* const kTwistNames[6] = {"vx", "vy", "vz", "wx", "wy", "wz"};

std::string describe(const char* what, const char* const names[6], int i, int j, double value) {
  std::ostringstream out;
  out << what << " covariance(" << names[i] << ", " << names[j] << ") = " << value;
  return out.str();
}

// Checks the covariance as a whole and says which components are measured. A component is measured
// when its variance is finite; its variance must then be > 0, and its covariances with the other
// measured components finite and symmetric.
std::string checkCovariance(const Matrix6d& C, const char* what, const char* const names[6], bool measured[6]) {
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (std::isnan(C(i, j))) return describe(what, names, i, j, C(i, j)) + " is NaN";
  for (int i = 0; i < 6; ++i) {
    const double v = C(i, i);
    if (v == kInfinity) {
      measured[i] = false;
      continue;
    }
    if (!(v > 0.0)) return describe(what, names, i, i, v) + ": a variance must be positive (or +inf for not measured)";
    measured[i] = true;
  }
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j) {
      if (!measured[i] || !measured[j]) continue;
      if (!std::isfinite(C(i, j)) || !std::isfinite(C(j, i)))
        return describe(what, names, i, j, C(i, j)) + ": covariance between measured components must be finite";
      const double tolerance = 1e-9 * std::sqrt(C(i, i) * C(j, j)) + 1e-300;
      if (std::abs(C(i, j) - C(j, i)) > tolerance)
        return describe(what, names, i, j, C(i, j)) + " differs from its transpose " + std::to_string(C(j, i)) +
               ": covariance must be symmetric";
    }
  return {};
}

// Fills the EKF part of the record from covariance rows `rows` (which map to state indices `states`).
std::string fillEkfPart(UpdateRecord& record, const Matrix6d& C, const bool measured[6], const int* rows,
                        const int* states, const double* values, int n, const char* what) {
  record.m = 0;
  int used_rows[3];
  for (int k = 0; k < n; ++k) {
    if (!measured[rows[k]]) continue;
    used_rows[record.m] = rows[k];
    record.index[record.m] = states[k];
    record.value[record.m] = values[k];
    ++record.m;
  }
  for (int i = 0; i < record.m; ++i)
    for (int j = 0; j < record.m; ++j) record.R(i, j) = 0.5 * (C(used_rows[i], used_rows[j]) + C(used_rows[j], used_rows[i]));
  if (record.m > 0) {
    // Padding the unused rows with the identity keeps the factorisation fixed-size (no allocation).
    Eigen::Matrix3d padded = Eigen::Matrix3d::Identity();
    padded.topLeftCorner(record.m, record.m) = record.R.topLeftCorner(record.m, record.m);
    Eigen::LLT<Eigen::Matrix3d> llt(padded);
    if (llt.info() != Eigen::Success) return std::string(what) + " covariance of the measured components is not positive definite";
  }
  return {};
}

}  // namespace

RecordOrError makePoseRecord(const PoseMeasurement& measurement) {
  bool measured[6];
  if (std::string why = checkCovariance(measurement.covariance, "pose", kPoseNames, measured); !why.empty()) return why;
  const Eigen::Vector3d& p = measurement.pose.position;
  for (int i = 0; i < 3; ++i)
    if (measured[i] && !std::isfinite(p[i])) return std::string("pose ") + kPoseNames[i] + " is not finite";
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  if (measured[3] || measured[4] || measured[5]) {
    const Eigen::Quaterniond& q = measurement.pose.orientation;
    if (!q.coeffs().allFinite()) return "pose orientation quaternion is not finite";
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-2)
      return "pose orientation quaternion has norm " + std::to_string(norm) + ", not 1";
    rpy = rollPitchYaw(q.normalized());
  }
  UpdateRecord record;
  const int rows[3] = {0, 1, 5};
  const int states[3] = {kX, kY, kYaw};
  const double values[3] = {p.x(), p.y(), rpy.z()};
  if (std::string why = fillEkfPart(record, measurement.covariance, measured, rows, states, values, 3, "pose");
      !why.empty())
    return why;
  const double aux_values[3] = {p.z(), rpy.x(), rpy.y()};
  for (int a = 0; a < 3; ++a) {
    if (!measured[2 + a]) continue;
    record.aux_mask |= 1 << a;
    record.aux_value[a] = aux_values[a];
    record.aux_variance[a] = measurement.covariance(2 + a, 2 + a);
  }
  if (record.m == 0 && record.aux_mask == 0) return "pose measures no component (every variance is +inf)";
  return record;
}

RecordOrError makeTwistRecord(const TwistMeasurement& measurement, double dead_band) {
  Matrix6d C = measurement.covariance;
  if (C(0, 0) != kInfinity && std::isfinite(measurement.linear.x()) && std::abs(measurement.linear.x()) < dead_band)
    C(0, 0) = 10000.0;
  bool measured[6];
  if (std::string why = checkCovariance(C, "twist", kTwistNames, measured); !why.empty()) return why;
  if (measured[0] && !std::isfinite(measurement.linear.x())) return "twist vx is not finite";
  if (measured[5] && !std::isfinite(measurement.angular.z())) return "twist wz is not finite";
  UpdateRecord record;
  const int rows[2] = {0, 5};
  const int states[2] = {kVx, kWz};
  const double values[2] = {measurement.linear.x(), measurement.angular.z()};
  if (std::string why = fillEkfPart(record, C, measured, rows, states, values, 2, "twist"); !why.empty()) return why;
  if (record.m == 0) return "twist measures neither vx nor wz (both variances are +inf)";
  return record;
}

bool measuresPlanarPose(const UpdateRecord& record) {
  bool has[3] = {false, false, false};
  for (int i = 0; i < record.m; ++i) {
    if (record.index[i] == kX) has[0] = true;
    if (record.index[i] == kY) has[1] = true;
    if (record.index[i] == kYaw) has[2] = true;
  }
  return has[0] && has[1] && has[2];
}

}  // namespace coloc::fusion
