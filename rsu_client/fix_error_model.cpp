#include "coloc/rsu_client/fix_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace coloc::rsu_client {

std::vector<RsuInfo::ErrorAtRange> fixErrorByRange(const Eigen::Vector2d& rsu_position, const std::vector<Eigen::Vector2d>& fixes,
                                                   const std::vector<Eigen::Vector2d>& residuals, double band, std::size_t fewest, bool with_mean) {
  std::vector<RsuInfo::ErrorAtRange> table;
  if (fixes.size() != residuals.size() || !(band > 0.0)) return table;
  struct Sums {
    double range = 0.0, along = 0.0, across = 0.0, along2 = 0.0, across2 = 0.0;
    std::size_t n = 0;
  };
  std::map<long, Sums> bands;
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const Eigen::Vector2d sight = fixes[i] - rsu_position;
    const double range = sight.norm();
    if (!residuals[i].allFinite() || !std::isfinite(range) || range < 1e-3) continue;
    const Eigen::Vector2d u = sight / range;
    const double along = residuals[i].dot(u), across = residuals[i].dot(Eigen::Vector2d(-u.y(), u.x()));
    Sums& s = bands[static_cast<long>(std::floor(range / band))];
    s.range += range;
    s.along += along;
    s.across += across;
    s.along2 += along * along;
    s.across2 += across * across;
    ++s.n;
  }
  for (const auto& [index, s] : bands) {
    if (s.n < std::max<std::size_t>(fewest, 1)) continue;
    const double n = static_cast<double>(s.n);
    const double along_mean = with_mean ? s.along / n : 0.0, across_mean = with_mean ? s.across / n : 0.0;
    // About the mean where it is taken off, else the whole mean square (tails included either way).
    const double along_var = std::max(s.along2 / n - along_mean * along_mean, 0.0), across_var = std::max(s.across2 / n - across_mean * across_mean, 0.0);
    // A band whose residuals are all the same along a direction says nothing a filter can take.
    if (!(along_var > 0.0) || !(across_var > 0.0)) continue;
    table.push_back({s.range / n, std::sqrt(along_var), std::sqrt(across_var), along_mean, across_mean});
  }
  return table;
}

}  // namespace coloc::rsu_client
