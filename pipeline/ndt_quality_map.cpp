#include "coloc/pipeline/ndt_quality_map.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/core/yaml_reader.hpp"

namespace coloc::pipeline {

namespace {
// Cells of 1-1000 m over maps of up to +-1e9 m: their indices fit in a long long with room to spare.
constexpr double kMinCell = 1.0, kMaxCell = 1000.0, kMaxVariance = 1e6, kMaxCoordinate = 1e9;
}  // namespace

std::pair<long long, long long> NdtQualityMap::indexOf(const Eigen::Vector2d& xy) const {
  return {static_cast<long long>(std::floor(xy.x() / cell_)), static_cast<long long>(std::floor(xy.y() / cell_))};
}

std::vector<bool> NdtQualityMap::grossErrors(const std::vector<NdtQualitySample>& samples, double cell) {
  if (!(cell >= kMinCell && cell <= kMaxCell)) throw Error("NDT quality map: the cell must be " + std::to_string(kMinCell) + "-" + std::to_string(kMaxCell) + " m");
  NdtQualityMap map;
  map.cell_ = cell;
  std::map<std::pair<long long, long long>, std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const NdtQualitySample& s = samples[i];
    if (!s.position.allFinite() || !s.error.allFinite() || s.position.cwiseAbs().maxCoeff() > kMaxCoordinate)
      throw Error("NDT quality map: sample " + std::to_string(i) + " is not finite or lies beyond 1e9 m");
    members[map.indexOf(s.position)].push_back(i);
  }
  std::vector<bool> gross(samples.size(), false);
  std::vector<double> errors;
  for (const auto& [index, in] : members) {
    if (in.size() < 3) continue;  // no median to speak of
    errors.clear();
    for (std::size_t i : in) errors.push_back(samples[i].error.norm());
    std::sort(errors.begin(), errors.end());
    const std::size_t n = errors.size();
    const double median = n % 2 ? errors[n / 2] : 0.5 * (errors[n / 2 - 1] + errors[n / 2]);
    for (std::size_t i : in) gross[i] = samples[i].error.norm() > kGrossError * median;
  }
  return gross;
}

