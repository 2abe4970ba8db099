#include "coloc/sim/lidar_model.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <mutex>

#include "coloc/core/error.hpp"
#include "coloc/sim/error_sources.hpp"
#include "coloc/sim/ray_noise.hpp"

namespace coloc::sim {

LidarSpec vlp16() {
  LidarSpec s;
  s.name = "VLP-16";
  s.vertical_deg = {-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};
  s.azimuth_offset_deg.assign(16, 0.0);
  s.max_range = 100.0;
  return s;
}

LidarSpec vlp32c() {
  LidarSpec s;
  s.name = "VLP-32C";
  s.vertical_deg = {-25.0, -1.0,  -1.667, -15.639, -11.31, 0.0,    -0.667, -8.843, -7.254, 0.333, -0.333,
                    -6.148, -5.333, 1.333, 0.667,   -4.0,   -4.667, 1.667,  1.0,    -3.667, -3.333, 3.333,
                    2.333,  -2.667, -3.0,  7.0,     4.667,  -2.333, -2.0,   15.0,   10.333, -1.333};
  s.azimuth_offset_deg = {-1.4, 4.2, -1.4, 1.4, -1.4, 1.4, -4.2, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -4.2, 1.4,
                          -1.4, 4.2, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4, -1.4, 1.4, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4};
  s.max_range = 200.0;
  return s;
}

LidarSpec os1_64() {
  LidarSpec s;
  s.name = "OS1-64";
  // 64 beams spread evenly over 45 deg, 1024 columns a turn: the kind of LiDAR roadside datasets put on
  // poles (its beams below the horizon are 0.7 deg apart where a VLP-32C's are 1.5-9.4 deg apart).
  for (int i = 0; i < 64; ++i) s.vertical_deg.push_back(-22.5 + 45.0 * i / 63.0);
  s.azimuth_offset_deg.assign(64, 0.0);
  s.azimuth_step_deg = 360.0 / 1024.0;
  s.max_range = 120.0;
  return s;
}

LidarSpec lidarNamed(const std::string& name) {
  if (name == "VLP-16") return vlp16();
  if (name == "VLP-32C") return vlp32c();
  if (name == "OS1-64") return os1_64();
  throw Error("no LiDAR model '" + name + "' in the twin (VLP-16, VLP-32C, OS1-64)");
}

LidarSpec withErrors(LidarSpec spec, const ErrorSources& errors) {
  spec.range_noise = errors.range_noise;
  spec.range_noise_per_m = errors.range_noise_per_m;
  spec.dropout = errors.dropout;
  spec.dropout_at_max_range = errors.dropout_at_max_range;
  spec.beam_divergence = errors.beam_divergence;
  spec.beam_divergence_vertical = errors.beam_divergence_vertical;
  return spec;
}

int firingsPerSweep(const LidarSpec& spec) { return static_cast<int>(std::lround(360.0 / spec.azimuth_step_deg)); }

namespace {

// Each ray's direction in the sensor frame, firing-major, for a spec's angles: the same every sweep, so
// computed once per spec (the trigonometry was a third of a sweep's cost outside the ray casting).
// In double for casting, and rounded to float for placing the points (as each point used to round it).
struct Directions {
  std::vector<Eigen::Vector3d> exact;
  std::vector<Eigen::Vector3f> rounded;
};

std::shared_ptr<const Directions> localDirections(const LidarSpec& spec, int firings) {
  struct Entry {
    std::vector<double> vertical, offsets;
    double step;
    std::shared_ptr<const Directions> directions;
  };
  static std::mutex mutex;
  static std::vector<Entry> cache;
  std::lock_guard<std::mutex> lock(mutex);
  for (const Entry& e : cache)
    if (e.vertical == spec.vertical_deg && e.offsets == spec.azimuth_offset_deg && e.step == spec.azimuth_step_deg) return e.directions;
  const int lasers = static_cast<int>(spec.vertical_deg.size());
  auto directions = std::make_shared<Directions>();
  directions->exact.reserve(static_cast<std::size_t>(firings * lasers));
  for (int f = 0; f < firings; ++f) {
    const double azimuth = spec.azimuth_step_deg * f;
    for (int l = 0; l < lasers; ++l) {
      const double a = (azimuth + spec.azimuth_offset_deg[l]) * M_PI / 180.0, e = spec.vertical_deg[l] * M_PI / 180.0;
      directions->exact.emplace_back(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    }
  }
  directions->rounded.reserve(directions->exact.size());
  for (const Eigen::Vector3d& d : directions->exact) directions->rounded.push_back(d.cast<float>());
  if (cache.size() >= 8) cache.erase(cache.begin());  // a twin uses two or three specs
  cache.push_back({spec.vertical_deg, spec.azimuth_offset_deg, spec.azimuth_step_deg, directions});
  return directions;
}

// What a footprint of three equal parts returns: samples within `separation` of each other make one
// echo at their mean range (mixed pixels), and the echo returned is the strongest, the share of the
// footprint it covers over its range squared (the same reflectivity assumed); nothing if none hit.
RayHit strongestEcho(RayHit (&samples)[3], double separation) {
  std::sort(std::begin(samples), std::end(samples), [](const RayHit& a, const RayHit& b) {
    return (a.distance >= 0.0f) != (b.distance >= 0.0f) ? a.distance >= 0.0f : a.distance < b.distance;
  });
  RayHit best;
  double best_energy = 0.0;
  for (int first = 0; first < 3 && samples[first].distance >= 0.0f;) {
    int last = first;
    double sum = 0.0;
    while (last < 3 && samples[last].distance >= 0.0f && samples[last].distance - samples[first].distance <= separation) sum += samples[last++].distance;
    const double range = sum / (last - first);
    const double energy = (last - first) / (range * range);
    if (energy > best_energy) best_energy = energy, best = {static_cast<float>(range), samples[first].mesh};
    first = last;
  }
  return best;
}

// The rays of a sweep at edges and the thirds of their footprints to cast, towards the neighbour that
// differs on either side (side 1: before or below, side 2: after or above); reused between sweeps.
class EdgeSamples {
 public:
  void clear() {
    edges_.clear();
    origins_.clear();
    directions_.clear();
  }
  /// `toward(sign)`: the direction of the third towards side 1 (sign -1) or side 2 (+1).
  template <typename Toward>
  void add(std::size_t ray, int sides, const Eigen::Vector3f& origin, Toward toward) {
    edges_.push_back({ray, sides, directions_.size()});
    for (int k = 1; k <= 2; ++k) {
      if (!(sides & k)) continue;
      origins_.push_back(origin);
      directions_.push_back(toward(k == 1 ? -1.0 : 1.0));
    }
  }
  /// Casts the thirds and gives each edge ray strongestEcho of its return and theirs; a third for which
  /// `counts(ray, hit)` is false is the centre's surface going on.
  template <typename Counts>
  void resolve(const LidarSpec& spec, const RayCaster& world, std::vector<RayHit>& hits, Counts counts) {
    if (edges_.empty()) return;
    world.cast(origins_, directions_, static_cast<float>(spec.max_range), hits_);
    for (const Edge& e : edges_) {
      RayHit samples[3] = {hits[e.ray], hits[e.ray], hits[e.ray]};
      std::size_t next = e.first;
      for (int k = 1; k <= 2; ++k) {
        if (!(e.sides & k)) continue;
        const RayHit& third = hits_[next++];
        if (counts(e.ray, third)) samples[k] = third;
      }
      hits[e.ray] = strongestEcho(samples, spec.echo_separation);
    }
  }

 private:
  struct Edge {
    std::size_t ray;
    int sides;
    std::size_t first;  ///< its first third among the casts
  };
  std::vector<Edge> edges_;
  std::vector<Eigen::Vector3f> origins_, directions_;
  std::vector<RayHit> hits_;
};

// The returns where a footprint straddles a depth edge. A ray is at an edge when the same laser's
// neighbouring firing hit something where it hit nothing, or something 0.1 m nearer or farther than a
// surface going on evenly would put it. The footprint is taken in three equal parts across the scan:
// the centre ray's, and on each side of such a neighbour a ray a third of the divergence towards it (on
// a side without one, the centre's surface goes on); the echo returned is strongestEcho's. Only the
// rays at edges are cast again.
void footprintsAtEdges(const LidarSpec& spec, const RayCaster& world, const std::vector<Eigen::Vector3d>& local, const std::vector<Eigen::Matrix3d>& turns,
                       const std::vector<Eigen::Vector3f>& origins, std::vector<RayHit>& hits) {
  const int lasers = static_cast<int>(spec.vertical_deg.size());
  const int firings = firingsPerSweep(spec);
  // Whether a sample towards `neighbour` can change what `centre` returns: not if the neighbour returned
  // nothing (the centre's echo stays alone), nor if it is farther by more than echo_separation (a third
  // of the footprint far away never outshines two thirds near), nor where the step to it is the step
  // from `other` on the centre's far side, within 0.1 m (a surface seen obliquely steps evenly).
  const float separation = static_cast<float>(spec.echo_separation);
  const auto differs = [separation](const RayHit& centre, const RayHit& neighbour, const RayHit& other) {
    if (neighbour.distance < 0.0f) return false;
    if (centre.distance < 0.0f) return true;
    const float step = neighbour.distance - centre.distance;
    if (other.distance >= 0.0f && std::abs(step - (centre.distance - other.distance)) <= 0.1f) return false;
    return step < -0.1f || (step > 0.1f && step <= separation);
  };
  thread_local EdgeSamples edges;
  edges.clear();
  // The firings' azimuth grows with f: the one before lies at a smaller angle about the sensor's z.
  const double side = spec.beam_divergence / 3.0;
  const double c = std::cos(side), s = std::sin(side);
  for (int f = 0; f < firings; ++f)
    for (int l = 0; l < lasers; ++l) {
      const std::size_t i = static_cast<std::size_t>(f * lasers + l);
      const std::size_t before = static_cast<std::size_t>(((f + firings - 1) % firings) * lasers + l);
      const std::size_t after = static_cast<std::size_t>(((f + 1) % firings) * lasers + l);
      const int sides = (differs(hits[i], hits[before], hits[after]) ? 1 : 0) | (differs(hits[i], hits[after], hits[before]) ? 2 : 0);
      if (!sides) continue;
      const Eigen::Vector3d& d = local[i];
      edges.add(i, sides, origins[i], [&](double sign) {
        const Eigen::Vector3d turned(c * d.x() - sign * s * d.y(), sign * s * d.x() + c * d.y(), d.z());
        return (turns[static_cast<std::size_t>(f)] * turned).normalized().cast<float>().eval();
      });
    }
  edges.resolve(spec, world, hits, [](std::size_t, const RayHit&) { return true; });
}

// The same up and down, between objects one above the other: a ray is at such an edge when the laser
// next to it in elevation, in the same firing, hit another object (another mesh) nearer, or farther
// by less than echo_separation (a car's sill over the road under it, seen from a pole; from a low mast
// the road lies farther behind and is told apart). Within one object the surface goes on (a road's
// rings of returns step by metres and are no edge). Run after the footprint across the scan, on its
// returns; the thirds of the footprint up and down are cast from the centre ray's direction.
void verticalFootprintsAtEdges(const LidarSpec& spec, const RayCaster& world, const std::vector<Eigen::Vector3d>& local,
                               const std::vector<Eigen::Matrix3d>& turns, const std::vector<Eigen::Vector3f>& origins,
                               const std::vector<RayHit>& centre_hits, std::vector<RayHit>& hits) {
  const int lasers = static_cast<int>(spec.vertical_deg.size());
  const int firings = firingsPerSweep(spec);
  // Each laser's neighbours in elevation (-1: none).
  std::vector<int> order(static_cast<std::size_t>(lasers)), below(static_cast<std::size_t>(lasers), -1), above(static_cast<std::size_t>(lasers), -1);
  for (int l = 0; l < lasers; ++l) order[static_cast<std::size_t>(l)] = l;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return spec.vertical_deg[static_cast<std::size_t>(a)] < spec.vertical_deg[static_cast<std::size_t>(b)]; });
  for (std::size_t k = 0; k + 1 < order.size(); ++k) {
    above[static_cast<std::size_t>(order[k])] = order[k + 1];
    below[static_cast<std::size_t>(order[k + 1])] = order[k];
  }
  const float separation = static_cast<float>(spec.echo_separation);
  const auto differs = [separation](const RayHit& centre, const RayHit& neighbour) {
    if (neighbour.distance < 0.0f) return false;
    if (centre.distance < 0.0f) return true;
    if (neighbour.mesh == centre.mesh) return false;
    const float step = neighbour.distance - centre.distance;
    return step < -0.1f || (step > 0.1f && step <= separation);
  };
  thread_local EdgeSamples edges;
  edges.clear();
  const double side = spec.beam_divergence_vertical / 3.0;
  for (int f = 0; f < firings; ++f)
    for (int l = 0; l < lasers; ++l) {
      const std::size_t i = static_cast<std::size_t>(f * lasers + l);
      const int lo = below[static_cast<std::size_t>(l)], hi = above[static_cast<std::size_t>(l)];
      const int sides = (lo >= 0 && differs(centre_hits[i], centre_hits[static_cast<std::size_t>(f * lasers + lo)]) ? 1 : 0) |
                        (hi >= 0 && differs(centre_hits[i], centre_hits[static_cast<std::size_t>(f * lasers + hi)]) ? 2 : 0);
      if (!sides) continue;
      const Eigen::Vector3d& d = local[i];
      const double azimuth = std::atan2(d.y(), d.x()), elevation = std::asin(std::clamp(d.z(), -1.0, 1.0));
      edges.add(i, sides, origins[i], [&](double sign) {
        const double e = elevation + sign * side;
        const Eigen::Vector3d turned(std::cos(e) * std::cos(azimuth), std::cos(e) * std::sin(azimuth), std::sin(e));
        return (turns[static_cast<std::size_t>(f)] * turned).normalized().cast<float>().eval();
      });
    }
  // A third on the centre's own object is the centre's surface going on (a road seen at a grazing
  // angle spreads its echo over a few decimetres about the centre's range; the sensor reports that).
  edges.resolve(spec, world, hits, [&](std::size_t ray, const RayHit& third) { return third.distance < 0.0f || third.mesh != centre_hits[ray].mesh; });
}

}  // namespace

