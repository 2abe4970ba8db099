#include "coloc/roadside/roadside_perception.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <unordered_map>

#include "coloc/core/error.hpp"
#include "coloc/core/number_text.hpp"
#include "coloc/roadside/road_surface.hpp"
#include "near_points.hpp"

namespace coloc::roadside {

struct RoadsidePerception::Impl {
  RoadsidePerceptionConfig config;
  RsuMount mount;
  std::optional<NearPoints> background;  ///< the reference frame's points, sensor frame
  Eigen::Matrix3d rotation;  ///< sensor axes to map axes (yaw, pitch, roll)
  RoadSurface road;          ///< the local road's height, map frame
};

namespace {

// Groups points closer than `distance` on the ground plane (single linkage), through a grid of that
// cell size. Vehicles are apart on the road, while a sparse LiDAR's rings on one body can lie farther
// apart in height than any sensible 3-D linkage distance (0.66 m for a VLP-16 at 19 m).
std::vector<std::vector<std::size_t>> clusters(const std::vector<Eigen::Vector3d>& points, double distance) {
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  auto key = [&](const Eigen::Vector3d& p, int dx, int dy) {
    const auto c = (p.head<2>() / distance).array().floor().cast<std::int64_t>();
    return (static_cast<std::uint64_t>(c.x() + dx + (1 << 30)) << 32) | static_cast<std::uint64_t>(c.y() + dy + (1 << 30));
  };
  for (std::size_t i = 0; i < points.size(); ++i) grid[key(points[i], 0, 0)].push_back(i);
  std::vector<int> label(points.size(), -1);
  std::vector<std::vector<std::size_t>> out;
  for (std::size_t seed = 0; seed < points.size(); ++seed) {
    if (label[seed] >= 0) continue;
    out.emplace_back();
    std::vector<std::size_t> stack = {seed};
    label[seed] = static_cast<int>(out.size() - 1);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      out.back().push_back(i);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const auto it = grid.find(key(points[i], dx, dy));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second)
            if (label[j] < 0 && (points[j] - points[i]).head<2>().norm() <= distance) {
              label[j] = label[seed];
              stack.push_back(j);
            }
        }
    }
  }
  return out;
}

}  // namespace

void validate(const RoadsidePerceptionConfig& c) {
  // A NaN passes every comparison a check makes and turns the check off (a NaN max_face_overhang
  // would let every face seen alone through): each figure is refused by name before it is used.
  const auto fail = [](const std::string& key, double value, const char* what) {
    throw Error("roadside perception: " + key + " must be " + what + ", got " + exactNumberText(value));
  };
  const auto positive = [&](const std::string& key, double v) {
    if (!(std::isfinite(v) && v > 0.0)) fail(key, v, "finite and > 0");
  };
  const auto non_negative = [&](const std::string& key, double v) {
    if (!(std::isfinite(v) && v >= 0.0)) fail(key, v, "finite and >= 0");
  };
  const auto finite = [&](const std::string& key, double v) {
    if (!std::isfinite(v)) fail(key, v, "finite (<= 0 turns the check off)");
  };
  const auto at_least = [&](const std::string& key, int v, int least) {
    if (v < least) fail(key, v, least == 1 ? ">= 1" : ">= 2");
  };
  positive("background_distance", c.background_distance);
  positive("search_radius", c.search_radius);
  positive("cluster_distance", c.cluster_distance);
  positive("cut_height", c.cut_height);
  if (c.max_points < 0) fail("max_points", c.max_points, ">= 0 (0: all)");
  non_negative("size_margin", c.size_margin);
  positive("attribution_radius", c.attribution_radius);
  at_least("min_object_points", c.min_object_points, 1);
  at_least("occlusion_points", c.occlusion_points, 1);
  positive("occlusion_top", c.occlusion_top);
  if (!(c.background_occlusion_share > 0.0 && c.background_occlusion_share <= 1.0))
    fail("background_occlusion_share", c.background_occlusion_share, "in (0, 1]");
  finite("max_heading_disagreement", c.max_heading_disagreement);
  non_negative("max_face_shortfall", c.max_face_shortfall);
  non_negative("max_width_face_shortfall", c.max_width_face_shortfall);
  if (!(c.oblique_face >= 0.0 && c.oblique_face < 0.5 * M_PI)) fail("oblique_face", c.oblique_face, "in [0, pi/2) rad");
  positive("max_face_placement_error", c.max_face_placement_error);
  finite("max_face_overhang", c.max_face_overhang);
  at_least("min_fit_points", c.min_fit_points, 2);  // the L-shape fit's least
  positive("road.cell", c.road.cell);
  non_negative("road.min_range", c.road.min_range);
  if (!(std::isfinite(c.road.max_range) && c.road.max_range > c.road.min_range)) fail("road.max_range", c.road.max_range, "finite and > road.min_range");
  positive("road.band", c.road.band);
  at_least("road.min_points", c.road.min_points, 1);
  non_negative("road.smoothing", c.road.smoothing);
  if (!(c.lshape.angle_step_deg > 0.0 && c.lshape.angle_step_deg <= 90.0)) fail("lshape.angle_step_deg", c.lshape.angle_step_deg, "in (0, 90]");
  positive("lshape.closeness_floor", c.lshape.closeness_floor);
  non_negative("lshape.edge_band", c.lshape.edge_band);
  non_negative("covariance.range_noise", c.covariance.range_noise);
  positive("covariance.azimuth_step", c.covariance.azimuth_step);
  non_negative("covariance.size_step", c.covariance.size_step);
  non_negative("covariance.heading_floor", c.covariance.heading_floor);
  non_negative("covariance.floor", c.covariance.floor);
  positive("covariance.scale", c.covariance.scale);
  validate(c.body_size);
}

