#include "coloc/roadside/fix_covariance.hpp"

#include <algorithm>

namespace coloc::roadside {

Eigen::Matrix2d fixCovariance(const AlignedBox& box, double range, const FixCovarianceModel& m) {
  const Eigen::Vector2d along(std::cos(box.yaw), std::sin(box.yaw)), across(-along.y(), along.x());
  const double noise_sq = m.range_noise * m.range_noise;
  const double spacing = std::max(range, 1.0) * m.azimuth_step;  // m between returns on a face at that range
  constexpr int kSeen = 3;
  // One axis: placed by its own face's returns, or by the other face's end.
  const auto axis = [&](int own_points, double missing) {
    if (own_points >= kSeen) return noise_sq / own_points;
    return spacing * spacing / 3.0 + missing * missing / 3.0;
  };
  const double var_across = axis(box.length_face_points, box.face_shortfall);
  const double var_along = axis(box.width_face_points, box.face_shortfall);
  // The heading from the longer face with returns: a line through n points over extent l.
  double heading_var = m.heading_floor * m.heading_floor;
  const int n = std::max(box.length_face_points, box.width_face_points);
  const double extent = box.length_face_points >= box.width_face_points ? box.length_face_extent : box.width_face_extent;
  if (n >= 2 && extent > 0.1) heading_var += 12.0 * noise_sq / (n * extent * extent);
  else heading_var += std::pow(10.0 * M_PI / 180.0, 2);  // no face to speak of: the heading check's bound
  const Eigen::Vector2d lever = box.center - box.alignment_point;
  const Eigen::Vector2d turned(-lever.y(), lever.x());
  const double size_var = m.size_step * m.size_step / 48.0;  // half of a uniform rounding
  Eigen::Matrix2d c = var_along * along * along.transpose() + var_across * across * across.transpose() + heading_var * turned * turned.transpose();
  c.diagonal().array() += m.floor * m.floor + size_var;
  return m.scale * m.scale * c;
}

}  // namespace coloc::roadside
