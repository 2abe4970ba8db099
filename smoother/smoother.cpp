#include "coloc/smoother/smoother.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "coloc/core/chi_square.hpp"
#include "coloc/core/error.hpp"
#include "marginals.hpp"
#include "residuals.hpp"

namespace coloc::smoother {

namespace {

using namespace residuals;

struct StoredPose {
  std::string source;
  Stamp stamp;
  int m;
  int component[3];
  double value[3];
  Eigen::Matrix3d whitening;
};

struct StoredTwist {
  std::string source;
  Stamp stamp;
  int m;
  int component[2];
  double value[2];
  Eigen::Matrix2d whitening;
};

const char* terminationName(ceres::TerminationType t) {
  switch (t) {
    case ceres::CONVERGENCE: return "CONVERGENCE";
    case ceres::NO_CONVERGENCE: return "NO_CONVERGENCE";
    case ceres::FAILURE: return "FAILURE";
    case ceres::USER_SUCCESS: return "USER_SUCCESS";
    case ceres::USER_FAILURE: return "USER_FAILURE";
  }
  return "?";
}

}  // namespace

struct CalibratedRsu {
  std::string source;
  Eigen::Vector2d position;
  bool clock;
};

struct StoredPrior {
  Stamp stamp;
  StatePrior prior;
};

struct Smoother::Impl {
  SmootherOptions options;
  std::vector<StoredPrior> priors;
  std::vector<CalibratedRsu> calibrated;
  std::vector<StoredPose> poses;
  std::vector<StoredTwist> twists;
  std::map<Stamp, Vector6d> guesses;
  std::set<std::string> biased;  ///< pose sources whose positions carry the shared slowly varying error

  // The guess at a stamp: linear between the neighbouring guesses (yaw along the short way round).
  Vector6d guessAt(Stamp t) const {
    auto after = guesses.lower_bound(t);
    if (after == guesses.end()) return std::prev(after)->second;
    if (after == guesses.begin() || after->first == t) return after->second;
    const auto before = std::prev(after);
    const double w = static_cast<double>(t - before->first) / static_cast<double>(after->first - before->first);
    Vector6d g = (1.0 - w) * before->second + w * after->second;
    g[2] = wrapAngle(before->second[2] + w * wrapAngle(after->second[2] - before->second[2]));
    return g;
  }
};

Smoother::Smoother(SmootherOptions options) : impl_(std::make_unique<Impl>()) {
  // The motion is weighed by the inverse of each process noise: refused when given, not at a solve.
  const auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0))
      throw Error(std::string("smoother: ") + name + " must be finite and > 0 (the motion is weighed by its inverse; a zero one is an infinite weight)");
  };
  positive(options.proc_stddev_yaw_c, "proc_stddev_yaw_c");
  positive(options.proc_stddev_vx_c, "proc_stddev_vx_c");
  positive(options.proc_stddev_wz_c, "proc_stddev_wz_c");
  positive(options.proc_stddev_position_c, "proc_stddev_position_c");
  positive(options.proc_stddev_yaw_bias_c, "proc_stddev_yaw_bias_c");
  impl_->options = options;
}
Smoother::~Smoother() = default;
Smoother::Smoother(Smoother&&) noexcept = default;
Smoother& Smoother::operator=(Smoother&&) noexcept = default;

namespace {

// The measured ones among `count` components (ROS 6x6 indices `index`, values `values`): a finite
// positive variance and a finite value; +inf leaves a component out. A NaN or negative variance, or a
// block that is not positive definite, refuses the whole measurement (nullopt), as the filter does.
struct Measured {
  int m = 0;
  int which[3];  ///< positions in `index` of the measured components
  Eigen::Matrix3d whitening = Eigen::Matrix3d::Zero();  ///< L^-1 of their covariance, upper-left m x m
};

std::optional<Measured> measured(const Matrix6d& covariance, const int* index, const double* values, int count) {
  Measured out;
  for (int k = 0; k < count; ++k) {
    const double v = covariance(index[k], index[k]);
    if (std::isnan(v) || v < 0.0) return std::nullopt;
    if (std::isfinite(v) && v > 0.0 && std::isfinite(values[k])) out.which[out.m++] = k;
  }
  if (out.m == 0) return std::nullopt;
  Eigen::MatrixXd block(out.m, out.m);
  for (int i = 0; i < out.m; ++i)
    for (int j = 0; j < out.m; ++j) block(i, j) = covariance(index[out.which[i]], index[out.which[j]]);
  const Eigen::LLT<Eigen::MatrixXd> llt(block);
  if (!block.allFinite() || llt.info() != Eigen::Success) return std::nullopt;
  out.whitening.topLeftCorner(out.m, out.m) = llt.matrixL().solve(Eigen::MatrixXd::Identity(out.m, out.m));
  return out;
}

}  // namespace