std::vector<RayHit> castSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose) {
  std::vector<RayHit> hits;
  castSweep(spec, world, pose, hits);
  return hits;
}

void castSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose, std::vector<RayHit>& hits) {
  const int lasers = static_cast<int>(spec.vertical_deg.size());
  const int firings = firingsPerSweep(spec);
  const double sweep = 1.0 / spec.rotation_hz;
  const std::shared_ptr<const Directions> table = localDirections(spec, firings);
  const std::vector<Eigen::Vector3d>& local = table->exact;
  // Reused between sweeps of a thread: fresh buffers of this size cost page faults every sweep.
  thread_local std::vector<Eigen::Vector3f> origins, directions;
  thread_local std::vector<Eigen::Matrix3d> turns;  // the sensor's orientation at each firing
  const std::size_t rays = static_cast<std::size_t>(firings * lasers);
  origins.resize(rays);
  directions.resize(rays);
  turns.resize(static_cast<std::size_t>(firings));
  for (int f = 0; f < firings; ++f) {
    const double t = sweep * f / firings;
    const Eigen::Isometry3d sensor = pose(t);
    turns[static_cast<std::size_t>(f)] = sensor.linear();
    const Eigen::Vector3f origin = sensor.translation().cast<float>();
    for (int l = 0; l < lasers; ++l) {
      const std::size_t i = static_cast<std::size_t>(f * lasers + l);
      origins[i] = origin;
      directions[i] = (sensor.linear() * local[i]).normalized().cast<float>();
    }
  }
  world.cast(origins, directions, static_cast<float>(spec.max_range), hits);
  // Edges up and down are found on the centre rays' hits, before the footprint across the scan
  // changes them.
  thread_local std::vector<RayHit> centre;
  if (spec.beam_divergence_vertical > 0.0) centre = hits;
  if (spec.beam_divergence > 0.0) footprintsAtEdges(spec, world, local, turns, origins, hits);
  if (spec.beam_divergence_vertical > 0.0) verticalFootprintsAtEdges(spec, world, local, turns, origins, centre, hits);
}

