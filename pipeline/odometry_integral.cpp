#include "odometry_integral.hpp"

#include <algorithm>
#include <cmath>

namespace coloc::pipeline {

void OdometryIntegral::add(Stamp stamp, double rate) {
  if (!std::isfinite(rate)) return;
  if (!marks_.empty() && stamp <= marks_.back().stamp) return;
  const double integral =
      marks_.empty() ? 0.0 : marks_.back().integral + 0.5 * (rate + marks_.back().rate) * toSeconds(stamp - marks_.back().stamp);
  marks_.push_back({stamp, rate, integral});
  while (marks_.size() > 2 && marks_.front().stamp < stamp - span_) marks_.pop_front();
}

double OdometryIntegral::at(Stamp stamp) const {
  const auto after = std::lower_bound(marks_.begin(), marks_.end(), stamp, [](const Mark& m, Stamp s) { return m.stamp < s; });
  if (after == marks_.begin()) return marks_.front().integral - marks_.front().rate * toSeconds(marks_.front().stamp - stamp);
  if (after == marks_.end()) return marks_.back().integral + marks_.back().rate * toSeconds(stamp - marks_.back().stamp);
  const auto before = after - 1;
  const double w = static_cast<double>(stamp - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  return before->integral + w * (after->integral - before->integral);
}

}  // namespace coloc::pipeline
