#include "coloc/ndt/aligner.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <mutex>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/core/principal_variances.hpp"
#include "target_impl.hpp"

namespace coloc::ndt {

const char* toString(AlignRejection rejection) {
  switch (rejection) {
    case AlignRejection::kNone: return "none";
    case AlignRejection::kMaxIterations: return "max_iterations";
    case AlignRejection::kOscillation: return "oscillation";
    case AlignRejection::kLowScore: return "low_score";
    case AlignRejection::kEmptySource: return "empty_source";
  }
  return "?";
}

namespace {

using Clock = std::chrono::steady_clock;

struct Optimisation {
  Vector6d pose;
  int iterations = 0;
  int oscillations = 0;
  bool converged = false;
  /// The score at `pose` over all the points, with NVTL when the neighbourhood is the radius one (the
  /// fast backend's last evaluation; else none).
  std::optional<ScoreEvaluation> at_pose;
};

// Whether the result's evaluation needs the Hessian: the Laplace covariance is its inverse.
bool hessianAtResult(const NdtConfig& config) { return config.covariance == CovarianceMode::kLaplace; }

// Newton's method on the NDT score inside a trust region (More & Sorensen 1983; Nocedal & Wright ch. 4).
// Autoware's ndt_scan_matcher clamps every step to step_size, so a start 2 m off needs 20 of its 30
// iterations, and where the Hessian is indefinite (far from the optimum; on 1,000-point scans often)
// the clamped Newton step aims at a saddle and the line search stalls. Here each step maximises the
// score's quadratic model within a radius: the Newton step when the Hessian is negative definite and
// the step fits, else the model's maximum on the radius, found exactly from the Hessian's eigenvectors
// (a Levenberg shift -H + lambda I, lambda solving |s| = radius). The radius starts at step_size,
// doubles while the model predicts the score's rise well, shrinks when it does not, and a step that
// lowers the score is refused. Rotations count in the radius at kLeverArm metres per radian, so that
// a radius bounds how far any point within that range moves. Converged when a full Newton step moves
// the pose less than transformation_epsilon (squared translation, PCL's test) and turns it less than
// kRotationEpsilon, or when no step as long as kSmallestRadius raises the score.
constexpr double kLeverArm = 10.0;         // m
constexpr double kRotationEpsilon = 2e-4;  // rad: 1 cm at 50 m, the translation test's 1 cm
constexpr double kSmallestRadius = 1e-3;   // m (scaled 6-D step norm)

struct TrustStep {
  Vector6d step;        ///< in the pose's own units
  bool newton = false;  ///< the unconstrained Newton step (the Hessian negative definite, the step inside)
};

// Maximises g's + s'Hs/2 subject to |D s| <= radius, D = diag(1, 1, 1, L, L, L).
TrustStep trustRegionStep(const Vector6d& gradient, const Matrix6d& hessian, double radius) {
  Vector6d d;
  d << 1.0, 1.0, 1.0, kLeverArm, kLeverArm, kLeverArm;
  const Vector6d gu = gradient.cwiseQuotient(d);
  const Matrix6d M = -(d.asDiagonal().inverse() * hessian * d.asDiagonal().inverse());
  Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(M);
  const Vector6d mu = eigen.eigenvalues();  // ascending
  const Matrix6d& V = eigen.eigenvectors();
  const Vector6d a = V.transpose() * gu;
  auto stepFor = [&](double lambda) { return Vector6d(V * a.cwiseQuotient((mu.array() + lambda).matrix())); };
  TrustStep out;
  const double scale = std::max(std::abs(mu[5]), 1e-12);
  if (mu[0] > 1e-9 * scale) {
    const Vector6d newton = stepFor(0.0);
    if (newton.norm() <= radius) {
      out.step = newton.cwiseQuotient(d);
      out.newton = true;
      return out;
    }
  }
  // |s(lambda)| falls from infinity (or from its value at -mu_min) to 0 as lambda grows: bisect.
  double lo = std::max(0.0, -mu[0]) + 1e-12 * scale, hi = lo + 1.0;
  while (stepFor(hi).norm() > radius) hi = lo + 2.0 * (hi - lo);
  Vector6d s = stepFor(hi);
  if (stepFor(lo).norm() < radius) {
    // The hard case: the gradient has (almost) nothing along the weakest direction; go along it.
    s = stepFor(lo);
    const double tau = std::sqrt(std::max(0.0, radius * radius - s.squaredNorm()));
    s += tau * V.col(0) * (V.col(0).dot(gu) < 0.0 ? -1.0 : 1.0);
  } else {
    for (int i = 0; i < 100 && hi - lo > 1e-12 * (1.0 + hi); ++i) {
      const double mid = 0.5 * (lo + hi);
      (stepFor(mid).norm() > radius ? lo : hi) = mid;
    }
    s = stepFor(hi);
  }
  out.step = s.cwiseQuotient(d);
  return out;
}

// The trust-region iterations on `points` from `pose` with radius `radius` (both carried on), counted
// into `out` up to the iteration limit. True when converged (see above).
bool iterate(const NdtTarget::Impl& target, const std::vector<Eigen::Vector3f>& points, const NdtConfig& config, NeighbourCache& cache,
             Vector6d& pose, double& radius, Eigen::Vector3d& previous_step, Optimisation& out) {
  ScoreOptions options;
  options.neighborhood = config.neighborhood;
  options.threads = config.threads;
  // NVTL in the same pass costs a comparison per voxel: the last evaluation, at the result, then
  // serves as the final one.
  options.nvtl = config.neighborhood == Neighborhood::kRadius;
  auto evaluateWith = [&](const Vector6d& p, const ScoreOptions& o) {
    return evaluateScore(target.voxels, config.resolution, target.constants, points, p, o, &cache);
  };
  auto evaluate = [&](const Vector6d& p) { return evaluateWith(p, options); };
  ScoreOptions score_only = options;
  score_only.gradient = score_only.hessian = false;
  const bool hessian_at_result = hessianAtResult(config);
  ScoreEvaluation current = evaluate(pose);
  // Every return leaves `pose` where `current` was evaluated.
  auto done = [&](bool converged) {
    if (options.nvtl) out.at_pose = current;
    return converged;
  };
  // The radius grows to half a voxel at most: the score's model is local to the voxels a point sees.
  const double max_radius = std::max(config.step_size, 0.5 * config.resolution);
  auto scaledNorm = [](const Vector6d& s) { return std::sqrt(s.head<3>().squaredNorm() + kLeverArm * kLeverArm * s.tail<3>().squaredNorm()); };
  while (out.iterations < config.max_iterations) {
    if (!current.gradient.allFinite() || !current.hessian.allFinite() || current.gradient.norm() == 0.0)
      return done(true);  // nothing to step on (no point sees a voxel)
    const TrustStep ts = trustRegionStep(current.gradient, current.hessian, radius);
    const Vector6d& step = ts.step;
    if (!step.allFinite()) return done(false);
    const bool small = ts.newton && step.head<3>().squaredNorm() <= config.transformation_epsilon && step.tail<3>().norm() <= kRotationEpsilon;
    // After a small step the iterations end whatever the trial gives: its derivatives are never used
    // unless the covariance needs the Hessian at the result. The score and NVTL are the same bits.
    ScoreEvaluation trial = small && !hessian_at_result ? evaluateWith(pose + step, score_only) : evaluate(pose + step);
    ++out.iterations;
    const double gain = trial.score - current.score;
    const double length = scaledNorm(step);
    if (!(gain >= 0.0)) {
      // Refused: the model overreached. Shrink below this step; give up once the smallest fails.
      radius = 0.25 * std::min(radius, length);
      if (small || radius < kSmallestRadius) return done(true);
      continue;
    }
    const double predicted = current.gradient.dot(step) + 0.5 * step.dot(current.hessian * step);
    const double agreement = predicted > 0.0 ? gain / predicted : 0.0;
    if (agreement > 0.75 && length >= 0.99 * radius) radius = std::min(2.0 * radius, max_radius);
    else if (agreement < 0.25) radius = std::max(0.25 * length, kSmallestRadius);
    pose += step;
    current = std::move(trial);
    if (small) return done(true);
    const Eigen::Vector3d translation = step.head<3>();
    if (previous_step.norm() > 0.0 && translation.norm() > 0.0 &&
        previous_step.dot(translation) / (previous_step.norm() * translation.norm()) < -0.9)
      ++out.oscillations;
    previous_step = translation;
  }
  return done(false);
}

// A dense scan first converges on an evenly spread subset of kCoarsePoints points, then on all of them:
// far from the optimum every point only repeats what its neighbours say, and the last, full-resolution
// iterations start next to the optimum (16k points: 9 full evaluations become 3 or 4). Scans of
// Autoware's size (1,500 points) never take the first stage.
constexpr std::size_t kCoarsePoints = 4000;

Optimisation optimiseFast(const NdtTarget::Impl& target, const std::vector<Eigen::Vector3f>& source, Vector6d pose,
                          const NdtConfig& config, NeighbourCache& cache) {
  Optimisation out;
  double radius = config.step_size;
  Eigen::Vector3d previous_step = Eigen::Vector3d::Zero();
  if (source.size() >= 2 * kCoarsePoints) {
    const std::size_t stride = source.size() / kCoarsePoints;
    std::vector<Eigen::Vector3f> coarse;
    coarse.reserve(source.size() / stride + 1);
    for (std::size_t i = 0; i < source.size(); i += stride) coarse.push_back(source[i]);
    NeighbourCache coarse_cache(coarse.size(), *target.neighbours);
    iterate(target, coarse, config, coarse_cache, pose, radius, previous_step, out);
  }
  out.converged = iterate(target, source, config, cache, pose, radius, previous_step, out);
  out.pose = pose;
  return out;
}

Optimisation optimisePcl(const NdtTarget::Impl& target, const PointCloud& source, const Eigen::Matrix4d& guess) {
  // PCL's NDT keeps per-alignment state in the object, so alignments on one target are serialised.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  ExposedNdt& ndt = *target.pcl_ndt;
  ndt.setInputSource(toPcl(source));
  PclCloud aligned;
  ndt.align(aligned, guess.cast<float>());
  Optimisation out;
  out.pose = matrixToPose(ndt.getFinalTransformation().cast<double>());
  out.iterations = ndt.getFinalNumIteration();
  out.converged = ndt.hasConverged() && out.iterations < ndt.getMaximumIterations();
  return out;
}

// -H^-1 of the score (a Laplace approximation), floored at the fixed covariance.
Matrix6d laplaceCovariance(const Matrix6d& hessian, const Vector6d& floor) {
  Matrix6d covariance = -hessian.inverse();
  if (!covariance.allFinite()) return Matrix6d(floor.asDiagonal());
  covariance = 0.5 * (covariance + covariance.transpose()).eval();
  for (int i = 0; i < 6; ++i) covariance(i, i) = std::max(covariance(i, i), 0.0) + std::max(0.0, floor[i] - covariance(i, i));
  return covariance;
}

// The NVTL of the source at a pose: the mean over points near the map of their best voxel's score.
double nvtlAt(const NdtTarget::Impl& t, const std::vector<Eigen::Vector3f>& source, const Vector6d& pose, const NdtConfig& config,
              NeighbourCache* cache) {
  ScoreOptions options;
  options.nvtl = true;
  options.gradient = false;
  options.hessian = false;
  options.threads = config.threads;
  const ScoreEvaluation e = evaluateScore(t.voxels, config.resolution, t.constants, source, pose, options, cache);
  return e.nvtl_points ? e.nvtl_sum / static_cast<double>(e.nvtl_points) : 0.0;
}

// The smallest symmetric matrix (in the floor's metric) that is at least both: the estimate's
// eigenvalues, seen through the floor's whitening, clamped at 1.
Eigen::Matrix2d floorCovariance(const Eigen::Matrix2d& estimate, const Eigen::Matrix2d& floor) {
  return clampedInMetric(estimate, floor, 1.0, std::numeric_limits<double>::infinity());
}

// Autoware's MULTI_NDT_SCORE, with yaw probes: NVTL at offset poses, softmax weights (the optimum
// included), weighted covariance of the probes' x/y and of their yaw, floored at the fixed matrix
// (given in the vehicle frame, rotated into the map's).
Matrix6d multiNdtScoreCovariance(const NdtTarget::Impl& t, const std::vector<Eigen::Vector3f>& source, const Vector6d& optimum, double nvtl,
                                 const NdtConfig& config, NeighbourCache* cache) {
  const Eigen::Matrix4d T = poseToMatrix(optimum);
  // The heading in the map's plane (a sensor looking straight up or down has none: the map's x then).
  const Eigen::Vector2d forward = T.block<2, 1>(0, 0);
  const Eigen::Vector2d along = forward.norm() > 1e-9 ? Eigen::Vector2d(forward.normalized()) : Eigen::Vector2d::UnitX();
  const Eigen::Vector2d across(-along.y(), along.x());
  const Eigen::Matrix2d heading = (Eigen::Matrix2d() << along, across).finished();
  // Autoware's initial_pose_offset_model, in the vehicle frame: x [0, 0, 0.5, -0.5, 1, -1], y [0.5, -0.5, 0, 0, 0, 0].
  static const double kOffsets[6][2] = {{0.0, 0.5}, {0.0, -0.5}, {0.5, 0.0}, {-0.5, 0.0}, {1.0, 0.0}, {-1.0, 0.0}};
  const auto weighted = [&](const std::vector<double>& scores) {
    const double best = *std::max_element(scores.begin(), scores.end());
    std::vector<double> w(scores.size());
    double sum = 0.0;
    for (std::size_t i = 0; i < scores.size(); ++i) sum += w[i] = std::exp((scores[i] - best) / config.score_temperature);
    for (double& x : w) x /= sum;
    return w;
  };

  std::vector<Eigen::Vector2d> offsets{Eigen::Vector2d::Zero()};
  std::vector<Eigen::Vector3d> shifts;
  for (const auto& o : kOffsets) {
    offsets.push_back(heading * Eigen::Vector2d(o[0], o[1]));
    shifts.emplace_back(offsets.back().x(), offsets.back().y(), 0.0);
  }
  std::vector<double> scores = nvtlAtTranslations(t.voxels, config.resolution, t.constants, source, optimum, shifts, *t.neighbours, config.threads, cache);
  scores.insert(scores.begin(), nvtl);
  std::vector<double> w = weighted(scores);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < w.size(); ++i) mean += w[i] * offsets[i];
  Eigen::Matrix2d xy = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < w.size(); ++i) xy += w[i] * (offsets[i] - mean) * (offsets[i] - mean).transpose();