NdtQualityMap NdtQualityMap::fromErrors(const std::vector<NdtQualitySample>& samples, double cell, std::size_t min_samples,
                                        std::optional<double> default_variance) {
  if (!(cell >= kMinCell && cell <= kMaxCell)) throw Error("NDT quality map: the cell must be " + std::to_string(kMinCell) + "-" + std::to_string(kMaxCell) + " m");
  if (default_variance && !(*default_variance >= 0.0 && *default_variance <= kMaxVariance))
    throw Error("NDT quality map: the default variance must be a finite number of m^2 >= 0");
  const std::vector<bool> gross = grossErrors(samples, cell);
  NdtQualityMap map;
  map.cell_ = cell;
  map.gross_left_out_ = static_cast<std::size_t>(std::count(gross.begin(), gross.end(), true));
  struct Sums {
    double square = 0.0;
    std::size_t poses = 0, pairs = 0, turned = 0, yawed = 0;
    Eigen::Vector2d error = Eigen::Vector2d::Zero(), along_across = Eigen::Vector2d::Zero();
    double yaw = 0.0, yaw_error = 0.0;
  };
  std::map<std::pair<long long, long long>, Sums> sums;
  double change = 0.0, all = 0.0, change_yaw = 0.0;  // all: the drive's own sum, for the default
  std::size_t changes = 0, poses = 0, turned = 0, yawed = 0;
  Eigen::Vector2d change_along_across = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const NdtQualitySample& s = samples[i];
    if (gross[i]) continue;
    Sums& sum = sums[map.indexOf(s.position)];
    sum.square += 0.5 * s.error.squaredNorm();  // x and y pooled
    ++sum.poses;
    all += 0.5 * s.error.squaredNorm(), ++poses;
    if (std::isfinite(s.heading)) {
      const Eigen::Vector2d body = Eigen::Rotation2Dd(-s.heading) * s.error;
      sum.error += body.cwiseProduct(body);
      ++sum.turned;
    }
    if (std::isfinite(s.yaw_error)) {
      const double off = std::remainder(s.yaw_error, 2.0 * M_PI);
      sum.yaw_error += off * off;
      ++sum.yawed;
    }
    // Two independent draws of the noise differ by twice its variance, per axis; x and y pooled.
    const NdtQualitySample* before = i > 0 && !gross[i - 1] ? &samples[i - 1] : nullptr;
    if (!before || (s.position - before->position).norm() >= cell) continue;
    const Eigen::Vector2d d = s.error - before->error;
    change += 0.25 * d.squaredNorm();
    ++changes;
    Eigen::Vector2d body = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (std::isfinite(s.heading)) {
      body = Eigen::Rotation2Dd(-s.heading) * d;  // along, across
      change_along_across += 0.5 * body.cwiseProduct(body);
      ++turned;
    }
    const double turn = std::remainder(s.yaw_error - before->yaw_error, 2.0 * M_PI);
    if (std::isfinite(turn)) change_yaw += 0.5 * turn * turn, ++yawed;
    // The cell where the pair ends counts it, where it measures all three.
    if (body.allFinite() && std::isfinite(turn)) {
      sum.along_across += 0.5 * body.cwiseProduct(body);
      sum.yaw += 0.5 * turn * turn;
      ++sum.pairs;
    }
  }
  if (changes > 0) map.noise_variance_ = std::min(change / static_cast<double>(changes), kMaxVariance);
  if (turned > 0) map.noise_along_across_ = (change_along_across / static_cast<double>(turned)).cwiseMin(kMaxVariance);
  if (yawed > 0) map.noise_yaw_ = std::min(change_yaw / static_cast<double>(yawed), kMaxVariance);
  map.default_variance_ = default_variance ? *default_variance : poses ? std::min(all / static_cast<double>(poses), kMaxVariance) : 0.0;
  for (const auto& [index, sum] : sums) {
    if (sum.poses < std::max<std::size_t>(min_samples, 1)) continue;
    Cell c{sum.square / static_cast<double>(sum.poses), sum.poses};
    if (sum.pairs > 0 && sum.turned > 0 && sum.yawed > 0) {
      const double n = static_cast<double>(sum.pairs);
      c.pairs = sum.pairs;
      c.error_along_across = (sum.error / static_cast<double>(sum.turned)).cwiseMin(kMaxVariance);
      c.error_yaw = std::min(sum.yaw_error / static_cast<double>(sum.yawed), kMaxVariance);
      c.noise_along_across = (sum.along_across / n).cwiseMin(kMaxVariance);
      c.noise_yaw = std::min(sum.yaw / n, kMaxVariance);
    }
    map.cells_[index] = c;
  }
  map.setNoisePrior();
  return map;
}

namespace {
// Variances along and across a vehicle heading `heading` (rad), as an x/y covariance in the map.
Eigen::Matrix2d turnedToMap(const Eigen::Vector2d& along_across, double heading) {
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(heading).toRotationMatrix();  // the vehicle's axes in the map
  return turn * along_across.asDiagonal() * turn.transpose();
}
}  // namespace

std::optional<Eigen::Matrix2d> NdtQualityMap::noiseAt(double heading) const {
  if (!noise_along_across_ || !std::isfinite(heading)) return std::nullopt;
  return turnedToMap(*noise_along_across_, heading);
}

void NdtQualityMap::setNoisePrior() {
  std::vector<double> along, across, yaw;
  for (const auto& [index, c] : cells_)
    if (c.pairs > 0) along.push_back(c.noise_along_across.x()), across.push_back(c.noise_along_across.y()), yaw.push_back(c.noise_yaw);
  const auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  if (!along.empty()) noise_prior_ = Eigen::Vector3d(median(along), median(across), median(yaw));
  else noise_prior_ = Eigen::Vector3d(noise_along_across_ ? noise_along_across_->x() : 0.0, noise_along_across_ ? noise_along_across_->y() : 0.0, noise_yaw_.value_or(0.0));
}

