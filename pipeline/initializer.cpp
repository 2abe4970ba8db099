#include "initializer.hpp"

#include <cmath>
#include <sstream>

namespace coloc::pipeline {

namespace {
constexpr std::size_t kKeptScans = 8;
}

void Initializer::reset() {
  positions_.clear();
  scans_.clear();
  searched_scan_ = 0;
}

void Initializer::addPosition(const std::string& source, Stamp stamp, const Eigen::Vector2d& xy, double variance) {
  positions_.push_back({source, stamp, xy, variance});
  while (!positions_.empty() && positions_.front().stamp < stamp - fromSeconds(config_.max_span)) positions_.pop_front();
}

void Initializer::setTwist(const TwistMeasurement& twist) {
  if (!std::isfinite(twist.covariance(0, 0)) || !std::isfinite(twist.linear.x())) return;
  twist_ = twist;
  vx_ = twist.linear.x();
}

void Initializer::addScan(std::shared_ptr<const ndt::PointCloud> scan, Stamp stamp) {
  scans_.push_back({std::move(scan), stamp});
  while (scans_.size() > kKeptScans) scans_.pop_front();
}

std::optional<double> Initializer::directionOfTravel(const Position& latest, double& distance) const {
  distance = 0.0;
  for (const Position& p : positions_) {
    if (p.source != latest.source || p.stamp >= latest.stamp) continue;
    const Eigen::Vector2d d = latest.xy - p.xy;
    if (d.norm() >= config_.min_travel) {
      distance = d.norm();
      return std::atan2(d.y(), d.x());
    }
  }
  return std::nullopt;
}

PoseMeasurement Initializer::startAt(Stamp stamp, const Eigen::Vector3d& position, double yaw, double position_variance, double heading_sd) const {
  PoseMeasurement m;
  m.stamp = stamp;
  m.pose.position = position;
  m.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, yaw);
  const double xy = position_variance + config_.start_position_sd * config_.start_position_sd;
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << xy, xy, kInfinity, kInfinity, kInfinity, heading_sd * heading_sd;
  return m;
}

std::optional<StartPose> Initializer::tryStart(ndt::NdtPoseSource* ndt, std::optional<double> heading_hint, std::string& waiting) {
  if (positions_.empty()) {
    waiting = "waiting for a position: an initial pose, a pose source or an RSU fix";
    return std::nullopt;
  }
  const Position& latest = positions_.back();
  std::string why;
  double travelled = 0.0;
  const std::optional<double> travel = directionOfTravel(latest, travelled);
  std::ostringstream how;
  how.precision(3);
  // NDT's search on the scan nearest a position: the heading, and the position refined by the map.
  if (ndt) {
    for (auto p = positions_.rbegin(); p != positions_.rend(); ++p) {
      const Scan* best = nullptr;
      for (const Scan& s : scans_)
        if (s.stamp > searched_scan_ && std::abs(toSeconds(s.stamp - p->stamp)) <= config_.pair_gap &&
            (!best || std::abs(s.stamp - p->stamp) < std::abs(best->stamp - p->stamp)))
          best = &s;
      if (!best) continue;
      searched_scan_ = best->stamp;
      ndt::HeadingSearch search;
      search.candidates = config_.heading_candidates;
      search.vx = vx_;
      if (heading_hint) search.near = heading_hint, search.within = M_PI / 4;
      else if (travel) search.near = travel;
      const ndt::ScanOutcome found = ndt->searchHeading(*best->cloud, best->stamp, p->xy, search);
      if (!found.produced) {
        why = "NDT's heading search at the position of " + p->source + " found no match (" + found.detail + ")";
        break;
      }
      const double offset = (found.pose.pose.position.head<2>() - p->xy).norm();
      const double allowed = config_.max_ndt_offset + std::abs(vx_ * toSeconds(best->stamp - p->stamp));
      if (offset > allowed) {
        how << "NDT's heading search matched " << offset << " m from the position of " << p->source;
        why = how.str() + ", too far to trust";
        break;
      }
      const double yaw = rollPitchYaw(found.pose.pose.orientation)[2];
      how << "position from " << p->source << ", heading " << yaw * 180.0 / M_PI << " deg from NDT's search over "
          << config_.heading_candidates << " headings" << (search.near ? " near the direction of travel" : "");
      if (heading_hint) how.str(""), how << "position from " << p->source << ", heading from NDT's search near the filter's own";
      return StartPose{startAt(best->stamp, found.pose.pose.position, yaw, 0.0, config_.start_heading_sd_ndt), how.str()};
    }
  }
  if (travel) {
    how << "position from " << latest.source << ", heading " << *travel * 180.0 / M_PI << " deg from its direction of travel over "
        << travelled << " m";
    const double heading_sd = std::hypot(config_.start_heading_sd_travel, 2.0 * std::sqrt(latest.variance) / travelled);
    return StartPose{startAt(latest.stamp, {latest.xy.x(), latest.xy.y(), 0.0}, *travel, latest.variance, heading_sd), how.str()};
  }
  if (heading_hint) {
    how << "position from " << latest.source << ", heading kept from the filter";
    return StartPose{startAt(latest.stamp, {latest.xy.x(), latest.xy.y(), 0.0}, *heading_hint, latest.variance, config_.start_heading_sd_travel),
                     how.str()};
  }
  std::ostringstream wait;
  wait.precision(3);
  if (!why.empty()) wait << why << "; ";
  wait << "waiting for " << (ndt ? "a scan near a position of " + latest.source + " to search the heading, or " : std::string()) << config_.min_travel
       << " m of travel between positions of " << latest.source << " for a heading";
  waiting = wait.str();
  return std::nullopt;
}

}  // namespace coloc::pipeline
