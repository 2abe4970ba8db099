#pragma once
// Where a pose source is accurate, judged on another drive than the one it is compared on.
// InputComparison's stretches are chosen by the compared drive's own error, and that choice favours the
// source by its luck there: a stretch whose few scans happened to fall well passes though the place is
// no better, most at speed (at 15 m/s a 10 m stretch holds 6-7 scans, at 5 m/s 20). Places chosen on a
// reference drive over the same road (the experiment's noise calibration drive) carry no luck of the
// drive compared: the same criterion, the mean planar error over a place, measured independently.
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "coloc/replay/evaluation.hpp"

namespace coloc::replay {

class AccuratePlaces {
 public:
  /// Poses a cell needs to be judged: half a 10 m stretch's at 10 m/s and 10 Hz.
  static constexpr std::size_t kMinPoses = 5;

  /// No place: nothing is accurate.
  AccuratePlaces() = default;

  /// Square cells of `cell` m by true position where the reference drive's `errors` (a source's
  /// poses against ground truth) average below `below` m over at least `min_samples` poses. Samples
  /// that are not finite are left out. Throws coloc::Error naming `cell` or `below` unless each is
  /// finite and > 0.
  static AccuratePlaces fromErrors(const std::vector<ErrorSample>& errors, double cell, double below, std::size_t min_samples);

  /// Each source's places from the `input_error.csv` that `coloc fuse` wrote for a reference drive
  /// (ReplayResult::writeInputErrorCsv; its columns source, truth_x, truth_y and error_m). Throws
  /// coloc::Error naming the file (and its line and column) if it cannot be read, lacks a column, has a
  /// row of another width or holds a field that is not a finite number (or an error_m below 0).
  static std::map<std::string, AccuratePlaces> fromInputErrorCsv(const std::string& path, double cell, double below,
                                                                 std::size_t min_samples = kMinPoses);

  /// Whether the true position `xy` lies in an accurate place.
  bool contains(const Eigen::Vector2d& xy) const;
  std::size_t accurate() const;          ///< cells found accurate
  std::size_t judged() const { return judged_.size(); }  ///< cells with enough poses to judge
  double cellSize() const { return cell_; }
  double below() const { return below_; }

 private:
  using Key = std::pair<long long, long long>;
  Key keyOf(const Eigen::Vector2d& xy) const;
  double cell_ = 10.0, below_ = 0.0;
  std::map<Key, bool> judged_;  ///< each cell judged: accurate or not
};

}  // namespace coloc::replay
