#pragma once
// A connected vehicle's body, measured over its frames, where its CAM's box is larger. The true-size box
// rests on the corner the LiDAR sees and reaches half the CAM's length and width from it; a CAM (or a
// dataset's label standing in for one) whose box is larger than the body it describes (mirrors counted
// in the width, a margin around the bumpers) puts every fix that much farther from the LiDAR. The
// maintainers' real roadside frames showed it: the true-size centre 8-20 cm farther than the label's,
// on both sets; on the twin, a box 0.4 m wider and 0.15 m longer than the body put the fixes 11 cm
// farther and beyond 3 sd of their covariance in three of four (test HighMount.*).
// A face seen from the corner to its far end measures its side of the body, short by what its last
// azimuth step leaves out (half a step on average) and by the far corner's rounding, whose arc turns
// away from the LiDAR; both are added back. One frame tells only a large excess: on the twin's sedan
// the front face's end falls 0.05-0.35 m short, as widely as the labels' excess, so a frame places the
// box with its own measure only where that is shorter than the CAM's by more than frame_tolerance and
// the frame shows the side whole (min_seen_height, end_clearance). The upper quantile of a vehicle's
// measures over its frames tells more: it is the frames that saw the face's end. The station keeps
// each vehicle's measures, and where five or more put a side shorter than the CAM's by more than the
// CAM's own rounding and the face's shortfall (`tolerance`), the box is placed with it. With the
// twin's CAMs (the body's size rounded), the experiment's fixes are then unchanged; learning from
// three frames, one of site C's moved from 17 to 28 cm.
// The vehicle's own correction of its CAM's rounding (coloc/pipeline/cam_size_correction.hpp) assumes the
// CAM's size was used; a side measured instead is the body's, within the tolerance.
#include <Eigen/Core>
#include <cmath>
#include <deque>

#include "coloc/roadside/lshape_fit.hpp"

