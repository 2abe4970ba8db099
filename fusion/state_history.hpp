#pragma once
// The filter's memory of the last N ticks, which is what makes delay compensation exact.
//
// Autoware keeps N past states in one augmented state of dimension 6N and updates all of them with a
// rank-m downdate of a 6N x 6N covariance (O(N^2) per tick). coloc keeps, per tick, the predicted
// state and the updates applied at that tick. A measurement stamped k ticks ago is appended to that
// tick's updates and the ticks after it are filtered again (O(k), 6x6 matrices only). The newest
// state is then exactly what the filter would hold had the measurement arrived on time.
//
// With relinearize = false each replayed step reuses the linearisation made at its original
// prediction: x_k = f(x_lin) + A (x_{k-1} - x_lin). That is the linear-Gaussian problem Autoware's
// augmented filter solves, so both give the same newest state up to rounding.
#include <array>
#include <optional>
#include <vector>

#include "coloc/fusion/filter_state.hpp"
#include "measurement_update.hpp"
#include "motion_model.hpp"

namespace coloc::fusion {

struct HistoryOptions {
  int steps = 50;                       ///< ticks a measurement may lag and still be applied
  Duration step = 20'000'000;           ///< tick period, ns
  ProcessNoise noise;
  std::array<double, 3> aux_proc_dev{5.0, 0.1, 0.1};  ///< z, roll, pitch random walks
  bool relinearize = true;
  /// How the extra states wander (where the state models them); its bias_variance is the place's,
  /// set by setBiasVariance.
  ExtraNoise extra;
};

class StateHistory {
 public:
  explicit StateHistory(const HistoryOptions& options);

  /// Forgets everything and starts at `initial`, the state at `stamp`.
  void reset(Stamp stamp, const FilterState& initial);
  bool empty() const { return count_ == 0; }

  Stamp latestStamp() const { return latest_stamp_; }
  Stamp oldestStamp() const { return latest_stamp_ - static_cast<Duration>(count_ - 1) * options_.step; }
  int size() const { return count_; }
  const HistoryOptions& options() const { return options_; }

  /// Ticks back from the newest tick (0 = newest) of the tick nearest `stamp` (ties go to the newer
  /// tick); nullopt if that tick is older than the history or newer than the newest tick.
  std::optional<int> ticksBack(Stamp stamp) const;
  Stamp stampAt(int ticks_back) const { return latest_stamp_ - static_cast<Duration>(ticks_back) * options_.step; }

  /// Predicts one tick ahead.
  void advance();

  /// The filtered state at a past tick, with every update recorded so far.
  const FilterState& stateAt(int ticks_back);
  const FilterState& latest() { return stateAt(0); }

  /// Records an update at a past tick; applied when a state is next read. False (nothing recorded) if
  /// the update cannot be applied to that tick's state (innovation covariance not positive definite).
  bool addUpdate(int ticks_back, const UpdateRecord& record);

  /// The map-matching bias's stationary variance from now on (the place's); the steps of the history
  /// filtered again after a late measurement take it too, a second at most of travel.
  void setBiasVariance(double variance) { options_.extra.bias_variance = variance; }
  double biasVariance() const { return options_.extra.bias_variance; }

  /// The map-matching bias let in at a tick (ticks back) with its spread (m^2 per axis, 2x2): the
  /// position followed NDT's bias while nothing told it apart, so it is uncertain by that spread and
  /// the bias is its difference from the truth (position and bias covariance -spread). Kept with the
  /// tick, so the ticks filtered again after a late measurement take it too. Nothing where the bias is
  /// not modelled.
  void releaseBias(int ticks_back, const Eigen::Matrix2d& spread);

 private:
  struct Slot {
    FilterState prior;      ///< predicted from the previous tick (the base for the oldest slot)
    FilterState posterior;  ///< prior with `updates` applied in order
    std::vector<UpdateRecord> updates;
    Eigen::Matrix2d release = Eigen::Matrix2d::Zero();  ///< the bias let in at this tick (releaseBias)
    // The linearisation of the step into this slot, fixed when it was first predicted.
    Vector6d from_linearization = Vector6d::Zero();
    Vector6d predicted_from_linearization = Vector6d::Zero();
    Matrix6d jacobian = Matrix6d::Identity();
  };

  Slot& slot(int ticks_back) { return slots_[(head_ + slots_.size() - ticks_back) % slots_.size()]; }
  void predictInto(const FilterState& from, Slot& into, bool first_time) const;
  void refresh(int down_to);
  static void applyAll(Slot& s);
  static void applyRelease(FilterState& prior, const Eigen::Matrix2d& spread);

  HistoryOptions options_;
  double dt_;
  Matrix6d Q_;
  std::vector<Slot> slots_;
  std::size_t head_ = 0;
  int count_ = 0;
  Stamp latest_stamp_ = 0;
  int dirty_ = -1;  ///< oldest slot (ticks back) whose posterior is stale; -1 = none
};

}  // namespace coloc::fusion
