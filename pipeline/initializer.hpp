#pragma once
// How the pipeline starts a filter that has no pose, and restarts one that is lost, without a person:
// from a position measured from outside the vehicle (a roadside fix, a position-only pose source such
// as GNSS), the heading from NDT's search at that position (a map and a scan near the position's
// stamp) or else from the direction of travel between two positions of one source.
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "coloc/core/types.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/ndt/point_cloud.hpp"

namespace coloc::pipeline {

struct InitializerConfig {
  double pair_gap = 0.06;       ///< s; a scan this close to a position's stamp is searched at it
  double min_travel = 2.0;      ///< m between two positions for a direction of travel
  double max_span = 3.0;        ///< s; positions older than this are forgotten
  double max_ndt_offset = 2.0;  ///< m; NDT's match farther than this from the position is refused
  int heading_candidates = 16;
  /// Standard deviations the filter starts with: a start is a first guess for NDT and the fixes to
  /// refine, never a measurement to be held to.
  double start_position_sd = 0.3;       ///< m
  double start_heading_sd_ndt = 0.05;   ///< rad, heading from NDT's search
  double start_heading_sd_travel = 0.15;  ///< rad, heading from the direction of travel (or kept while lost)
};

/// A pose to start the filter from, and how it was found.
struct StartPose {
  PoseMeasurement pose;
  std::string how;
};

class Initializer {
 public:
  explicit Initializer(InitializerConfig config = {}) : config_(config) {}

  void reset();
  /// A position (map x, y) measured from outside the vehicle, with its variance.
  void addPosition(const std::string& source, Stamp stamp, const Eigen::Vector2d& xy, double variance);
  /// Scans are kept a short while for the heading search.
  void addScan(std::shared_ptr<const ndt::PointCloud> scan, Stamp stamp);
  /// The odometry's latest twist as the filter takes it (speed scaled): for deskewing the searched
  /// scan, and for the filter to start at speed.
  void setTwist(const TwistMeasurement& twist);
  const std::optional<TwistMeasurement>& twist() const { return twist_; }

  /// A start from what has arrived, or nullopt (then `waiting` says what is missing). `ndt` may be
  /// null (no map). `heading_hint`: a heading to search near (a lost filter's own), with its tolerance.
  std::optional<StartPose> tryStart(ndt::NdtPoseSource* ndt, std::optional<double> heading_hint, std::string& waiting);

 private:
  struct Position {
    std::string source;
    Stamp stamp;
    Eigen::Vector2d xy;
    double variance;
  };
  struct Scan {
    std::shared_ptr<const ndt::PointCloud> cloud;
    Stamp stamp;
  };
  std::optional<double> directionOfTravel(const Position& latest, double& distance) const;
  PoseMeasurement startAt(Stamp stamp, const Eigen::Vector3d& position, double yaw, double position_variance, double heading_sd) const;

  InitializerConfig config_;
  std::deque<Position> positions_;
  std::deque<Scan> scans_;
  Stamp searched_scan_ = 0;  ///< the newest scan searched already (each is searched once)
  double vx_ = 0.0;
  std::optional<TwistMeasurement> twist_;
};

}  // namespace coloc::pipeline