  Matrix6d covariance = Matrix6d(config.covariance_floor.asDiagonal());
  const Eigen::Matrix2d floor = heading * covariance.topLeftCorner<2, 2>() * heading.transpose();
  covariance.topLeftCorner<2, 2>() = floor.allFinite() ? floorCovariance(xy, floor) : floor;
  if (config.score_yaw_offset_deg > 0.0) {
    const double step = config.score_yaw_offset_deg * M_PI / 180.0;
    std::vector<double> yaws{0.0};
    std::vector<double> yaw_scores{nvtl};
    for (const double k : {1.0, -1.0, 2.0, -2.0}) {
      const Eigen::Matrix3d turn = Eigen::AngleAxisd(k * step, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      Eigen::Matrix4d probe = T;
      probe.topLeftCorner<3, 3>() = turn * T.topLeftCorner<3, 3>();
      yaws.push_back(k * step);
      yaw_scores.push_back(nvtlAt(t, source, matrixToPose(probe), config, cache));
    }
    w = weighted(yaw_scores);
    double m = 0.0, var = 0.0;
    for (std::size_t i = 0; i < w.size(); ++i) m += w[i] * yaws[i];
    for (std::size_t i = 0; i < w.size(); ++i) var += w[i] * (yaws[i] - m) * (yaws[i] - m);
    covariance(5, 5) = std::max(covariance(5, 5), var);
  }
  return covariance;
}

}  // namespace

