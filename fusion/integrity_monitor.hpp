#pragma once
// The filter's integrity from what its sources say at each pose's first use (applied or gated, and by
// how much), and from how long it has gone on the twist alone. The Localizer feeds it; see
// coloc/fusion/integrity.hpp for the states.
#include <deque>
#include <string>

#include "coloc/core/types.hpp"
#include "coloc/fusion/ekf_config.hpp"
#include "coloc/fusion/integrity.hpp"

namespace coloc::fusion {

class IntegrityMonitor {
 public:
  explicit IntegrityMonitor(const EkfConfig& config);

  /// The filter (re)started at `stamp` (localized), or was reset (initialising).
  void restart(Stamp stamp, bool initialized);
  /// A pose's first use. `innovation`: measured minus predicted x and y (NaN where not measured);
  /// `gated_in_a_row`: the source's poses gated in a row, this one included (the Localizer keeps it).
  void onPose(const std::string& source, bool anchor, bool applied, const Eigen::Vector2d& innovation, double d2, int gated_in_a_row,
              Stamp now);
  /// Another part of the system doubts the estimate by `offset` (x, y): degraded, its reported
  /// covariance covering the offset, until an anchor agrees with it (or the filter starts again).
  void doubt(const std::string& reason, const Eigen::Vector2d& offset, Stamp now);
  /// The same with the places it might be instead given as `spread`, added to the reported x/y
  /// covariance (the sum of each place's offset times itself covers every one of them within 1 sd).
  void doubt(const std::string& reason, const Eigen::Matrix2d& spread, Stamp now);
  /// The part that doubted vouches for the position after all: a doubt that nothing else has
  /// overtaken ends (localized again).
  void confirm(Stamp now);
  /// The filter's clock advanced to `now`.
  void onTick(Stamp now);

  const IntegrityStatus& status() const { return status_; }
  /// What the reported x/y covariance must add to cover the anchors' disagreement (zero when localized).
  const Eigen::Matrix2d& inflation() const { return inflation_; }

 private:
  enum class Cause { kNone, kAnchor, kAnchorWindow, kGated, kDeadReckoning, kDoubt };
  void enter(LocalizationState state, Cause cause, std::string reason, Stamp now);
  /// An applied anchor pose: the window's poses far off on average, telling one story, make the filter
  /// lost (a metre or more) or degraded; back under the limit, localized again.
  void onAnchorApplied(const std::string& source, const Eigen::Vector2d& innovation, double d2, Stamp now);

  EkfConfig config_;
  IntegrityStatus status_;
  Cause cause_ = Cause::kNone;
  Eigen::Matrix2d inflation_ = Eigen::Matrix2d::Zero();
  // Anchors: the gated run, and the disagreement it tells.
  int anchor_gated_in_a_row_ = 0;
  Eigen::Vector2d anchor_disagreement_ = Eigen::Vector2d::Zero();
  Stamp anchor_gated_at_ = 0;
  struct AnchorUse {
    Stamp at;
    Eigen::Vector2d innovation;
    double d2;
  };
  std::deque<AnchorUse> anchor_window_;  ///< the last anchor poses applied, for their mean disagreement
  std::string gated_source_;
  /// While the position is doubted (status_.doubted), an anchor's disagreement of any size means
  /// lost, since the map no longer vouches for it.
  double lostDistance() const { return status_.doubted ? 0.0 : config_.integrity_lost_min_distance; }  ///< the other source whose gated run degraded the filter
  Stamp last_applied_ = 0;
};

}  // namespace coloc::fusion