const NdtQualityMap::Cell* NdtQualityMap::cellAt(const Eigen::Vector2d& xy) const {
  if (cells_.empty() || !xy.allFinite() || xy.cwiseAbs().maxCoeff() > kMaxCoordinate) return nullptr;
  const auto found = cells_.find(indexOf(xy));
  return found == cells_.end() ? nullptr : &found->second;
}

std::optional<Eigen::Matrix2d> NdtQualityMap::noiseAt(const Eigen::Vector2d& xy, double heading) const {
  if (!noise_along_across_ || !std::isfinite(heading)) return std::nullopt;
  Eigen::Vector2d along_across = *noise_along_across_;
  if (const Cell* c = cellAt(xy); c && c->pairs > 0) {
    const double n = static_cast<double>(c->pairs);
    along_across = (n * c->noise_along_across + kNoisePriorPairs * noise_prior_.head<2>()) / (n + kNoisePriorPairs);
  }
  return turnedToMap(along_across, heading);
}

std::optional<Eigen::Matrix2d> NdtQualityMap::errorAt(const Eigen::Vector2d& xy, double heading) const {
  const Cell* c = cellAt(xy);
  if (!c || c->pairs == 0 || !std::isfinite(heading)) return std::nullopt;
  return turnedToMap(c->error_along_across, heading);
}

std::optional<double> NdtQualityMap::yawErrorAt(const Eigen::Vector2d& xy) const {
  const Cell* c = cellAt(xy);
  if (!c || c->pairs == 0) return std::nullopt;
  return c->error_yaw;
}

std::optional<double> NdtQualityMap::yawNoiseAt(const Eigen::Vector2d& xy) const {
  if (!noise_yaw_) return std::nullopt;
  const Cell* c = cellAt(xy);
  if (!c || c->pairs == 0) return noise_yaw_;
  const double n = static_cast<double>(c->pairs);
  return (n * c->noise_yaw + kNoisePriorPairs * noise_prior_.z()) / (n + kNoisePriorPairs);
}

double NdtQualityMap::varianceAt(const Eigen::Vector2d& xy) const {
  const Cell* c = cellAt(xy);
  return c ? c->variance : default_variance_;
}

std::string NdtQualityMap::toYaml() const {
  std::ostringstream out;
  out << std::setprecision(17);
  out << "# coloc NDT quality map: NDT's mean square x/y error (m^2) per cell of the map, from a drive with a reference.\n"
      << "# Each NDT pose's x/y variance is held at least at its cell's (ndt.quality_map).\n"
      << "cell: " << cell_ << "  # m; cell [i, j] spans x in [i, i + 1) * cell, y in [j, j + 1) * cell\n"
      << "default_variance: " << default_variance_ << "  # m^2, where no cell is listed\n"
      << "noise_variance: " << noise_variance_ << "  # m^2 per axis: NDT's scan-to-scan noise (half the mean square change between consecutive poses)\n";
  if (noise_along_across_)
    out << "noise_along: " << noise_along_across_->x() << "  # m^2: the same along the vehicle\n"
        << "noise_across: " << noise_along_across_->y() << "  # m^2: and across it\n";
  if (noise_yaw_) out << "noise_yaw: " << *noise_yaw_ << "  # rad^2: NDT's scan-to-scan yaw noise\n";
  if (gross_left_out_ > 0)
    out << "# " << gross_left_out_ << " pose(s) left out as gross errors (over " << kGrossError << "x their cell's median error): the travel check's to catch, not the place's\n";
  out
      << "cells:  # [i, j, poses, variance] or, where consecutive poses measured its noise, [..., error_along, error_across, error_yaw, pairs, noise_along, noise_across, noise_yaw]\n";
  if (cells_.empty()) out << "  []\n";
  for (const auto& [index, c] : cells_) {
    out << "  - [" << index.first << ", " << index.second << ", " << c.samples << ", " << c.variance;
    if (c.pairs > 0) out << ", " << c.error_along_across.x() << ", " << c.error_along_across.y() << ", " << c.error_yaw << ", " << c.pairs << ", " << c.noise_along_across.x() << ", " << c.noise_along_across.y() << ", " << c.noise_yaw;
    out << "]\n";
  }
  return out.str();
}

