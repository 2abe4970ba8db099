#include "coloc/rsu_client/fix_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace coloc::rsu_client {

std::vector<RsuInfo::ErrorAtRange> fixErrorByRange(const Eigen::Vector2d& rsu_position, const std::vector<Eigen::Vector2d>& fixes,
                                                   const std::vector<Eigen::Vector2d>& residuals, double band, std::size_t fewest,
                                                   const std::vector<double>& headings) {
  std::vector<RsuInfo::ErrorAtRange> table;
  const bool with_mean = !headings.empty();
  if (fixes.size() != residuals.size() || (with_mean && headings.size() != fixes.size()) || !(band > 0.0)) return table;
  struct Sample {
    Eigen::Vector2d sight, residual;  // the unit line of sight; the residual, map frame
    double range;
    Eigen::Vector2d forward;  // the vehicle's heading as a unit vector (with headings)
  };
  std::map<long, std::vector<Sample>> bands;
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const Eigen::Vector2d sight = fixes[i] - rsu_position;
    const double range = sight.norm();
    if (!residuals[i].allFinite() || !std::isfinite(range) || range < 1e-3) continue;
    if (with_mean && !std::isfinite(headings[i])) continue;
    const double yaw = with_mean ? headings[i] : 0.0;
    bands[static_cast<long>(std::floor(range / band))].push_back({sight / range, residuals[i], range, Eigen::Vector2d(std::cos(yaw), std::sin(yaw))});
  }
  for (const auto& [index, samples] : bands) {
    if (samples.size() < std::max<std::size_t>(fewest, 1)) continue;
    const double n = static_cast<double>(samples.size());
    // The mean in the vehicle's frame: a far car's fit is pulled towards the side it shows the RSU,
    // which across the line of sight has one sign as the car comes and the other as it goes.
    double forward = 0.0, left = 0.0, range = 0.0;
    for (const Sample& s : samples) {
      range += s.range;
      if (with_mean) {
        forward += s.residual.dot(s.forward);
        left += s.residual.dot(Eigen::Vector2d(-s.forward.y(), s.forward.x()));
      }
    }
    forward /= n, left /= n;
    // About the mean where it is taken off, else the whole mean square (tails included either way).
    double along2 = 0.0, across2 = 0.0;
    for (const Sample& s : samples) {
      const Eigen::Vector2d off = s.residual - forward * s.forward - left * Eigen::Vector2d(-s.forward.y(), s.forward.x());
      along2 += std::pow(off.dot(s.sight), 2);
      across2 += std::pow(off.dot(Eigen::Vector2d(-s.sight.y(), s.sight.x())), 2);
    }
    // A band whose residuals are all the same along a direction says nothing a filter can take.
    if (!(along2 > 0.0) || !(across2 > 0.0)) continue;
    table.push_back({range / n, std::sqrt(along2 / n), std::sqrt(across2 / n), forward, left});
  }
  return table;
}

}  // namespace coloc::rsu_client