namespace coloc::roadside {

struct BodySizeConfig {
  bool enabled = true;
  int min_points = 5;                          ///< returns on the face
  double max_incidence = 45.0 * M_PI / 180.0;  ///< rad at the face's far end; beyond, its end is lost
  double corner_radius = 0.4;                  ///< m, a car's corners in plan at bumper height (0.3-0.5)
  double arc_grazing = 70.0 * M_PI / 180.0;    ///< rad: a corner's arc returns while seen within this of its normal
  int min_measures = 5;                        ///< of a side before it is used
  int max_measures = 50;                       ///< the latest kept per side
  double quantile = 0.9;                       ///< of the measures: the frames that saw the end
  double tolerance = 0.1;                      ///< m: the CAM rounding up by half its 0.1 m step, the face's end short by as much
  /// m: one frame's measure shorter than the CAM's side by more is a face not seen whole (its far end
  /// hidden or lost), neither used nor doubting: the perception's bound on a face seen alone
  /// (RoadsidePerceptionConfig::max_width_face_shortfall).
  double max_shortfall = 0.6;
  /// m: one frame's measure shorter than the CAM's side by more than this is that frame's side (what a
  /// caller of the perception frame by frame gets, without a station; the station's measures over the
  /// frames take over once they are enough). <= 0: off. From a pole (test HighMount.*, OS1-64 at 2-8 m)
  /// a 1.84 m front sent as 1.8 m measured at most 0.18 m short, and 0.25 takes a label's 0.36 m excess
  /// out of most frames (median 19.4 -> 8.1-8.9 cm), the two checks below keeping the experiment's fixes
  /// as they are with it off.
  double frame_tolerance = 0.25;
  // What one frame must show before its measure places the box (the station's quantile over the frames
  // needs neither: a frame that measured short is outvoted).
  /// m the lower body's returns must span, lowest to highest. One ring (a VLP-16 on a 2 m mast at 15-50
  /// m) slices the body at one height, and a slice at the bumpers' lip or the sills, between the wheel
  /// arches, is shorter than the body: on the experiment's site C such slices (0.1-0.25 m of height)
  /// measured the car 0.3-0.6 m short in 3-7 frames a drive, those fixes going from 5-18 to 16-35 cm,
  /// while from the poles of test HighMount.* 98 % of the frames span 0.3 m or more.
  double min_seen_height = 0.3;
  /// m: the face's far end must be seen as an end: the LiDAR's next columns beyond it, at the heights
  /// the body was seen at, return from farther than the end by this much (the road or what stands
  /// behind), not from as near (the face going on, unseen or taken for background) or nearer (something
  /// hiding it), and not nothing (a frame that ends there: on the twin's site B a car cut by the
  /// sweep's seam measured 0.46 m narrow).
  double end_clearance = 0.3;
  /// m: one frame's measure shorter than the CAM's side by more than this, where the side is not placed
  /// with it (the frame does not show it whole), makes that frame's fix doubt both sides by as much
  /// (sizeDoubt): the covariance says what the frame shows, the position waits for the station's
  /// measures. <= 0: off.
  double doubt_tolerance = 0.25;
};

/// Throws coloc::Error naming the first key out of range (min_points, min_measures >= 1, max_measures at
/// least min_measures; max_incidence and arc_grazing in (0, 90) deg; quantile in [0, 1]; tolerance,
/// frame_tolerance, doubt_tolerance and corner_radius finite, the first and last >= 0; max_shortfall > 0;
/// min_seen_height and end_clearance finite and >= 0).
void validate(const BodySizeConfig& config);

/// What the faces at a box's seen corner measure of the body's length and width (m; negative where a
/// face does not: the corner not seen, too few returns, its far end seen beyond max_incidence): each
/// face's extent and half the azimuth step at its far end. `azimuth_step`: rad between the LiDAR's columns.
Eigen::Vector2d measureBodySides(const AlignedBox& box, const Eigen::Vector2d& lidar, double azimuth_step, const BodySizeConfig& config = {});

/// One frame's size to place the box with: the CAM's, or a side `measured` shorter than it by more
/// than frame_tolerance (and by no more than max_shortfall: a face that short is not seen whole).
Eigen::Vector2d frameBodySize(const Eigen::Vector2d& measured, double cam_length, double cam_width, const BodySizeConfig& config = {});

/// The sd of each side of `used` beyond what the fix's covariance counts (the CAM's rounding), m: a side
/// measured instead of the CAM's, the tolerance; a CAM's side kept while the other was found too large,
/// as much as that one was (a CAM that overstates one side may overstate the other); else 0.
Eigen::Vector2d sizeDoubt(const Eigen::Vector2d& used, double cam_length, double cam_width, double tolerance);

/// The doubt one frame's `measured` sides cast on the box placed with `used` (the CAM's, or the
/// station's or the frame's measure): for a side placed with the CAM's yet measured shorter by more
/// than doubt_tolerance (and by no more than max_shortfall), that shortfall on both sides; else 0.
Eigen::Vector2d frameDoubt(const Eigen::Vector2d& measured, const Eigen::Vector2d& used, double cam_length, double cam_width,
                           const BodySizeConfig& config = {});

/// What a doubt on the sides (sizeDoubt) adds to the covariance of the box's centre at heading `yaw`: half
/// of each side's, along it, m^2.
Eigen::Matrix2d sizeCovariance(const Eigen::Vector2d& doubt, double yaw);

/// One vehicle's measures over its frames.
class BodySizeLearner {
 public:
  explicit BodySizeLearner(BodySizeConfig config = {}) : config_(config) {}
  /// A frame's measures (measureBodySides); a negative or non-finite side is skipped.
  void add(const Eigen::Vector2d& sides);
  /// The length and width to place the box with: the CAM's, or a side the measures found shorter by
  /// more than the tolerance.
  Eigen::Vector2d size(double cam_length, double cam_width) const;
  /// sizeDoubt of size().
  Eigen::Vector2d doubt(double cam_length, double cam_width) const;

 private:
  double learned(const std::deque<double>& measures) const;  ///< negative until min_measures
  BodySizeConfig config_;
  std::deque<double> length_, width_;
};

}  // namespace coloc::roadside
