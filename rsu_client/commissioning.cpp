#include "coloc/rsu_client/commissioning.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace coloc::rsu_client {

namespace {

// The residual of one sample: the fix corrected by (dx, dy, dyaw) against the reference at the fix's
// stamp minus the clock offset, and its Jacobian in (dx, dy, dyaw, clock).
Eigen::Vector2d residual(const Eigen::Vector2d& at, const CommissioningSample& s, const Eigen::Vector4d& p, Eigen::Matrix<double, 2, 4>* jacobian) {
  const Eigen::Rotation2Dd back(-p[2]);
  const Eigen::Vector2d turned = back * (s.fix - at);
  if (jacobian) {
    jacobian->setZero();
    jacobian->leftCols<2>() = -Eigen::Matrix2d::Identity();
    jacobian->col(2) = Eigen::Vector2d(turned.y(), -turned.x());  // d/d(dyaw) of R(-dyaw) x
    jacobian->col(3) = s.velocity;
  }
  return at - p.head<2>() + turned - (s.reference - s.velocity * p[3]);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

namespace {

// One robust fit, with the clock free (if the drive separates it) or held at 0.
CommissioningResult fit(const Eigen::Vector2d& at, const std::vector<CommissioningSample>& samples, const CommissioningConfig& config,
                        bool with_clock) {
  CommissioningResult out;
  std::vector<bool> inlier(samples.size(), true);
  Eigen::Vector4d p = Eigen::Vector4d::Zero();
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  double sigma = 0.0;
  for (int round = 0; round < 4; ++round) {
    // Gauss-Newton on the inliers; the clock column is dropped when the drive cannot separate it.
    for (int iteration = 0; iteration < 5; ++iteration) {
      information.setZero();
      Eigen::Vector4d gradient = Eigen::Vector4d::Zero();
      Eigen::Matrix<double, 2, 4> J;
      for (std::size_t i = 0; i < samples.size(); ++i) {
        if (!inlier[i]) continue;
        const Eigen::Vector2d r = residual(at, samples[i], p, &J);
        if (!with_clock) J.col(3).setZero();
        information += J.transpose() * J;
        gradient += J.transpose() * r;
      }
      if (!with_clock) information(3, 3) = 1.0;
      const Eigen::Vector4d step = information.ldlt().solve(-gradient);
      if (!step.allFinite()) break;
      p += step;
      if (step.head<2>().norm() < 1e-7 && std::abs(step[2]) < 1e-9) break;
    }
    // Residuals, their robust spread, and the samples beyond 3 of it.
    std::vector<double> abs_components;
    std::vector<double> norms(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const Eigen::Vector2d r = residual(at, samples[i], p, nullptr);
      norms[i] = r.norm();
      if (inlier[i]) abs_components.push_back(std::abs(r.x())), abs_components.push_back(std::abs(r.y()));
    }
    sigma = std::max(1.4826 * median(abs_components), 1e-4);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const bool in = norms[i] <= 3.0 * std::sqrt(2.0) * sigma;
      changed += in != inlier[i] ? 1 : 0;
      inlier[i] = in;
    }
    // The clock: separable only if the velocities differ enough over the drive (speed or heading).
    if (with_clock) {
      const Eigen::Matrix4d covariance = sigma * sigma * information.inverse();
      if (!(covariance(3, 3) >= 0.0) || std::sqrt(covariance(3, 3)) > config.max_clock_sd) {
        with_clock = false;
        p[3] = 0.0;
        continue;
      }
    }
    if (changed == 0 && round > 0) break;
  }
  out.inliers = static_cast<std::size_t>(std::count(inlier.begin(), inlier.end(), true));
  out.outliers = samples.size() - out.inliers;
  out.residual_sd = sigma;
  out.clock_observable = with_clock;
  Eigen::Matrix4d covariance = sigma * sigma * information.inverse();
  if (!with_clock) covariance.row(3).setZero(), covariance.col(3).setZero(), covariance(3, 3) = 1.0;
  out.sd = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  if (!with_clock) out.sd[3] = -1.0;
  out.calibration.dx = p[0];
  out.calibration.dy = p[1];
  out.calibration.dyaw = p[2];
  out.calibration.clock_offset = with_clock ? p[3] : 0.0;
  if (out.inliers < config.min_fixes) out.note = "too few fixes agree with the reference";
  else if (out.sd[0] > config.max_position_sd || out.sd[1] > config.max_position_sd) out.note = "position not determined by this drive";
  else if (out.sd[2] > config.max_yaw_sd) out.note = "yaw not determined by this drive";
  out.determined = out.note.empty() && p.allFinite();
  for (const CommissioningSample& sample : samples) out.residuals.push_back(residual(at, sample, p, nullptr));
  return out;
}

}  // namespace

std::vector<Eigen::Vector2d> commissioningResiduals(const Eigen::Vector2d& at, const std::vector<CommissioningSample>& samples,
                                                    const RsuCalibrationEntry& calibration) {
  const Eigen::Vector4d p(calibration.dx, calibration.dy, calibration.dyaw, calibration.clock_offset);
  std::vector<Eigen::Vector2d> out;
  for (const CommissioningSample& sample : samples)
    if (sample.fix.allFinite() && sample.reference.allFinite() && sample.velocity.allFinite()) out.push_back(residual(at, sample, p, nullptr));
  return out;
}

CommissioningResult commissionRsu(const Eigen::Vector2d& at, const std::vector<CommissioningSample>& all, const CommissioningConfig& config) {
  // A sample with a NaN or infinite value says nothing; it is counted, not fitted.
  std::vector<CommissioningSample> samples;
  for (const CommissioningSample& s : all)
    if (s.fix.allFinite() && s.reference.allFinite() && s.velocity.allFinite()) samples.push_back(s);
  const std::size_t not_finite = all.size() - samples.size();
  if (samples.size() < config.min_fixes || !at.allFinite()) {
    CommissioningResult out;
    out.not_finite = not_finite;
    out.note = !at.allFinite() ? std::string("the RSU's registry position is not finite")
                               : std::to_string(samples.size()) + " usable fixes, fewer than " + std::to_string(config.min_fixes);
    return out;
  }
  // With the clock if the drive separates it well enough that the survey is still determined;
  // otherwise the clock is held and the shift along the road absorbs it.
  CommissioningResult with_clock = fit(at, samples, config, true);
  with_clock.not_finite = not_finite;
  if (with_clock.determined || !with_clock.clock_observable) return with_clock;
  CommissioningResult held = fit(at, samples, config, false);
  held.not_finite = not_finite;
  return held.determined ? held : with_clock;
}

}  // namespace coloc::rsu_client