bool Smoother::addPose(const std::string& source, const PoseMeasurement& measurement) {
  const int index[3] = {0, 1, 5};  // x, y, yaw in the ROS 6x6 order
  const double values[3] = {measurement.pose.position.x(), measurement.pose.position.y(), rollPitchYaw(measurement.pose.orientation)[2]};
  const std::optional<Measured> got = measured(measurement.covariance, index, values, 3);
  if (!got) return false;
  StoredPose p;
  p.source = source;
  p.stamp = measurement.stamp;
  p.m = got->m;
  for (int j = 0; j < p.m; ++j) p.component[j] = got->which[j], p.value[j] = values[got->which[j]];
  p.whitening = got->whitening;
  impl_->poses.push_back(p);
  return true;
}

bool Smoother::addTwist(const std::string& source, const TwistMeasurement& measurement) {
  const int index[2] = {0, 5};  // vx, wz
  const double values[2] = {measurement.linear.x(), measurement.angular.z()};
  const std::optional<Measured> got = measured(measurement.covariance, index, values, 2);
  if (!got) return false;
  StoredTwist t;
  t.source = source;
  t.stamp = measurement.stamp;
  t.m = got->m;
  for (int j = 0; j < t.m; ++j) t.component[j] = got->which[j] == 0 ? 4 : 5, t.value[j] = values[got->which[j]];
  t.whitening = got->whitening.topLeftCorner<2, 2>();
  impl_->twists.push_back(t);
  return true;
}

void Smoother::setPoseBias(const std::string& source) { impl_->biased.insert(source); }

void Smoother::calibrateRsu(const std::string& source, const Eigen::Vector2d& surveyed_position, bool clock) {
  impl_->calibrated.push_back({source, surveyed_position, clock});
}

bool Smoother::addPrior(Stamp stamp, const Vector6d& state, const Matrix6d& covariance) {
  if (!state.allFinite() || !covariance.allFinite()) return false;
  const Eigen::LLT<Matrix6d> llt(0.5 * (covariance + covariance.transpose()));
  if (llt.info() != Eigen::Success) return false;
  impl_->priors.push_back({stamp, {state, llt.matrixL().solve(Matrix6d::Identity())}});
  return true;
}

void Smoother::addGuess(Stamp stamp, const Vector6d& state) {
  if (state.allFinite()) impl_->guesses[stamp] = state;
}

SmootherResult Smoother::solve(Stamp first, Stamp last) const {
  std::vector<bool> clock(impl_->calibrated.size());
  for (std::size_t i = 0; i < clock.size(); ++i) clock[i] = impl_->calibrated[i].clock;
  SmootherResult result = solveWith(first, last, clock);
  // A drive at one speed along a straight road cannot tell an RSU's clock offset from an along-road
  // survey offset (both move its fixes along the road alike). Then the rest is still determined: the
  // clock is held at 0 and the survey offset absorbs its effect, which holds for drives at that speed.
  bool retry = false;
  for (std::size_t i = 0; i < clock.size(); ++i)
    if (clock[i] && !result.calibrations[i].observable && result.calibrations[i].fixes > 0) clock[i] = false, retry = true;
  if (!retry) return result;
  SmootherResult held = solveWith(first, last, clock);
  if (!held.summary.usable()) return result;
  for (std::size_t i = 0; i < clock.size(); ++i) {
    if (clock[i] || !impl_->calibrated[i].clock) continue;
    RsuCalibration& c = held.calibrations[i];
    c.clock_observable = false;
    if (c.observable)
      c.note = "the clock offset is not separable from the survey offset along the road on this drive (one speed, a straight road): held at 0, "
               "its effect absorbed by the survey offset, which holds for drives at this speed";
  }
  return held;
}

