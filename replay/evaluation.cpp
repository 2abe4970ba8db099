#include "coloc/replay/evaluation.hpp"

#include <algorithm>
#include <cmath>

namespace coloc::replay {

std::optional<Eigen::Vector2d> truthAt(const std::vector<io::TrajectoryPoint>& truth, Stamp t, Duration max_gap) {
  auto after = std::lower_bound(truth.begin(), truth.end(), t, [](const io::TrajectoryPoint& p, Stamp s) { return p.stamp < s; });
  if (after == truth.end()) return std::nullopt;
  if (after->stamp == t) return after->pose.position.head<2>();
  if (after == truth.begin()) return std::nullopt;
  const auto before = after - 1;
  if (after->stamp - before->stamp > max_gap) return std::nullopt;
  const double w = static_cast<double>(t - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  return ((1.0 - w) * before->pose.position.head<2>() + w * after->pose.position.head<2>()).eval();
}

std::vector<ErrorSample> evaluate(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<io::TrajectoryPoint>& truth,
                                  Duration max_gap) {
  std::vector<ErrorSample> errors;
  for (const io::TrajectoryPoint& p : estimates) {
    if (const auto t = truthAt(truth, p.stamp, max_gap)) {
      const Eigen::Vector2d estimate = p.pose.position.head<2>();
      errors.push_back({p.stamp, estimate, *t, (estimate - *t).norm()});
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
  }
  if (!errors.empty()) {
    s.mean /= errors.size();
    s.rmse = std::sqrt(s.rmse / errors.size());
  }
  return s;
}

}  // namespace coloc::replay
