#pragma once
// The paper's roadside perception (Sections III-B and III-D): background filtering of the current frame
// against a reference frame with a k-d tree, only near the vehicle's reference position; clustering;
// the points below 0.8 m, at most the 500 lowest; L-shape fit; the true-size box on the alignment
// point; the result in the map frame, stamped with the frame's capture time.
// Other road users share the road: the clusters are grouped into objects no larger than the vehicle
// the CAM describes, and a frame is refused, with its reason, when it cannot be attributed to the ego
// vehicle beyond doubt (nothing at the CAM's position, a cluster larger than the vehicle, two objects
// there, something between the RSU and the vehicle). A refused fix beats a wrong one.
#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/roadside/body_size.hpp"
#include "coloc/roadside/fix_covariance.hpp"
#include "coloc/roadside/lshape_fit.hpp"
#include "coloc/roadside/road_surface.hpp"

namespace coloc::roadside {

struct RoadsidePerceptionConfig {
  double background_distance = 0.15;  ///< m; a point this close to the reference frame is background
  double search_radius = 8.0;         ///< m around the vehicle's reference position; beyond is background
  double cluster_distance = 0.6;      ///< m, Euclidean clustering
  bool height_cut = true;             ///< keep only points below cut_height (chassis, no mirrors)
  double cut_height = 0.8;            ///< m above the road
  int max_points = 500;               ///< the lowest this many go to the fit
  bool align_true_size = true;        ///< false: report the fitted rectangle's centre (the plain L-shape)
  /// Attribution. An object may exceed the CAM's length and width by `size_margin` (heading error,
  /// noise); its fitted centre must lie within `attribution_radius` of the CAM's position (which is
  /// about 0.3 m off: 3 sigma and the fit's own error), and no other object of at least
  /// `min_object_points` may reach that far. `attribute = false`: every cluster reaching into the
  /// vehicle's footprint is the vehicle, the refusals are off (the paper's pipeline on an empty road).
  bool attribute = true;
  double size_margin = 0.6;         ///< m
  double attribution_radius = 1.2;  ///< m
  int min_object_points = 5;
  /// Points of other objects that hide part of the vehicle's expected footprint from the LiDAR make the
  /// view partial: refused from this many. A point hides it when it is nearer, within the footprint's
  /// bearing, and rises above the line of sight from the LiDAR to the top of the part the fit uses
  /// (cut_height; occlusion_top without the cut) at the footprint's nearest range: from a high pole a
  /// pedestrian or a kerb halfway sees under that line, from a 2 m mast a car does not.
  int occlusion_points = 5;
  double occlusion_top = 1.2;  ///< m, the top of a car's lower body, when height_cut is off
  /// Background stands there too (a parked car, a hedge, a post): it hides the vehicle when its points
  /// above the line of sight cover at least this share of the footprint's bearings. A post or a lamp
  /// post in front of a car hides a strip of it and the fit holds (site B's posts, 2 m from its mast,
  /// cover 30-50 % of a car 11-20 m away, whose fixes were within 4 cm; 0.3 refused them); a car parked
  /// squarely in front hides it.
  double background_occlusion_share = 0.5;
  /// The fitted heading against the CAM's: a fit turned further than this put its box on the wrong faces
  /// (held-back real frames, the maintainers' measurement: fixes 69-73 cm off with headings 22-26 deg wrong). Refused beyond it; <= 0: no check.
  double max_heading_disagreement = 10.0 * M_PI / 180.0;  ///< rad
  /// The true-size box rests on the fitted corner nearest the LiDAR. With one face of the vehicle seen
  /// and no corner, that face's end is a corner only if the face is seen whole; one shorter than its side
  /// of the vehicle by more than this (head-on from afar, a high mount's few beams on the chassis) puts
  /// the box on a guess up to half the vehicle off: refused (with `attribute` and `align_true_size`).
  double max_face_shortfall = 0.3;  ///< m
  /// ... except a front or rear face seen alone and obliquely (at least `oblique_face` between the line
  /// of sight and the face's normal): the box rests on its end nearest the LiDAR, which is then the
  /// body's true corner (what is lost is the far end, seen at grazing incidence), so the face may be
  /// shorter: refused only beyond this plus the LiDAR's column spacing on the face (its returns stop
  /// inside the body's edges, one spacing in all on average), and beyond what keeps the placement's
  /// error across within `max_face_placement_error`. A 64-beam LiDAR 8 m up beside the road sees cars
  /// coming or going at 40-60 m so, 0.3-0.6 m short with a CAM of the body's size (test HighMount.*:
  /// 61 -> 67 of 84 frames with a fix, none worse than 13.3 cm), 0.6-0.9 m with a label's (0.36 m wider
  /// than the body). Seen square on, from a gantry over the lane, either end may be the lost one, and
  /// `max_face_shortfall` holds. Side faces keep it too: taken obliquely up to 0.6 m short, they gave
  /// the 2 m masts of the experiment fixes that made the fused error worse (site B's VLP-32C 0.42 ->
  /// 0.50 cm) while the twin's RSUs sent the registry's figure rather than each fix's covariance.
  double max_width_face_shortfall = 0.6;  ///< m
  double oblique_face = 5.0 * M_PI / 180.0;  ///< rad
  /// The largest error across a front or rear face seen alone that its placement may have: placed from
  /// its near end with the CAM's width, it errs by at most (shortfall + column spacing) / 2, and a face
  /// shorter than that allows is refused. Label-sized CAMs from 2-8 m up, 13 drives each: 66-73 % ->
  /// 75-82 % of the frames with a fix, none beyond 0.4 m (test HighMount.*).
  double max_face_placement_error = 0.5;  ///< m
  /// With one face seen, that face must be the body's end on its side: refused when the vehicle's
  /// returns at any height (those above the cut too) reach out beyond it, towards the LiDAR, by more than
  /// this. From a 2 m mast 60 m away, a 64-beam LiDAR's one ring under the rear bumper returns from the
  /// underbody 0.9-1.0 m inside the body while the rings above return from the bumper and the boot: the
  /// box was placed a metre off along the car (test HighMount.*). A side mirror reaches out 0.2 m. <= 0: no check.
  double max_face_overhang = 0.3;  ///< m
  /// Returns the fit needs (with `attribute`): a car 60 m from a 2 m mast showed a 64-beam LiDAR 4 on
  /// its lower body, which fitted a box 0.9 m off with a heading 9 deg wrong (test HighMount.*). Five
  /// on one face seen whole (a car coming or going at 50-60 m from a pole) place it within 5-38 cm, and
  /// the fix's covariance says how far across (sd 0.3-0.45 m there): from 8 m up the OS1-64 gave 61 ->
  /// 70 of 84 frames a fix with six -> five, none beyond 3 sd; the twin's poles 94 -> 100 of 123.
  int min_fit_points = 5;
  /// Heights (the cut, the road's own returns, the line of sight) over the local road found in the
  /// background (RoadSurface); false: over the plane z = 0 of the mount's road datum.
  bool local_road = true;
  RoadSurfaceConfig road;
  LShapeConfig lshape;
  /// The faces' measure of the body's sides (body_size.hpp), at the covariance's azimuth step.
  BodySizeConfig body_size;
  FixCovarianceModel covariance;
};

/// Throws coloc::Error naming the first key that is out of range or not finite, and its value (the
/// constructor of RoadsidePerception calls it, and so does an RSU station's).
void validate(const RoadsidePerceptionConfig& config);

/// Where the RSU's LiDAR stands: map position of the sensor (z = height above the road), heading, and
/// its tilt (a pole's LiDAR is pitched down towards the road; 1.9 deg at 40 m puts a point 1.3 m off in
/// height, the height cut then keeps the wrong part of the body).
struct RsuMount {
  Eigen::Vector3d position = Eigen::Vector3d(0.0, 0.0, 2.0);
  double yaw = 0.0;
  double roll = 0.0, pitch = 0.0;  ///< rad, about the sensor's x and y axes (applied before the yaw)
};

/// Why a frame gave no fix.
enum class Refusal {
  kNone,
  kNoVehicle,      ///< no object (or too few points) at the CAM's position
  kTooLarge,       ///< the cluster there is larger than the vehicle: merged with a neighbour or a structure
  kAmbiguous,      ///< more than one object there
  kOccluded,       ///< another object between the LiDAR and the vehicle
  kNotAtPosition,  ///< the fitted vehicle is farther from the CAM's position than attribution_radius
  kInconsistent,   ///< disagrees with the vehicle's track (FixConsistency), or has none to agree with
  kCornerNotSeen,  ///< one face seen: no corner to rest the vehicle's box on
  /// Not the perception's: the twin's analysis bound (TwinRecordingOptions::oracle_fix_limit) withheld
  /// a fix farther than its limit from the vehicle's true position, which no RSU can know.
  kBeyondOracleLimit,
  kHeadingDisagrees,  ///< the fitted heading is further from the CAM's than max_heading_disagreement
  kTooFewPoints,      ///< fewer returns on the part of the body the fit uses than min_fit_points
};
const char* toString(Refusal r);
inline constexpr int kRefusalCount = 11;

struct VehicleDetection {
  bool found = false;
  Refusal refusal = Refusal::kNone;  ///< why not, when !found
  Stamp stamp = 0;                 ///< the frame's capture time
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< vehicle centre, map frame
  double yaw = 0.0;                ///< map frame
  Eigen::Vector2d alignment_point = Eigen::Vector2d::Zero();
  bool corner_seen = true;         ///< AlignedBox::corner_seen of the fit
  double face_shortfall = 0.0;     ///< AlignedBox::face_shortfall of the fit, m
  /// With one face seen: how far the vehicle's returns at any height reach out beyond that face, m.
  double face_overhang = 0.0;
  double heading_disagreement = 0.0;  ///< rad, the fitted heading against the CAM's, modulo a half turn
  /// The fix's covariance from its fit (fix_covariance.hpp), map frame, m^2; when found.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  /// What the fit's faces measure of the body's length and width, m (negative where they do not):
  /// body_size.hpp; when found.
  Eigen::Vector2d measured_sides = Eigen::Vector2d::Constant(-1.0);
  /// The length and width the true-size box was placed with, m: the size asked for, or a side this
  /// frame measured shorter (BodySizeConfig::frame_tolerance); when found.
  Eigen::Vector2d placed_size = Eigen::Vector2d::Zero();
  std::size_t foreground_points = 0, fit_points = 0;
  double processing_ms = 0.0;      ///< measured, the whole pipeline
};

class RoadsidePerception {
 public:
  /// `reference_frame`: the background in the sensor frame: a frame of the empty scene, or what a
  /// BackgroundLearner learned from frames of the busy one. The local road is found in it.
  RoadsidePerception(const std::vector<Eigen::Vector3f>& reference_frame, const RsuMount& mount,
                     const RoadsidePerceptionConfig& config = {});
  ~RoadsidePerception();
  RoadsidePerception(RoadsidePerception&&) noexcept;
  RoadsidePerception& operator=(RoadsidePerception&&) noexcept;

  /// Detects the vehicle in `frame` (sensor frame). `reference_position` is where the vehicle is
  /// expected (map frame, e.g. from its CAM), `heading_prior` its heading, `length` and `width` its
  /// true dimensions from the CAM.
  VehicleDetection detect(const std::vector<Eigen::Vector3f>& frame, Stamp stamp, const Eigen::Vector2d& reference_position,
                          double heading_prior, double length, double width) const;

  const RoadsidePerceptionConfig& config() const;
  /// The road's height at `xy` (map frame) over the mount's road datum, as the background showed it.
  double roadHeight(const Eigen::Vector2d& xy) const;
  /// The plane through the road in the map frame, if the background showed one (config().local_road).
  std::optional<GroundPlane> roadPlane() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::roadside