RoadsidePerception::RoadsidePerception(const std::vector<Eigen::Vector3f>& reference_frame, const RsuMount& mount,
                                       const RoadsidePerceptionConfig& config)
    : impl_(std::make_unique<Impl>()) {
  if (reference_frame.empty()) throw Error("roadside perception: the reference (background) frame is empty");
  validate(config);
  if (!(mount.position.allFinite() && std::isfinite(mount.yaw) && std::isfinite(mount.roll) && std::isfinite(mount.pitch)))
    throw Error("roadside perception: the mount's position and angles must be finite");
  impl_->config = config;
  impl_->mount = mount;
  impl_->background.emplace(reference_frame, config.background_distance);
  impl_->rotation = (Eigen::AngleAxisd(mount.yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(mount.pitch, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(mount.roll, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  if (config.local_road) {
    std::vector<Eigen::Vector3d> in_map;
    in_map.reserve(reference_frame.size());
    for (const auto& p : reference_frame) in_map.push_back(impl_->rotation * p.cast<double>() + mount.position);
    impl_->road = RoadSurface(in_map, mount.position.head<2>(), config.road);
  }
}

double RoadsidePerception::roadHeight(const Eigen::Vector2d& xy) const { return impl_->road.height(xy); }
std::optional<GroundPlane> RoadsidePerception::roadPlane() const { return impl_->road.plane(); }

RoadsidePerception::~RoadsidePerception() = default;
RoadsidePerception::RoadsidePerception(RoadsidePerception&&) noexcept = default;
RoadsidePerception& RoadsidePerception::operator=(RoadsidePerception&&) noexcept = default;
const RoadsidePerceptionConfig& RoadsidePerception::config() const { return impl_->config; }

const char* toString(Refusal r) {
  switch (r) {
    case Refusal::kNone: return "none";
    case Refusal::kNoVehicle: return "no vehicle at the CAM position";
    case Refusal::kTooLarge: return "cluster larger than the vehicle";
    case Refusal::kAmbiguous: return "more than one object at the CAM position";
    case Refusal::kOccluded: return "vehicle partly hidden by another object";
    case Refusal::kNotAtPosition: return "fitted vehicle away from the CAM position";
    case Refusal::kInconsistent: return "disagrees with the vehicle's track";
    case Refusal::kCornerNotSeen: return "one face seen, no corner to place the vehicle on";
    case Refusal::kBeyondOracleLimit: return "beyond the oracle limit from the true position (analysis bound)";
    case Refusal::kHeadingDisagrees: return "fitted heading away from the CAM's";
    case Refusal::kTooFewPoints: return "too few returns on the vehicle's body to fit";
  }
  return "?";
}

namespace {

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

// An object: clusters that together fit in the vehicle's size, in the frame of the CAM's heading
// (u along it, v across).
struct Object {
  std::vector<std::size_t> points;
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  bool too_large = false;
};

// The lowest part of an object's body (below the cut, at most max_points, lowest first) into `xy`, and
// the true-size box on its L-shape fit (its centre at the alignment point's default when < 3 points).
AlignedBox fitBody(const std::vector<std::size_t>& points, const std::vector<Eigen::Vector3d>& foreground, const RoadsidePerceptionConfig& c,
                   const Eigen::Vector2d& lidar, double length, double width, double heading_prior, std::vector<Eigen::Vector2d>& xy,
                   FittedRectangle* fit = nullptr) {
  std::vector<Eigen::Vector3d> body;
  for (std::size_t i : points)
    if (!c.height_cut || foreground[i].z() < c.cut_height) body.push_back(foreground[i]);
  std::sort(body.begin(), body.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
  if (c.max_points > 0 && body.size() > static_cast<std::size_t>(c.max_points)) body.resize(static_cast<std::size_t>(c.max_points));
  xy.clear();
  for (const auto& p : body) xy.push_back(p.head<2>());
  if (xy.size() < 3) return {Eigen::Vector2d::Constant(1e9), 0.0, Eigen::Vector2d::Constant(1e9)};
  const FittedRectangle rectangle = fitLShape(xy, c.lshape);
  if (fit) *fit = rectangle;
  return alignTrueSizeBox(rectangle, xy, lidar, length, width, heading_prior);
}

// How much shorter than its side of the vehicle the one face seen may be (AlignedBox::face_shortfall).
// A front or rear face seen obliquely rests the box on its near end, the body's corner. Its returns stop
// inside the body's edges by up to a column's spacing on the face at each end, one spacing in all on
// average: 0.3-0.4 m at 50-60 m from a 64-beam LiDAR (0.35 deg), as much as a label's excess width. So it
// may be short by max_width_face_shortfall plus that spacing. Placed from its near end with the CAM's
// width, its error across is half the shortfall plus half the near end's loss less the far end's: at
// most (shortfall + spacing) / 2, which max_face_placement_error bounds.
double faceShortfallLimit(const AlignedBox& box, double range, const RoadsidePerceptionConfig& c) {
  if (!box.width_face_alone || box.face_obliquity < c.oblique_face) return c.max_face_shortfall;
  const double spacing = range * c.covariance.azimuth_step / std::max(std::cos(box.face_obliquity), 0.5);
  return std::min(c.max_width_face_shortfall + spacing, 2.0 * c.max_face_placement_error - spacing);
}

// Whether a face's far end, `end`, is seen as its end (BodySizeConfig::end_clearance): the LiDAR's
// next columns beyond it, away from `corner`, at elevations lo..hi (rad, those the body was seen at),
// return from farther than the end by `clearance`, and none from nearer. `rotation` turns a frame's
// point into the map's axes; `lidar` is the LiDAR in the map.
bool endSeen(const std::vector<Eigen::Vector3f>& frame, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& lidar, const Eigen::Vector2d& corner,
             const Eigen::Vector2d& end, double lo, double hi, double azimuth_step, double clearance) {
  const Eigen::Vector2d e = end - lidar.head<2>(), k = corner - lidar.head<2>();
  const double end_range = e.norm();
  if (!(end_range > 1e-6) || !(azimuth_step > 0.0)) return false;
  const Eigen::Vector2d u = e / end_range;
  // Beyond is the side of the end away from the corner.
  const double away = u.x() * k.y() - u.y() * k.x() > 0.0 ? -1.0 : 1.0;
  const double first = 0.5 * azimuth_step, last = 2.5 * azimuth_step, tan_last = std::tan(last);
  bool beyond = false;
  for (const Eigen::Vector3f& p : frame) {
    if (!p.allFinite()) continue;
    const Eigen::Vector3d q = rotation * p.cast<double>() + lidar;
    const Eigen::Vector2d d = q.head<2>() - lidar.head<2>();
    const double along = d.dot(u), side = away * (u.x() * d.y() - u.y() * d.x());
    if (!(along > 0.0) || !(side > 0.0) || side > along * tan_last) continue;  // outside the columns, cheaply
    const double angle = std::atan2(side, along);
    if (angle <= first || angle > last) continue;
    const double range = d.norm(), elevation = std::atan2(q.z() - lidar.z(), range);
    if (elevation < lo || elevation > hi) continue;
    if (range < end_range + clearance) return false;
    beyond = true;
  }
  return beyond;
}

}  // namespace

VehicleDetection RoadsidePerception::detect(const std::vector<Eigen::Vector3f>& frame, Stamp stamp, const Eigen::Vector2d& reference,
                                            double heading_prior, double length, double width) const {
  const auto start = std::chrono::steady_clock::now();
  const RoadsidePerceptionConfig& c = impl_->config;
  VehicleDetection out;
  out.stamp = stamp;
  const Eigen::Vector2d lidar = impl_->mount.position.head<2>();
  const Eigen::Vector2d heading(std::cos(heading_prior), std::sin(heading_prior)), across(-heading.y(), heading.x());
  // Where the vehicle is expected, seen from the LiDAR: the bearings its footprint spans and the range
  // of its nearest part. Anything of another object in that sector and nearer hides part of it.
  const double bearing0 = std::atan2(reference.y() - lidar.y(), reference.x() - lidar.x());
  double bearing_lo = 0.0, bearing_hi = 0.0;
  for (double su : {-0.5, 0.5})
    for (double sv : {-0.5, 0.5}) {
      const Eigen::Vector2d corner = reference + su * length * heading + sv * width * across;
      const double b = wrapAngle(std::atan2(corner.y() - lidar.y(), corner.x() - lidar.x()) - bearing0);
      bearing_lo = std::min(bearing_lo, b);
      bearing_hi = std::max(bearing_hi, b);
    }
  const Eigen::Vector2d lidar_local((lidar - reference).dot(heading), (lidar - reference).dot(across));
  const Eigen::Vector2d nearest_local(std::clamp(lidar_local.x(), -0.5 * length, 0.5 * length),
                                      std::clamp(lidar_local.y(), -0.5 * width, 0.5 * width));
  const double footprint_range = (lidar_local - nearest_local).norm();
  constexpr double kOccluderClearance = 0.3;  // m nearer than the footprint: the footprint's own error and noise
  // The line of sight from the LiDAR to the top of the body part the fit uses, at the footprint's
  // nearest range: a point below it at its own range hides nothing of that part (from a high mount,
  // a pedestrian or an uneven road between; from a 2 m mast, a car still does).
  // Heights here are the map's (over the mount's road datum): the road under the vehicle need not be
  // the road under the pole.
  const RoadSurface& road = impl_->road;
  const double lidar_z = impl_->mount.position.z();
  const double sight_top = road.height(reference) + (c.height_cut ? c.cut_height : c.occlusion_top);
  const auto sightHeight = [&](double range) { return lidar_z + (sight_top - lidar_z) * range / std::max(footprint_range, 1e-3); };
  // A point whose bearing is further off the expected one than the sector reaches on either side is
  // outside it: a cosine against a bound rules out most near points without the two arc tangents and
  // the wrap. The margin, a microradian, is far above either way's rounding (1e-15), so every point
  // is decided as the exact test alone decides it.
  const double reach = std::max(-bearing_lo, bearing_hi) + 1e-6;
  const double cos_reach = reach < M_PI ? std::cos(reach) : -2.0;
  const Eigen::Vector2d toward(std::cos(bearing0), std::sin(bearing0));
  const auto inSector = [&](const Eigen::Vector2d& xy, double z) {
    // Range first: most of a frame lies beyond the vehicle, and needs no bearing.
    const Eigen::Vector2d d = xy - lidar;
    const double range = d.norm();
    if (!(range < footprint_range - kOccluderClearance)) return false;
    if (z < sightHeight(range)) return false;
    if (d.dot(toward) < cos_reach * range) return false;
    const double b = wrapAngle(std::atan2(xy.y() - lidar.y(), xy.x() - lidar.x()) - bearing0);
    return b >= bearing_lo && b <= bearing_hi;
  };
  // 1. Foreground: near the expected position and away from the reference frame. Points farther from
  //    the reference position are background without a tree query (the paper's restriction), except
  //    in the sector between the LiDAR and the vehicle, where they count as occluders.
  std::vector<Eigen::Vector3d> foreground;  // map frame, z = height above the road under the point
  std::vector<double> foreground_z;         // the map's z of each
  int far_occluders = 0;
  // Background in front of the vehicle: its points, and which of 20 equal parts of the footprint's
  // bearings they fall in.
  int background_occluders = 0;
  std::vector<bool> hidden(20, false);
  for (const Eigen::Vector3f& p : frame) {
    const Eigen::Vector3d in_map = impl_->rotation * p.cast<double>() + impl_->mount.position;
    const Eigen::Vector2d xy = in_map.head<2>();
    const bool near = (xy - reference).norm() <= c.search_radius;
    if (!near && !(c.attribute && inSector(xy, in_map.z()))) continue;
    const double height = in_map.z() - road.height(xy);
    if (height < 0.05) continue;  // the road itself
    if (impl_->background->anyWithin(p)) {
      // What stands still between the LiDAR and the vehicle (a parked car, a hedge) hides part of it as
      // much as what moves: background to the clustering, an occluder all the same, by the share of the
      // footprint's bearings it covers (a post or a sign's pole in front of a car hides a strip of it).
      if (c.attribute && inSector(xy, in_map.z())) {
        const double b = wrapAngle(std::atan2(xy.y() - lidar.y(), xy.x() - lidar.x()) - bearing0);
        const auto bin = static_cast<std::size_t>(std::clamp((b - bearing_lo) / (bearing_hi - bearing_lo + 1e-9), 0.0, 0.999) * hidden.size());
        hidden[bin] = true;
        ++background_occluders;
      }
      continue;
    }
    if (near) {
      foreground.emplace_back(xy.x(), xy.y(), height);
      foreground_z.push_back(in_map.z());
    } else {
      ++far_occluders;
    }
  }
  out.foreground_points = foreground.size();
  const auto groups = clusters(foreground, c.cluster_distance);
  std::vector<std::size_t> vehicle_points;
  // The vehicle's lowest points, their L-shape and the true-size box (fitted once per object).
  std::vector<Eigen::Vector2d> xy;
  FittedRectangle fit;
  AlignedBox box{};
  const auto finish = [&](Refusal why) {
    out.refusal = why;
    out.processing_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
  if (!c.attribute) {
    // 2. The vehicle is every cluster that reaches into its footprint around the expected position. A
    //    body seen from afar falls apart into pieces (bumper, cabin, side) farther apart than any linkage
    //    distance that still separates it from its neighbours; its size, known from the CAM, joins them.
    const double reach = 0.5 * std::hypot(length, width) + 1.0;
    for (const auto& g : groups) {
      bool near = false;
      for (std::size_t i : g) near = near || (foreground[i].head<2>() - reference).norm() <= reach;
      if (near) vehicle_points.insert(vehicle_points.end(), g.begin(), g.end());
    }
  } else {
    // 2. Objects: the clusters, largest first, each joined to an object it fits with in the vehicle's
    //    size (a body seen from afar falls apart into bumper, side and cabin), else an object of its own.
    const double max_u = length + c.size_margin, max_v = width + c.size_margin;
    std::vector<std::size_t> order(groups.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return groups[a].size() > groups[b].size(); });
    std::vector<Object> objects;
    for (std::size_t g : order) {
      Object piece;
      for (std::size_t i : groups[g]) {
        const Eigen::Vector2d d = foreground[i].head<2>() - reference;
        const double u = d.dot(heading), v = d.dot(across);
        piece.u0 = std::min(piece.u0, u), piece.u1 = std::max(piece.u1, u), piece.v0 = std::min(piece.v0, v), piece.v1 = std::max(piece.v1, v);
      }
      piece.points = groups[g];
      piece.too_large = piece.u1 - piece.u0 > max_u || piece.v1 - piece.v0 > max_v;
      bool joined = false;
      for (Object& o : objects) {
        if (piece.too_large || o.too_large) break;
        const double u0 = std::min(o.u0, piece.u0), u1 = std::max(o.u1, piece.u1), v0 = std::min(o.v0, piece.v0), v1 = std::max(o.v1, piece.v1);
        if (u1 - u0 > max_u || v1 - v0 > max_v) continue;
        o.u0 = u0, o.u1 = u1, o.v0 = v0, o.v1 = v1;
        o.points.insert(o.points.end(), piece.points.begin(), piece.points.end());
        joined = true;
        break;
      }
      if (!joined) objects.push_back(std::move(piece));
    }
    // 3. The candidates: objects of some size reaching into the footprint widened by the CAM's error.
    //    One larger than the vehicle on the footprint itself may have swallowed it: no fix.
    const double R = c.attribution_radius;
    const auto reaches = [&](const Object& o, double widen) {
      return o.u1 >= -0.5 * length - widen && o.u0 <= 0.5 * length + widen && o.v1 >= -0.5 * width - widen && o.v0 <= 0.5 * width + widen;
    };
    std::vector<const Object*> candidates;
    for (const Object& o : objects) {
      if (static_cast<int>(o.points.size()) < c.min_object_points || !reaches(o, R)) continue;
      if (o.too_large && reaches(o, 0.5 * R)) return finish(Refusal::kTooLarge);
      if (!o.too_large) candidates.push_back(&o);
    }
    // 4. Nothing of another object between the LiDAR and where the vehicle is expected: a partial view
    //    puts the box on the wrong corner.
    const auto occluding = [&](const Object* except) {
      int n = far_occluders;
      if (background_occluders >= c.occlusion_points &&
          std::count(hidden.begin(), hidden.end(), true) >= static_cast<long>(std::ceil(c.background_occlusion_share * hidden.size())))
        n += background_occluders;
      for (const Object& o : objects)
        if (&o != except)
          for (std::size_t i : o.points) n += inSector(foreground[i].head<2>(), foreground_z[i]) ? 1 : 0;
      return n;
    };
    if (candidates.empty()) return finish(occluding(nullptr) >= c.occlusion_points ? Refusal::kOccluded : Refusal::kNoVehicle);
    // 5. Each candidate fitted; the vehicle is the one whose box centre is near the CAM's position, and
    //    it must be the only one there.
    const Object* vehicle = nullptr;
    double best = 1e9;
    int plausible = 0;
    bool fitted = false;
    for (const Object* o : candidates) {
      std::vector<Eigen::Vector2d> o_xy;
      FittedRectangle o_fit;
      const AlignedBox o_box = fitBody(o->points, foreground, c, lidar, length, width, heading_prior, o_xy, &o_fit);
      fitted = fitted || o_xy.size() >= 3;
      const double d = o_xy.size() < 3 ? 1e9 : (o_box.center - reference).norm();
      plausible += d <= R ? 1 : 0;
      if (d < best) best = d, vehicle = o, box = o_box, fit = o_fit, xy = std::move(o_xy);
    }
    // Candidates with no returns on the lower body at all: hidden by something nearer, or a car passing
    // close to a low mast, below its lowest beam (a VLP-16 2 m up sees nothing under 0.8 m nearer than
    // 4.5 m). Nothing to fit, rather than a fit away from the CAM's position, as the RSU's operator
    // should read it.
    if (!fitted) return finish(occluding(nullptr) >= c.occlusion_points ? Refusal::kOccluded : Refusal::kTooFewPoints);
    if (occluding(vehicle) >= c.occlusion_points) return finish(Refusal::kOccluded);
    if (best > R) return finish(Refusal::kNotAtPosition);
    if (plausible > 1) return finish(Refusal::kAmbiguous);
    vehicle_points = vehicle->points;
  }
  if (vehicle_points.size() < 5) return finish(Refusal::kNoVehicle);
  // 6. The lowest part of the body, the L-shape fit, the plain centre or the true-size box.
  if (!c.attribute) box = fitBody(vehicle_points, foreground, c, lidar, length, width, heading_prior, xy, &fit);
  if (xy.size() < 3) return finish(Refusal::kNoVehicle);
  out.fit_points = xy.size();
  out.corner_seen = box.corner_seen;
  out.face_shortfall = box.face_shortfall;
  if (c.attribute && c.align_true_size && box.face_shortfall > faceShortfallLimit(box, (box.alignment_point - lidar).norm(), c))
    return finish(Refusal::kCornerNotSeen);
  // One face seen: the box rests on it as on the body's end, which no return of the vehicle, at any
  // height, lies beyond.
  if (c.attribute && c.align_true_size && !box.corner_seen && c.max_face_overhang > 0.0) {
    const Eigen::Vector2d outward = box.width_face_alone ? Eigen::Vector2d(-box.along) : Eigen::Vector2d(-box.across);
    for (std::size_t i : vehicle_points) out.face_overhang = std::max(out.face_overhang, (foreground[i].head<2>() - box.alignment_point).dot(outward));
    if (out.face_overhang > c.max_face_overhang) return finish(Refusal::kCornerNotSeen);
  }
  // The fit's heading against the CAM's (modulo a half turn: the L-shape cannot tell front from back).
  if (c.attribute && c.max_heading_disagreement > 0.0) {
    const double off = std::abs(wrapAngle(2.0 * (box.yaw - heading_prior))) / 2.0;
    out.heading_disagreement = off;
    if (off > c.max_heading_disagreement) return finish(Refusal::kHeadingDisagrees);
  }
  if (c.attribute && static_cast<int>(xy.size()) < c.min_fit_points) return finish(Refusal::kTooFewPoints);
  // What the faces measure of the body; a side this frame finds far shorter than the CAM's (a label's
  // or a CAM's box larger than the body: body_size.hpp) places the box instead.
  const Eigen::Vector2d measured = measureBodySides(box, lidar, c.covariance.azimuth_step, c.body_size);
  // This frame places the box with its own measure of a side only where it shows that side whole: the
  // body seen over some height, the face's far end seen as an end (body_size.hpp).
  Eigen::Vector2d placing = measured;
  // The heights over the road and the elevations from the LiDAR the fitted part of the body was seen
  // at, found once, when a side would be placed.
  double z_lo = 1e9, z_hi = -1e9, el_lo = 1e9, el_hi = -1e9;
  bool seen_found = false;
  for (int side = 0; side < 2; ++side) {
    const double cam = side == 0 ? length : width;
    if (!(c.body_size.frame_tolerance > 0.0) || !(placing[side] > 0.0) || !(cam - placing[side] > c.body_size.frame_tolerance)) continue;
    if (!seen_found) {
      seen_found = true;
      for (std::size_t i : vehicle_points) {
        if (c.height_cut && foreground[i].z() >= c.cut_height) continue;
        z_lo = std::min(z_lo, foreground[i].z());
        z_hi = std::max(z_hi, foreground[i].z());
        const double elevation = std::atan2(foreground_z[i] - lidar_z, (foreground[i].head<2>() - lidar).norm());
        el_lo = std::min(el_lo, elevation);
        el_hi = std::max(el_hi, elevation);
      }
    }
    constexpr double kRingMargin = 0.003;  // rad: a ring's own spread (beam angle's noise, the mount's tilt across a face)
    const Eigen::Vector2d end = box.alignment_point + (side == 0 ? box.length_face_extent * box.along : box.width_face_extent * box.across);
    if (!(z_hi - z_lo >= c.body_size.min_seen_height) ||
        !endSeen(frame, impl_->rotation, impl_->mount.position, box.alignment_point, end, el_lo - kRingMargin, el_hi + kRingMargin,
                 c.covariance.azimuth_step, c.body_size.end_clearance))
      placing[side] = -1.0;
  }
  const Eigen::Vector2d size = frameBodySize(placing, length, width, c.body_size);
  if (size != Eigen::Vector2d(length, width)) box.center = box.alignment_point + 0.5 * size.x() * box.along + 0.5 * size.y() * box.across;
  const Eigen::Vector2d position = c.align_true_size ? box.center : fit.center;
  if (c.attribute && (position - reference).norm() > c.attribution_radius) return finish(Refusal::kNotAtPosition);
  out.found = true;
  out.fit_points = xy.size();
  out.alignment_point = box.alignment_point;
  out.position = position;
  out.yaw = box.yaw;
  out.covariance = fixCovariance(box, (box.alignment_point - lidar).norm(), c.covariance);
  if (size != Eigen::Vector2d(length, width)) out.covariance += sizeCovariance(sizeDoubt(size, length, width, c.body_size.tolerance), box.yaw);
  out.covariance += sizeCovariance(frameDoubt(measured, size, length, width, c.body_size), box.yaw);
  out.measured_sides = measured;
  out.placed_size = size;
  return finish(Refusal::kNone);
}

}  // namespace coloc::roadside