SmootherResult Smoother::solveWith(Stamp first, Stamp last, const std::vector<bool>& clock) const {
  const SmootherOptions& o = impl_->options;
  if (impl_->guesses.empty()) throw Error("smoother: no first guess of the states (addGuess)");
  if (last <= first) throw Error("smoother: the span to smooth is empty");
  const Duration step = static_cast<Duration>(std::llround(1e9 / o.rate));
  const std::size_t n = static_cast<std::size_t>((last - first) / step) + 1;
  SmootherResult result;
  result.states.resize(n);
  std::vector<std::array<double, kState>> x(n);
  for (std::size_t k = 0; k < n; ++k) {
    result.states[k].stamp = first + static_cast<Stamp>(k) * step;
    const Vector6d g = impl_->guessAt(result.states[k].stamp);
    x[k].fill(0.0);
    for (int i = 0; i < 6; ++i) x[k][static_cast<std::size_t>(i)] = g[i];
  }
  auto blockOf = [&](std::size_t k) { return x[k].data(); };

  ceres::Problem problem;
  const double dt = toSeconds(step);
  Vector6d inverse_sigma;
  inverse_sigma << 1.0 / (o.proc_stddev_position_c * dt), 1.0 / (o.proc_stddev_position_c * dt), 1.0 / (o.proc_stddev_yaw_c * dt),
      1.0 / (o.proc_stddev_yaw_bias_c * dt), 1.0 / (o.proc_stddev_vx_c * dt), 1.0 / (o.proc_stddev_wz_c * dt);
  for (std::size_t k = 0; k + 1 < n; ++k)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<MotionResidual, 6, kState, kState>(new MotionResidual{dt, o.trapezoid, inverse_sigma}), nullptr,
                             blockOf(k), blockOf(k + 1));
  // A state prior (a window's start) replaces the weak pull of the yaw bias to zero.
  bool prior_at_start = false;
  for (const StoredPrior& p : impl_->priors) {
    if (p.stamp < first || p.stamp > last) continue;
    const std::size_t k = std::min(n - 1, static_cast<std::size_t>((p.stamp - first) / step));
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<StatePrior, 6, kState>(new StatePrior(p.prior)), nullptr, blockOf(k));
    prior_at_start = prior_at_start || k == 0;
  }
  if (!prior_at_start)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<YawBiasPrior, 1, kState>(new YawBiasPrior{1.0 / std::sqrt(o.initial_yaw_bias_variance)}),
                             nullptr, blockOf(0));

  struct Added {
    ceres::ResidualBlockId id;
    const std::string* source;
    Stamp stamp;
    double threshold;  ///< squared whitened norm where the loss starts to down-weight
    int rsu = -1;      ///< the calibrated RSU whose fix it is
    ceres::LossFunctionWrapper* loss = nullptr;
    bool gated = true;  ///< false: a process model's residual, never left out
  };
  std::vector<Added> added;
  // One block per calibrated RSU, (dx, dy, dyaw, clock offset) starting at 0; without a clock, the
  // offset is held at 0.
  std::vector<std::array<double, 4>> calibration(impl_->calibrated.size(), std::array<double, 4>{0.0, 0.0, 0.0, 0.0});
  std::map<std::string, std::size_t> calibration_of;
  for (std::size_t i = 0; i < impl_->calibrated.size(); ++i) calibration_of[impl_->calibrated[i].source] = i;
  std::vector<int> fixes_of(impl_->calibrated.size(), 0);
  // Robust measurements start with a Cauchy loss at the gate, whose pull fades with the residual, so
  // that a gross fix does not drag its neighbours (twists included) past the gate as well; see below.
  // A calibrated RSU's fixes are all off until its calibration is found (0.15 m and 0.5 deg put them
  // 35 cm off, far beyond a 2 mm fix's gate): they start under a Huber loss, which still pulls, and
  // turn Cauchy once a first solve has found the calibration.
  auto loss = [&](int m, bool calibrated = false) -> std::pair<ceres::LossFunctionWrapper*, double> {
    const double delta2 = chiSquareQuantile(m, o.gate_alpha);
    if (!o.robust && !o.estimate_noise) return {nullptr, delta2};
    ceres::LossFunction* inner = nullptr;
    if (o.robust) inner = calibrated ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(std::sqrt(delta2))) : new ceres::CauchyLoss(std::sqrt(delta2));
    return {new ceres::LossFunctionWrapper(inner, ceres::TAKE_OWNERSHIP), delta2};
  };
  for (const StoredPose& p : impl_->poses) {
    if (p.stamp < first || p.stamp > last) continue;
    const std::size_t k = std::min(n - 1, static_cast<std::size_t>((p.stamp - first) / step));
    const auto calibrated = calibration_of.find(p.source);
    if (calibrated != calibration_of.end() && p.m == 2 && p.component[0] == 0 && p.component[1] == 1) {
      const CalibratedRsu& rsu = impl_->calibrated[calibrated->second];
      auto* f = new CalibratedFixResidual{toSeconds(p.stamp - result.states[k].stamp), p.value[0], p.value[1], rsu.position.x(), rsu.position.y(),
                                          p.whitening.topLeftCorner<2, 2>()};
      const auto [l, delta2] = loss(2, true);
      double* block = calibration[calibrated->second].data();
      added.push_back({problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CalibratedFixResidual, 2, kState, 4>(f), l, blockOf(k), block),
                       &p.source, p.stamp, delta2, static_cast<int>(calibrated->second), l});
      ++fixes_of[calibrated->second];
      ++result.summary.pose_residuals;
      continue;
    }
    const bool biased = o.pose_bias && impl_->biased.count(p.source) > 0;
    PoseResidual* r = new PoseResidual{toSeconds(p.stamp - result.states[k].stamp), biased, p.m, {}, {}, p.whitening};
    for (int j = 0; j < p.m; ++j) r->component[j] = p.component[j], r->value[j] = p.value[j];
    const auto [l, delta2] = loss(p.m);
    added.push_back({problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PoseResidual, ceres::DYNAMIC, kState>(r, p.m), l, blockOf(k)),
                     &p.source, p.stamp, delta2, -1, l});
    ++result.summary.pose_residuals;
  }
  for (std::size_t i = 0; i < impl_->calibrated.size(); ++i)
    if (!clock[i] && fixes_of[i] > 0) problem.SetManifold(calibration[i].data(), new ceres::SubsetManifold(4, {3}));
  // Per twist source, optionally, its speed scale and yaw-rate bias, with a prior at (1, 0).
  std::map<std::string, std::array<double, 2>> odometry;
  for (const StoredTwist& t : impl_->twists) {
    if (t.stamp < first || t.stamp > last || n < 2) continue;
    const std::size_t k = std::min(n - 2, static_cast<std::size_t>((t.stamp - first) / step));
    const TwistResidual r{toSeconds(t.stamp - result.states[k].stamp) / dt, t.m, {t.component[0], t.component[1]}, {t.value[0], t.value[1]},
                          t.whitening};
    const auto [l, delta2] = loss(t.m);
    ceres::ResidualBlockId id;
    if (o.calibrate_odometry) {
      auto [it, fresh] = odometry.try_emplace(t.source, std::array<double, 2>{1.0, 0.0});
      if (fresh)
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<OdometryPrior, 2, 2>(new OdometryPrior{1.0 / o.odometry_scale_sd, 1.0 / o.odometry_yaw_rate_bias_sd}),
            nullptr, it->second.data());
      id = problem.AddResidualBlock(
          new TwistCost(r, true), l,
          blockOf(k), blockOf(k + 1), it->second.data());
    } else {
      id = problem.AddResidualBlock(new TwistCost(r, false), l,
                                    blockOf(k), blockOf(k + 1));
    }
    added.push_back({id, &t.source, t.stamp, delta2, -1, l});
    ++result.summary.twist_residuals;
  }

  // The pose bias: 0 on average with pose_bias_sd, varying over pose_bias_time. How large it is gets
  // measured on the drive (kBiasSource) where something absolute, the fixes, makes it visible.
  static const std::string kBiasSource = "pose bias";
  const bool bias_used = o.pose_bias && !impl_->biased.empty();  // else it stays 0, its prior's mean
  bool bias_held = false;  // held somewhere (below): there NDT's residuals do not show its bias
  {
    const double phi = std::exp(-dt / o.pose_bias_time);
    const double inverse_sigma = 1.0 / (o.pose_bias_sd * std::sqrt(1.0 - phi * phi));
    const bool used = bias_used;
    auto* prior_loss = used ? new ceres::LossFunctionWrapper(nullptr, ceres::TAKE_OWNERSHIP) : nullptr;
    const ceres::ResidualBlockId prior_id = problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BiasPrior, 2, kState>(new BiasPrior{1.0 / o.pose_bias_sd}), prior_loss, blockOf(0));
    if (used) added.push_back({prior_id, &kBiasSource, result.states[0].stamp, 0.0, -1, prior_loss, false});
    // The bias is told apart only near a pose that carries none (a roadside fix): there it moves as
    // its process says. Elsewhere it is held, fading without new spread, as the filter holds it away
    // from the fixes: the odometry alone would split NDT's moves between the bias and the vehicle and
    // pass its own slow errors (a gyro's bias, a wheel's scale) for NDT's (the twin's full run with the
    // bias loose everywhere: 1.3-2.1x the filter's error outside coverage on sites A and D). Not while
    // RSUs are calibrated: their fixes then carry an unknown offset of their own, and what tells it from
    // NDT's bias is the bias's wander over the whole drive (PoseBias.WithABiasedAnchor...).
    const bool hold = used && impl_->calibrated.empty();
    bias_held = hold;
    std::vector<char> told_apart(n, hold ? 0 : 1);
    if (hold) {
      // Each fix opens its reach and closes it after; a running count over the ticks then marks every
      // tick within one (fixes at 10 Hz overlap twenty-fold: marking each reach tick by tick repeats it).
      std::vector<int> opened(n + 1, 0);
      const Duration reach = fromSeconds(o.pose_bias_time);
      for (const StoredPose& p : impl_->poses) {
        if (impl_->biased.count(p.source) || p.stamp + reach < first || p.stamp - reach > last) continue;
        ++opened[static_cast<std::size_t>(std::max<Duration>(0, p.stamp - reach - first) / step)];
        --opened[std::min(n - 1, static_cast<std::size_t>(std::max<Duration>(0, p.stamp + reach - first) / step)) + 1];
      }
      int open = 0;
      for (std::size_t k = 0; k < n; ++k) told_apart[k] = (open += opened[k]) > 0;
    }
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const bool loose = told_apart[k] || told_apart[k + 1];
      auto* l = used && loose ? new ceres::LossFunctionWrapper(nullptr, ceres::TAKE_OWNERSHIP) : nullptr;
      // Held: a hundredth of the spread, stiff enough to hold it and not so stiff as to spoil the solve.
      const ceres::ResidualBlockId id = problem.AddResidualBlock(
          new BiasProcessCost(BiasProcess{phi, loose ? inverse_sigma : 100.0 * inverse_sigma}), l, blockOf(k), blockOf(k + 1));
      if (used && loose) added.push_back({id, &kBiasSource, result.states[k].stamp, 0.0, -1, l, false});
    }
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = o.max_iterations;
  // The problem is nearly linear about the filter's states (its rotations turn by fractions of a degree
  // between guess and optimum), so Gauss-Newton's full step is the right first step. Ceres's default
  // first radius (1e4) damps it: on site B's 1,835 states the solves took 27 iterations in all, against
  // 11 from 1e6, and the smoothed track moved by under 0.01 mm. A step that fails still shrinks the
  // region as before.
  solver.initial_trust_region_radius = 1e6;
  solver.num_threads = std::max(1, o.threads);
  solver.minimizer_progress_to_stdout = false;
  solver.logging_type = ceres::SILENT;
  auto whitenedSquared = [&](const Added& a) {
    const ceres::CostFunction* f = problem.GetCostFunctionForResidualBlock(a.id);
    std::vector<double*> parameters;
    problem.GetParameterBlocksForResidualBlock(a.id, &parameters);
    std::vector<double> residuals(static_cast<std::size_t>(f->num_residuals()));
    f->Evaluate(parameters.data(), residuals.data(), nullptr);
    double sum = 0.0;
    for (double r : residuals) sum += r * r;
    return sum;
  };
  // The chain's blocks, for the marginal covariances: states, then the calibrations with fixes.
  std::vector<double*> state_blocks(n), global_blocks;
  std::vector<std::size_t> global_rsu;  // which calibrated RSU each global block is
  for (std::size_t k = 0; k < n; ++k) state_blocks[k] = blockOf(k);
  // The state a parameter block is, or n for another block (a calibration).
  static_assert(sizeof(std::array<double, kState>) == kState * sizeof(double), "the states lie end to end");
  auto stateOf = [&, begin = x.front().data()](const double* block) {
    const std::less<const double*> before;
    if (before(block, begin) || !before(block, begin + n * kState)) return n;
    return static_cast<std::size_t>(block - begin) / kState;
  };
  auto collectGlobals = [&] {
    global_blocks.clear();
    global_rsu.clear();
    for (std::size_t i = 0; i < impl_->calibrated.size(); ++i)
      if (fixes_of[i] > 0) global_blocks.push_back(calibration[i].data()), global_rsu.push_back(i);
    for (auto& [source, block] : odometry) global_blocks.push_back(block.data());
  };

  const auto start = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  result.summary.initial_cost = summary.initial_cost;
  result.summary.iterations = static_cast<int>(summary.iterations.size()) - 1;
  if (o.robust && summary.IsSolutionUsable() && std::any_of(added.begin(), added.end(), [](const Added& a) { return a.rsu >= 0; })) {
    for (const Added& a : added)
      if (a.rsu >= 0) a.loss->Reset(new ceres::CauchyLoss(std::sqrt(a.threshold)), ceres::TAKE_OWNERSHIP);
    ceres::Solve(solver, &problem, &summary);
    result.summary.iterations += static_cast<int>(summary.iterations.size()) - 1;
  }
  // Each source's variance factor: what its covariances are off by, as the drive measures it.
  std::map<std::string, double> factor;
  auto factorOf = [&](const Added& a) {
    const auto it = factor.find(*a.source);
    return it == factor.end() ? 1.0 : it->second;
  };
  const int rounds = o.estimate_noise ? o.noise_rounds : 0;
  for (int round = 0; (o.robust || rounds > 0) && summary.IsSolutionUsable(); ++round) {
    // The filter's gate, with hindsight: a measurement beyond it at the robust solution is left out,
    // and the rest are solved again under a Huber loss at the gate (quadratic within it, as the filter
    // weighs what passes its gate), each source's covariance scaled by its factor. A Huber loss from
    // the start would bound a gross fix's pull but not end it: 1.8 m off with a 12 cm sigma, it pulled
    // the track 3 cm back, and at 2 mm it dragged the twists around it past their gate too.
    std::vector<Added> kept;
    for (const Added& a : added) {
      const double f = factorOf(a), sum = whitenedSquared(a);
      if (!o.robust || !a.gated || sum <= f * a.threshold) {
        ceres::LossFunction* inner = o.robust && a.gated ? new ceres::HuberLoss(std::sqrt(f * a.threshold)) : nullptr;
        a.loss->Reset(new ceres::ScaledLoss(inner, 1.0 / f, ceres::TAKE_OWNERSHIP), ceres::TAKE_OWNERSHIP);
        kept.push_back(a);
        continue;
      }
      result.summary.down_weighted.push_back({*a.source, a.stamp, std::sqrt(sum / f), 0.0});
      problem.RemoveResidualBlock(a.id);
      if (a.rsu >= 0) --fixes_of[static_cast<std::size_t>(a.rsu)];
    }
    added = kept;
    ceres::Solve(solver, &problem, &summary);
    result.summary.iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (round >= rounds || !summary.IsSolutionUsable()) break;

    // Variance components (Foerstner), made robust: a residual's squared whitened norm r^2 has the
    // expectation f (m - tr(A Sigma A^T) / f), its redundancy, where A is its Jacobian on the states
    // and Sigma their marginal covariance; the source's new factor is the median of r^2 / (redundancy
    // / m) over the median of chi-square(m), so that the few misfits that the Huber loss bounds (a fix
    // on the wrong corner) do not inflate it for all the good ones.
    collectGlobals();
    const ChainMarginals m = chainMarginals(problem, state_blocks, global_blocks, std::max(1, o.threads), kState);
    if (!m.ok) break;
    struct Tally {
      std::vector<double> normalised;  ///< r^2 / (redundancy / m)
      int m = 0;
    };
    std::map<std::string, Tally> tally;
    std::vector<double*> parameters;
    std::vector<double> residuals;
    std::vector<std::vector<double>> jacobian_storage;
    std::vector<double*> jacobians;
    for (const Added& a : added) {
      if (a.source == &kBiasSource) continue;  // measured below, from the states
      const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(a.id);
      problem.GetParameterBlocksForResidualBlock(a.id, &parameters);
      const int rows = cost->num_residuals();
      residuals.resize(static_cast<std::size_t>(rows));
      jacobian_storage.resize(parameters.size());
      jacobians.resize(parameters.size());
      for (std::size_t b = 0; b < parameters.size(); ++b) {
        jacobian_storage[b].resize(static_cast<std::size_t>(rows * cost->parameter_block_sizes()[b]));
        jacobians[b] = jacobian_storage[b].data();
      }
      cost->Evaluate(parameters.data(), residuals.data(), jacobians.data());
      double hat = 0.0;
      for (std::size_t b = 0; b < parameters.size(); ++b) {
        const std::size_t k = stateOf(parameters[b]);
        if (k == n) continue;  // a calibration block: its share is small beside the states'
        const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, kState, Eigen::RowMajor>> J(jacobians[b], rows, kState);
        hat += (J * m.states[k] * J.transpose()).trace();
      }
      double squares = 0.0;
      for (double r : residuals) squares += r * r;
      const double redundancy = (rows - hat / factorOf(a)) / rows;
      if (redundancy < 0.05) continue;  // a residual its states follow almost entirely says little
      Tally& t = tally[*a.source];
      t.normalised.push_back(squares / redundancy);
      t.m = std::max(t.m, rows);
    }
    bool changed = false;
    // The bias's size, by expectation-maximisation over the states that show it: the mean of b^2 + its
    // variance where its variance is well below the size assumed (elsewhere the drive says nothing).
    if (bias_used) {
      const double assumed = o.pose_bias_sd * o.pose_bias_sd * (factor.count(kBiasSource) ? factor[kBiasSource] : 1.0);
      double sum = 0.0;
      int count = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const double variance = 0.5 * (m.states[k](6, 6) + m.states[k](7, 7));
        if (variance > 0.25 * assumed) continue;
        sum += 0.5 * (x[k][6] * x[k][6] + x[k][7] * x[k][7]) + variance;
        ++count;
      }
      if (count >= 50) {
        const double updated = std::clamp(sum / count / (o.pose_bias_sd * o.pose_bias_sd), 1e-4, 1e4);
        double& f = factor.try_emplace(kBiasSource, 1.0).first->second;
        changed = changed || std::abs(updated / f - 1.0) > 0.05;
        f = updated;
      }
    }
    for (auto& [source, t] : tally) {
      if (static_cast<int>(t.normalised.size()) < o.noise_min_measurements) continue;
      const auto middle = t.normalised.begin() + static_cast<std::ptrdiff_t>(t.normalised.size() / 2);
      std::nth_element(t.normalised.begin(), middle, t.normalised.end());
      double updated = std::clamp(*middle / chiSquareQuantile(t.m, 0.5), 1e-4, 1e4);
      // A map-matching source without its bias modelled is never taken as better than it says: its
      // residuals show the scatter from scan to scan, not the error its poses share, and along a
      // corridor, where the scene does not hold NDT, each pose repeats the prediction it started from,
      // agreeing with the odometry by construction. Site D's cutting: NDT measured at 0.05x its
      // covariance outvoted the RSU's fixes (6.6 cm against the filter's 1.2).
      // Where the bias is held (away from the fixes) it is not modelled either.
      if ((!bias_used || bias_held) && impl_->biased.count(source)) updated = std::max(updated, 1.0);
      double& f = factor.try_emplace(source, 1.0).first->second;
      changed = changed || std::abs(updated / f - 1.0) > 0.05;
      f = updated;
    }
    if (!changed) break;
  }
  for (const auto& [source, f] : factor)
    if (source != kBiasSource) result.summary.noise.push_back({source, std::sqrt(f)});
  if (bias_used) result.summary.pose_bias_sd = o.pose_bias_sd * std::sqrt(factor.count(kBiasSource) ? factor.at(kBiasSource) : 1.0);
  result.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.summary.final_cost = summary.final_cost;
  result.summary.termination = terminationName(summary.termination_type);
  result.summary.report = summary.BriefReport();
  result.summary.states = static_cast<int>(n);
  for (std::size_t k = 0; k < n; ++k) {
    for (int i = 0; i < 6; ++i) result.states[k].state[i] = x[k][static_cast<std::size_t>(i)];
    result.states[k].state[2] = wrapAngle(result.states[k].state[2]);
    result.states[k].pose_bias = Eigen::Vector2d(x[k][6], x[k][7]);
  }

  // What the robust loss still weighs less than its covariance: whitened norms beyond the gate.
  for (const Added& a : added) {
    const double f = factorOf(a), sum = whitenedSquared(a) / f;
    if (a.gated && sum > a.threshold) result.summary.down_weighted.push_back({*a.source, a.stamp, std::sqrt(sum), std::sqrt(a.threshold / sum)});
  }

  // Marginal covariances of the states and of the calibrations, from the chain's structure (linear in
  // the drive's length; ceres::Covariance's sparse QR took 20 times the solve on a 90 s log).
  collectGlobals();
  const ChainMarginals marginals = result.summary.usable() && (o.covariances || !global_blocks.empty())
                                      ? chainMarginals(problem, state_blocks, global_blocks, std::max(1, o.threads), kState)
                                      : ChainMarginals{};
  if (o.covariances && marginals.ok)
    for (std::size_t k = 0; k < n; ++k) result.states[k].position_covariance = marginals.states[k].topLeftCorner(2, 2);

  // The calibrations, with their uncertainty; a block the drive does not determine is said to be so.
  const char* rank_note = "the drive does not determine it: no anchoring pose source (NDT), or too few fixes in too little geometry";
  std::vector<int> offset_of(impl_->calibrated.size(), -1);
  for (std::size_t g = 0, offset = 0; g < global_rsu.size(); ++g) {
    offset_of[global_rsu[g]] = static_cast<int>(offset);
    offset += clock[global_rsu[g]] ? 4 : 3;  // the held clock is not in the tangent space
  }
  for (std::size_t i = 0; i < impl_->calibrated.size(); ++i) {
    RsuCalibration c;
    c.source = impl_->calibrated[i].source;
    c.dx = calibration[i][0], c.dy = calibration[i][1], c.dyaw = calibration[i][2], c.clock_offset = calibration[i][3];
    c.fixes = fixes_of[i];
    c.clock_observable = clock[i];
    if (fixes_of[i] == 0) {
      c.note = "no fix of this RSU in the span";
    } else if (marginals.globals) {
      const Eigen::MatrixXd& C = *marginals.globals;
      const int at = offset_of[i];
      c.sd_dx = std::sqrt(std::max(0.0, C(at, at)));
      c.sd_dy = std::sqrt(std::max(0.0, C(at + 1, at + 1)));
      c.sd_dyaw = std::sqrt(std::max(0.0, C(at + 2, at + 2)));
      if (clock[i]) c.sd_clock_offset = std::sqrt(std::max(0.0, C(at + 3, at + 3)));
      // Determined: to better than 10 cm, 1 deg and 20 ms, and within what a registry accepts.
      c.observable = c.sd_dx < 0.1 && c.sd_dy < 0.1 && c.sd_dyaw < M_PI / 180.0 && (!clock[i] || c.sd_clock_offset < 0.02);
      if (!c.observable) c.note = rank_note;
      if (c.observable && (std::abs(c.dx) > 10.0 || std::abs(c.dy) > 10.0 || std::abs(c.dyaw) > M_PI / 6.0 || std::abs(c.clock_offset) > 1.0)) {
        c.observable = false;
        c.note = "implausible: beyond 10 m, 30 deg or 1 s, what a registry accepts; the fixes are not this RSU's, or the drive not this site's";
      }
    } else {
      c.note = result.summary.usable() ? rank_note : "the solver failed";
    }
    result.calibrations.push_back(c);
  }
  std::size_t odometry_offset = 0;
  for (std::size_t g = 0; g < global_rsu.size(); ++g) odometry_offset += clock[global_rsu[g]] ? 4 : 3;
  for (const auto& [source, block] : odometry) {
    OdometryCalibration c;
    c.source = source;
    c.speed_scale = block[0];
    c.yaw_rate_bias = block[1];
    if (marginals.globals) {
      c.sd_speed_scale = std::sqrt(std::max(0.0, (*marginals.globals)(odometry_offset, odometry_offset)));
      c.sd_yaw_rate_bias = std::sqrt(std::max(0.0, (*marginals.globals)(odometry_offset + 1, odometry_offset + 1)));
    }
    odometry_offset += 2;
    result.odometry.push_back(c);
  }
  return result;
}

}  // namespace coloc::smoother