std::vector<LidarPoint> sweepPoints(const LidarSpec& spec, const std::vector<RayHit>& hits, RandomEngine& rng) {
  std::vector<LidarPoint> points;
  sweepPoints(spec, hits, rng, points);
  return points;
}

void sweepPoints(const LidarSpec& spec, const std::vector<RayHit>& hits, RandomEngine& rng, std::vector<LidarPoint>& points) {
  const int lasers = static_cast<int>(spec.vertical_deg.size());
  const int firings = firingsPerSweep(spec);
  if (hits.size() != static_cast<std::size_t>(firings * lasers))
    throw Error("LiDAR sweep: " + std::to_string(hits.size()) + " ray hits for a " + spec.name + " sweep of " + std::to_string(firings * lasers) + " rays");
  const double sweep = 1.0 / spec.rotation_hz;
  const std::shared_ptr<const Directions> table = localDirections(spec, firings);
  const std::vector<Eigen::Vector3f>& local = table->rounded;
  const bool dropouts = spec.dropout > 0.0 || spec.dropout_at_max_range > 0.0;
  // One draw of the drive's engine per sweep; each ray's draws are then its own (ray_noise.hpp).
  const RayNoise noise(rng());
  points.clear();
  points.reserve(hits.size());  // a sweep hits more than half its rays outdoors: no second allocation and copy
  for (int f = 0; f < firings; ++f) {
    const float time = static_cast<float>(sweep * f / firings);
    for (int l = 0; l < lasers; ++l) {
      const std::size_t i = static_cast<std::size_t>(f * lasers + l);
      if (hits[i].distance < 0.0f) continue;
      const double r = hits[i].distance;
      if (dropouts && noise.uniform(i) < spec.dropout + spec.dropout_at_max_range * (r / spec.max_range) * (r / spec.max_range)) continue;
      const double range = r + noise.normal(i) * (spec.range_noise + spec.range_noise_per_m * r);
      if (range < spec.min_range || range > spec.max_range) continue;
      points.push_back({static_cast<float>(range) * local[i], time, l, hits[i].mesh});
    }
  }
}

std::vector<LidarPoint> scanSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose, RandomEngine& rng) {
  return sweepPoints(spec, castSweep(spec, world, pose), rng);
}

}  // namespace coloc::sim
