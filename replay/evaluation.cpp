#include "coloc/replay/evaluation.hpp"

#include <algorithm>
#include <cmath>

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
      errors.push_back({p.stamp, estimate, t->position, d.norm(), d.dot(ahead), ahead.x() * d.y() - ahead.y() * d.x()});
    }
  }
  return errors;
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

}  // namespace coloc::replay