namespace {

// The alignment proper, on a source cloud whose points are all finite.
AlignResult alignFinite(const NdtTarget::Impl& t, const PointCloud& source, const Eigen::Matrix4d& guess, const NdtConfig& config) {
  AlignResult result;
  result.transform = guess;
  if (source.empty()) {
    result.rejection = AlignRejection::kEmptySource;
    result.detail = "the source cloud is empty (or has no finite point)";
    return result;
  }
  const auto start = Clock::now();
  // Which voxels each point can reach, remembered across the evaluations of this alignment.
  NeighbourCache cache(source.size(), *t.neighbours);
  const bool fast = config.backend == NdtBackend::kFast;
  const Optimisation opt = fast ? optimiseFast(t, source.points, matrixToPose(guess), config, cache) : optimisePcl(t, source, guess);
  result.elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  result.transform = poseToMatrix(opt.pose);
  result.iterations = opt.iterations;
  result.oscillations = opt.oscillations;

  // Scores and the Hessian at the result, over PCL's radius neighbourhood whatever the backend.
  ScoreOptions options;
  options.nvtl = true;
  options.hessian = hessianAtResult(config);
  options.gradient = options.hessian;
  options.threads = config.threads;
  // The fast backend's last evaluation is this one, with the derivatives besides (the same bits: the
  // same points, pose, voxels and order of sums).
  const ScoreEvaluation eval =
      opt.at_pose ? *opt.at_pose : evaluateScore(t.voxels, config.resolution, t.constants, source.points, opt.pose, options, fast ? &cache : nullptr);
  result.transform_probability = eval.score / static_cast<double>(source.size());
  result.nvtl = eval.nvtl_points ? eval.nvtl_sum / static_cast<double>(eval.nvtl_points) : 0.0;

  Matrix6d covariance;
  switch (config.covariance) {
    case CovarianceMode::kLaplace: covariance = laplaceCovariance(eval.hessian, config.covariance_floor); break;
    case CovarianceMode::kMultiNdtScore:
      covariance = multiNdtScoreCovariance(t, source.points, opt.pose, result.nvtl, config, fast ? &cache : nullptr);
      break;
    case CovarianceMode::kFixed: {
      // The fixed matrix is given in the vehicle frame; rotate its position block into the map frame.
      const Eigen::Matrix3d R = result.transform.topLeftCorner<3, 3>();
      covariance = Matrix6d(config.fixed_covariance.asDiagonal());
      covariance.topLeftCorner<3, 3>() = R * covariance.topLeftCorner<3, 3>() * R.transpose();
      break;
    }
  }
  result.covariance = covariance;

  std::ostringstream why;
  if (eval.nvtl_points == 0) {
    result.rejection = AlignRejection::kEmptySource;
    why << "no source point lies near the map";
  } else if (!opt.converged) {
    result.rejection = AlignRejection::kMaxIterations;
    why << "stopped at the iteration limit (" << config.max_iterations << ") without converging";
  } else if (opt.oscillations > config.max_oscillations) {
    result.rejection = AlignRejection::kOscillation;
    why << opt.oscillations << " steps reversed direction (limit " << config.max_oscillations << ")";
  } else if (result.nvtl < config.nvtl_threshold) {
    result.rejection = AlignRejection::kLowScore;
    why << "NVTL " << result.nvtl << " is under the threshold " << config.nvtl_threshold;
  }
  result.detail = why.str();
  return result;
}

}  // namespace

AlignResult align(const NdtTarget& target, const PointCloud& source, const Eigen::Matrix4d& guess, const NdtConfig& config) {
  if (!guess.allFinite()) throw Error("NDT align: the initial guess is not finite");
  const NdtTarget::Impl& t = target.impl();
  // Non-finite points carry no information and would poison the voxel lookup: leave them out.
  PointCloud finite;
  const bool all_finite = std::all_of(source.points.begin(), source.points.end(), [](const Eigen::Vector3f& p) { return p.allFinite(); });
  if (!all_finite)
    for (const Eigen::Vector3f& p : source.points)
      if (p.allFinite()) finite.points.push_back(p);
  const PointCloud& source_used = all_finite ? source : finite;
  return alignFinite(t, source_used, guess, config);
}

}  // namespace coloc::ndt
