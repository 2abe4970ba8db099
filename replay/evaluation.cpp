#include "coloc/replay/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "coloc/replay/accurate_places.hpp"

namespace coloc::replay {

std::optional<TruthSample> truthAt(const std::vector<io::TrajectoryPoint>& truth, Stamp t, Duration max_gap) {
  auto after = std::lower_bound(truth.begin(), truth.end(), t, [](const io::TrajectoryPoint& p, Stamp s) { return p.stamp < s; });
  if (after == truth.end()) return std::nullopt;
  const double yaw_after = rollPitchYaw(after->pose.orientation)[2];
  if (after->stamp == t) return TruthSample{after->pose.position.head<2>(), yaw_after};
  if (after == truth.begin()) return std::nullopt;
  const auto before = after - 1;
  if (after->stamp - before->stamp > max_gap) return std::nullopt;
  const double w = static_cast<double>(t - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  const double yaw_before = rollPitchYaw(before->pose.orientation)[2];
  return TruthSample{((1.0 - w) * before->pose.position.head<2>() + w * after->pose.position.head<2>()).eval(),
                     wrapAngle(yaw_before + w * wrapAngle(yaw_after - yaw_before))};
}

std::vector<ErrorSample> evaluate(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<io::TrajectoryPoint>& truth,
                                  Duration max_gap) {
  std::vector<ErrorSample> errors;
  for (const io::TrajectoryPoint& p : estimates) {
    if (const auto t = truthAt(truth, p.stamp, max_gap)) {
      const Eigen::Vector2d estimate = p.pose.position.head<2>();
      const Eigen::Vector2d d = estimate - t->position;
      const Eigen::Vector2d ahead(std::cos(t->heading), std::sin(t->heading));
      errors.push_back({p.stamp, estimate, t->position, d.norm(), d.dot(ahead), ahead.x() * d.y() - ahead.y() * d.x(),
                        wrapAngle(rollPitchYaw(p.pose.orientation)[2] - t->heading), t->heading});
    }
  }
  return errors;
}

Eigen::Vector2d alongAcrossDeviation(const Eigen::Matrix2d& covariance, double heading) {
  if (!covariance.allFinite()) return Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  const Eigen::Vector2d ahead(std::cos(heading), std::sin(heading)), left(-ahead.y(), ahead.x());
  return {std::sqrt(std::max(0.0, ahead.dot(covariance * ahead))), std::sqrt(std::max(0.0, left.dot(covariance * left)))};
}

std::vector<ErrorSample> evaluateAt(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<Stamp>& stamps,
                                    const std::vector<io::TrajectoryPoint>& truth, Duration max_gap) {
  std::vector<io::TrajectoryPoint> at;
  for (Stamp s : stamps)
    if (const auto e = truthAt(estimates, s, max_gap)) {  // the same interpolation serves any trajectory
      io::TrajectoryPoint p;
      p.stamp = s;
      p.pose.position.head<2>() = e->position;
      p.pose.orientation = Eigen::AngleAxisd(e->heading, Eigen::Vector3d::UnitZ());
      at.push_back(p);
    }
  return evaluate(at, truth, max_gap);
}

InputComparison compareWithInput(const std::vector<ErrorSample>& input, const std::vector<ErrorSample>& fused_at_input,
                                 const std::vector<ErrorSample>& settled_at_input, double stretch_length, double accurate_below,
                                 const AccuratePlaces* places) {
  InputComparison c;
  c.stretch_length = stretch_length;
  c.accurate_below = accurate_below;
  c.places_given = places != nullptr;
  // Pair by stamp; all three are in stamp order.
  struct Triple {
    const ErrorSample* input;
    double fused, settled;
  };
  std::vector<Triple> pairs;
  for (std::size_t i = 0, j = 0, k = 0; i < input.size() && j < fused_at_input.size() && k < settled_at_input.size();) {
    const Stamp s = std::max({input[i].stamp, fused_at_input[j].stamp, settled_at_input[k].stamp});
    if (input[i].stamp < s) ++i;
    else if (fused_at_input[j].stamp < s) ++j;
    else if (settled_at_input[k].stamp < s) ++k;
    else pairs.push_back({&input[i++], fused_at_input[j++].error, settled_at_input[k++].error});
  }
  c.samples = pairs.size();
  if (pairs.empty()) return c;
  for (const Triple& p : pairs) {
    c.input_mean += p.input->error;
    c.fused_mean += p.fused;
    c.settled_mean += p.settled;
    c.mean_square_xy += 0.5 * p.input->error * p.input->error;
    c.yaw_mean += p.input->heading_error;
  }
  const double n = static_cast<double>(pairs.size());
  c.input_mean /= n, c.fused_mean /= n, c.settled_mean /= n, c.mean_square_xy /= n, c.yaw_mean /= n;
  for (const Triple& p : pairs) c.yaw_variance += (p.input->heading_error - c.yaw_mean) * (p.input->heading_error - c.yaw_mean) / n;
  if (places)
    for (const Triple& p : pairs)
      if (places->contains(p.input->truth)) {
        ++c.place_samples;
        c.place_input_mean += p.input->error, c.place_fused_mean += p.fused, c.place_settled_mean += p.settled;
      }
  if (c.place_samples > 0) {
    const double m = static_cast<double>(c.place_samples);
    c.place_input_mean /= m, c.place_fused_mean /= m, c.place_settled_mean /= m;
  }
  // Stretches by distance along the true path.
  std::size_t begin = 0;
  double along = 0.0;
  double input_sum = 0.0, fused_sum = 0.0, settled_sum = 0.0;
  auto close = [&](std::size_t end) {
    double in = 0.0, fu = 0.0, se = 0.0;
    for (std::size_t k = begin; k < end; ++k) in += pairs[k].input->error, fu += pairs[k].fused, se += pairs[k].settled;
    if (end > begin && in / static_cast<double>(end - begin) < accurate_below) {
      c.accurate_samples += end - begin;
      input_sum += in, fused_sum += fu, settled_sum += se;
    }
    begin = end;
    along = 0.0;
  };
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    along += (pairs[k].input->truth - pairs[k - 1].input->truth).norm();
    if (along >= stretch_length) close(k);
  }
  close(pairs.size());
  if (c.accurate_samples > 0) {
    const double m = static_cast<double>(c.accurate_samples);
    c.accurate_input_mean = input_sum / m;
    c.accurate_fused_mean = fused_sum / m;
    c.accurate_settled_mean = settled_sum / m;
  }
  return c;
}

ErrorStats errorStats(const std::vector<ErrorSample>& errors) {
  ErrorStats s;
  for (const ErrorSample& e : errors) {
    s.mean += e.error;
    s.rmse += e.error * e.error;
    s.max = std::max(s.max, e.error);
    s.along_mean += e.along;
    s.across_mean += e.across;
  }
  if (!errors.empty()) {
    s.along_mean /= errors.size();
    s.across_mean /= errors.size();
    s.mean /= errors.size();
    s.rmse = std::sqrt(s.rmse / errors.size());
  }
  return s;
}

pipeline::NdtQualityMap ndtQualityMap(const std::vector<ErrorSample>& ndt, double cell, std::size_t min_poses) {
  std::vector<pipeline::NdtQualitySample> samples;
  samples.reserve(ndt.size());
  for (const ErrorSample& s : ndt) {
    // A sample the map cannot place (not finite, or beyond the 1e9 m it indexes) says nothing about any place: left out, not an error
    // that would stop `coloc fuse` after its replay.
    if (!s.estimate.allFinite() || !s.truth.allFinite() || s.estimate.cwiseAbs().maxCoeff() > 1e9) continue;
    samples.push_back({s.estimate, s.estimate - s.truth, s.truth_heading, s.heading_error});
  }
  return pipeline::NdtQualityMap::fromErrors(samples, cell, min_poses);  // elsewhere the drive's own mean square
}

}  // namespace coloc::replay