NdtQualityMap NdtQualityMap::parse(const std::string& text, const std::string& source) {
  const YamlReader r(source);
  const YAML::Node root = r.parse(text);
  if (!root.IsMap()) r.fail(root, "(top level)", "expected a mapping with cell, default_variance and cells");
  r.allowKeys(root, "(top level)", {"cell", "default_variance", "noise_variance", "noise_along", "noise_across", "noise_yaw", "cells"});
  NdtQualityMap map;
  map.cell_ = r.inRange(r.require(root, "cell", "(top level)"), "cell", kMinCell, kMaxCell);
  map.default_variance_ = r.inRange(r.require(root, "default_variance", "(top level)"), "default_variance", 0.0, kMaxVariance);
  if (const YAML::Node noise = root["noise_variance"]) map.noise_variance_ = r.inRange(noise, "noise_variance", 0.0, kMaxVariance);
  const YAML::Node along = root["noise_along"], across = root["noise_across"];
  if (along || across) {
    if (!along) r.fail(across, "noise_across", "given without noise_along");
    if (!across) r.fail(along, "noise_along", "given without noise_across");
    map.noise_along_across_ = Eigen::Vector2d(r.inRange(along, "noise_along", 0.0, kMaxVariance), r.inRange(across, "noise_across", 0.0, kMaxVariance));
  }
  if (const YAML::Node yaw = root["noise_yaw"]) map.noise_yaw_ = r.inRange(yaw, "noise_yaw", 0.0, kMaxVariance);
  const YAML::Node cells = r.require(root, "cells", "(top level)");
  if (!cells.IsSequence()) r.fail(cells, "cells", "expected a list of [i, j, poses, variance]");
  const long long reach = static_cast<long long>(kMaxCoordinate / map.cell_) + 1;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const std::string key = "cells[" + std::to_string(i) + "]";
    const std::size_t entries = cells[i].IsSequence() && cells[i].size() == 11 ? 11 : 4;
    const std::vector<double> v = r.numbers(cells[i], key, entries,
                                            entries == 11 ? "[i, j, poses, variance, error_along, error_across, error_yaw, pairs, noise_along, noise_across, noise_yaw]"
                                                          : "[i, j, poses, variance]");
    for (int k = 0; k < 3; ++k)
      if (!(std::isfinite(v[k]) && v[k] == std::floor(v[k]) && std::abs(v[k]) <= static_cast<double>(reach)))
        r.fail(cells[i], key, "i, j and poses must be whole numbers, i and j within the map's reach (1e9 m)");
    if (v[2] < 1.0) r.fail(cells[i], key, "a cell holds at least one pose");
    if (!(v[3] >= 0.0 && v[3] <= kMaxVariance)) r.fail(cells[i], key, "the variance must be a finite number of m^2 >= 0");
    Cell c{v[3], static_cast<std::size_t>(v[2])};
    if (entries == 11) {
      if (!map.noise_along_across_ || !map.noise_yaw_) r.fail(cells[i], key, "a cell's noise needs the map's noise_along, noise_across and noise_yaw");
      if (!(v[7] >= 1.0 && v[7] == std::floor(v[7]) && v[7] <= v[2])) r.fail(cells[i], key, "pairs must be a whole number from 1 to the cell's poses");
      for (int k : {4, 5, 6, 8, 9, 10})
        if (!(v[k] >= 0.0 && v[k] <= kMaxVariance)) r.fail(cells[i], key, "the error and noise figures must be finite numbers >= 0");
      c.error_along_across = Eigen::Vector2d(v[4], v[5]);
      c.error_yaw = v[6];
      c.pairs = static_cast<std::size_t>(v[7]);
      c.noise_along_across = Eigen::Vector2d(v[8], v[9]);
      c.noise_yaw = v[10];
    }
    const std::pair<long long, long long> index{static_cast<long long>(v[0]), static_cast<long long>(v[1])};
    if (!map.cells_.emplace(index, c).second) r.fail(cells[i], key, "the cell appears twice");
  }
  map.setNoisePrior();
  return map;
}

NdtQualityMap NdtQualityMap::load(const std::string& path) { return parse(YamlReader::readFile(path, "NDT quality map"), path); }

}  // namespace coloc::pipeline
