#include "state_history.hpp"

#include <stdexcept>

namespace coloc::fusion {

StateHistory::StateHistory(const HistoryOptions& options)
    : options_(options),
      dt_(toSeconds(options.step)),
      Q_(processNoise(options.noise, toSeconds(options.step))),
      slots_(static_cast<std::size_t>(options.steps) + 1) {
  if (options.steps < 0) throw std::invalid_argument("history steps must be >= 0");
  if (options.step <= 0) throw std::invalid_argument("history tick period must be > 0");
  for (Slot& s : slots_) s.updates.reserve(16);
}

void StateHistory::reset(Stamp stamp, const FilterState& initial) {
  head_ = 0;
  count_ = 1;
  latest_stamp_ = stamp;
  dirty_ = -1;
  Slot& s = slots_[0];
  s.prior = s.posterior = initial;
  s.updates.clear();
  s.release.setZero();
}

std::optional<int> StateHistory::ticksBack(Stamp stamp) const {
  if (count_ == 0) return std::nullopt;
  // Nearest tick to the stamp; a stamp exactly half-way goes to the newer tick.
  const Duration numerator = latest_stamp_ - stamp + options_.step / 2 - 1;
  Duration back = numerator / options_.step;
  if (numerator % options_.step != 0 && numerator < 0) --back;  // floor division
  if (back < 0 || back >= count_) return std::nullopt;
  return static_cast<int>(back);
}

void StateHistory::predictInto(const FilterState& from, Slot& into, bool first_time) const {
  FilterState& prior = into.prior;
  Matrix6d A_used;
  if (options_.relinearize || first_time) {
    Matrix6d& A = A_used;
    prior.x = predictState(from.x, dt_, A);
    prior.P = propagateCovariance(A, from.P, Q_);
    if (!options_.relinearize) {
      into.from_linearization = from.x;
      into.predicted_from_linearization = prior.x;
      into.jacobian = A;
    }
  } else {
    Vector6d delta = from.x - into.from_linearization;
    delta[kYaw] = wrapAngle(delta[kYaw]);
    prior.x = into.predicted_from_linearization + into.jacobian * delta;
    prior.P = propagateCovariance(into.jacobian, from.P, Q_);
  }
  prior.extra = from.extra;
  if (prior.extra.any()) propagateExtra(prior.extra, options_.relinearize || first_time ? A_used : into.jacobian, from.x[kVx], dt_, options_.extra);
  prior.aux = from.aux;
  predictAux(prior, options_.aux_proc_dev, dt_);
}

void StateHistory::applyRelease(FilterState& prior, const Eigen::Matrix2d& spread) {
  if (!prior.extra.bias_modelled || spread.isZero(0.0)) return;
  prior.P.topLeftCorner<2, 2>() += spread;
  prior.extra.P.topLeftCorner<2, 2>() += spread;
  prior.extra.cross.topLeftCorner<2, 2>() -= spread;  // rows x, y; columns the bias's x, y
}

void StateHistory::releaseBias(int ticks_back, const Eigen::Matrix2d& spread) {
  if (ticks_back < 0 || ticks_back >= count_) throw std::out_of_range("bias release outside the state history");
  refresh(ticks_back);
  Slot& s = slot(ticks_back);
  s.release += spread;
  applyRelease(s.prior, spread);
  applyAll(s);
  if (ticks_back > 0 && ticks_back - 1 > dirty_) dirty_ = ticks_back - 1;
}

void StateHistory::applyAll(Slot& s) {
  s.posterior = s.prior;
  for (const UpdateRecord& r : s.updates) applyUpdate(s.posterior, r);
}

void StateHistory::refresh(int down_to) {
  // dirty_ is the oldest tick whose prior is stale because the tick before it changed.
  for (; dirty_ >= down_to; --dirty_) {
    Slot& s = slot(dirty_);
    predictInto(slot(dirty_ + 1).posterior, s, false);
    applyRelease(s.prior, s.release);
    applyAll(s);
  }
}

void StateHistory::advance() {
  if (count_ == 0) throw std::logic_error("StateHistory::advance before reset");
  refresh(0);
  const std::size_t next = (head_ + 1) % slots_.size();
  Slot& s = slots_[next];
  s.updates.clear();
  s.release.setZero();
  predictInto(slots_[head_].posterior, s, true);
  s.posterior = s.prior;
  head_ = next;
  latest_stamp_ += options_.step;
  if (count_ < static_cast<int>(slots_.size())) ++count_;
}

const FilterState& StateHistory::stateAt(int ticks_back) {
  refresh(ticks_back);
  return slot(ticks_back).posterior;
}

bool StateHistory::addUpdate(int ticks_back, const UpdateRecord& record) {
  if (ticks_back < 0 || ticks_back >= count_) throw std::out_of_range("update outside the state history");
  refresh(ticks_back);
  Slot& s = slot(ticks_back);
  FilterState trial = s.posterior;
  if (!applyUpdate(trial, record)) return false;
  s.updates.push_back(record);
  // The slot's own posterior is already right; only the ticks after it need filtering again.
  s.posterior = trial;
  if (ticks_back > 0 && ticks_back - 1 > dirty_) dirty_ = ticks_back - 1;
  return true;
}

}  // namespace coloc::fusion
