#include "coloc/ndt/aligner.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <mutex>
#include <cmath>
#include <sstream>

#include "coloc/core/error.hpp"
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
};

// Newton's method on the NDT score with each step clamped to step_size, as Autoware's ndt_scan_matcher
// does, plus what its line search provides: a step is taken only if the score rises. Far from the
// optimum the Hessian can be indefinite, and plain clamped Newton then zig-zags (seen on 1,000-point
// scans started 0.5 m off); there the Hessian is shifted until it is negative definite
// (Levenberg-style), and a step that lowers the score is halved. The evaluation at an accepted pose is
// reused for the next iteration, so the safeguard costs nothing while steps succeed. Stops as PCL does,
// on the squared translation of a step.
Optimisation optimiseFast(const NdtTarget::Impl& target, const std::vector<Eigen::Vector3f>& source, Vector6d pose,
                          const NdtConfig& config, NeighbourCache& cache) {
  Optimisation out;
  ScoreOptions options;
  options.neighborhood = config.neighborhood;
  options.threads = config.threads;
  auto evaluate = [&](const Vector6d& p) {
    return evaluateScore(target.voxels, config.resolution, target.constants, source, p, options, &cache);
  };
  ScoreEvaluation current = evaluate(pose);
  Eigen::Vector3d previous_step = Eigen::Vector3d::Zero();
  constexpr int kMaxHalvings = 8;
  while (out.iterations < config.max_iterations) {
    // The Newton step (pseudo-inverse, as PCL), turned uphill if it points down. Where the Hessian is
    // indefinite this still aims at the model's stationary point in most directions, which converges far
    // faster than shifting the Hessian towards a gradient step.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12 misreads Eigen's JacobiSVD internals
    Eigen::JacobiSVD<Matrix6d> svd(current.hessian, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Vector6d step = svd.solve(-current.gradient);
#pragma GCC diagnostic pop
    if (!step.allFinite() || step.norm() == 0.0) {
      out.converged = true;
      break;
    }
    if (step.dot(current.gradient) < 0.0) step = -step;
    const double length = step.norm();
    if (length > config.step_size) step *= config.step_size / length;
    const bool small = step.head<3>().squaredNorm() <= config.transformation_epsilon;
    // Take the longest of step, step/2, step/4, ... that does not lower the score.
    bool moved = false;
    int halvings = 0;
    for (; halvings <= kMaxHalvings; ++halvings, step *= 0.5) {
      ScoreEvaluation trial = evaluate(pose + step);
      if (trial.score >= current.score) {
        pose += step;
        current = std::move(trial);
        moved = true;
        break;
      }
    }
    ++out.iterations;
    // Converged when the full step is already below the threshold, or no ascent is left within 1/256
    // of it; a step shortened by the search says nothing about convergence.
    if (!moved || small) {
      out.converged = true;
      break;
    }
    const Eigen::Vector3d translation = step.head<3>();
    if (previous_step.norm() > 0.0 && translation.norm() > 0.0 &&
        previous_step.dot(translation) / (previous_step.norm() * translation.norm()) < -0.9)
      ++out.oscillations;
    previous_step = translation;
  }
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
  // Which voxels each point can reach, remembered across the evaluations of this alignment. The margin
  // trades list length against regathering: a quarter voxel outlasts several clamped Newton steps.
  NeighbourCache cache(source.size(), config.resolution, 0.25 * config.resolution);
  const bool fast = config.backend == NdtBackend::kFast;
  const Optimisation opt = fast ? optimiseFast(t, source.points, matrixToPose(guess), config, cache) : optimisePcl(t, source, guess);
  result.elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  result.transform = poseToMatrix(opt.pose);
  result.iterations = opt.iterations;
  result.oscillations = opt.oscillations;

  // Scores and the Hessian at the result, over PCL's radius neighbourhood whatever the backend.
  ScoreOptions options;
  options.nvtl = true;
  options.hessian = config.covariance == CovarianceMode::kLaplace;
  options.gradient = options.hessian;
  options.threads = config.threads;
  const ScoreEvaluation eval = evaluateScore(t.voxels, config.resolution, t.constants, source.points, opt.pose, options, fast ? &cache : nullptr);
  result.transform_probability = eval.score / static_cast<double>(source.size());
  result.nvtl = eval.nvtl_points ? eval.nvtl_sum / static_cast<double>(eval.nvtl_points) : 0.0;

  Matrix6d covariance = config.covariance == CovarianceMode::kLaplace ? laplaceCovariance(eval.hessian, config.fixed_covariance)
                                                                     : Matrix6d(config.fixed_covariance.asDiagonal());
  // The fixed matrix is given in the vehicle frame; rotate its position block into the map frame.
  const Eigen::Matrix3d R = result.transform.topLeftCorner<3, 3>();
  if (config.covariance == CovarianceMode::kFixed)
    covariance.topLeftCorner<3, 3>() = R * covariance.topLeftCorner<3, 3>() * R.transpose();
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
