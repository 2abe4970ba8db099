#pragma once
// A planar covariance changed direction by direction: its principal variances mapped, its axes kept.
// Raising a covariance "to at least" a figure means it in every direction, not on the x and y axes
// alone (a fit sure along the road and unsure across it keeps that shape), and one solver does it.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace coloc {

/// The symmetric part of `covariance` with each principal variance v replaced by f(v); the covariance
/// itself, symmetrized, if it has no real eigen-decomposition.
template <typename F>
Eigen::Matrix2d mapPrincipalVariances(const Eigen::Matrix2d& covariance, F f) {
  const Eigen::Matrix2d symmetric = 0.5 * (covariance + covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> e(symmetric);
  if (e.info() != Eigen::Success) return symmetric;
  const Eigen::Vector2d mapped(f(e.eigenvalues()[0]), f(e.eigenvalues()[1]));
  const Eigen::Matrix2d out = e.eigenvectors() * mapped.asDiagonal() * e.eigenvectors().transpose();
  return 0.5 * (out + out.transpose());
}

/// Every direction's variance at least `variance`.
inline Eigen::Matrix2d principalVariancesAtLeast(const Eigen::Matrix2d& covariance, double variance) {
  return mapPrincipalVariances(covariance, [variance](double v) { return v < variance ? variance : v; });
}

/// At least `covariance` and at least `floor` in every direction: covariance + (floor - covariance)+,
/// the positive part of the difference (a floor that is not round, NDT's noise along a vehicle and
/// across it). With floor = v I it is principalVariancesAtLeast(covariance, v).
inline Eigen::Matrix2d coveringAtLeast(const Eigen::Matrix2d& covariance, const Eigen::Matrix2d& floor) {
  const Eigen::Matrix2d symmetric = 0.5 * (covariance + covariance.transpose());
  return symmetric + mapPrincipalVariances(floor - symmetric, [](double v) { return v > 0.0 ? v : 0.0; });
}

/// `covariance` seen in `metric`'s whitening (where the metric is round), its principal variances
/// clamped to [lo, hi] there, and turned back: lo = 1 gives the smallest covariance at least both
/// (NDT's score floored at its fixed matrix), hi = 1 the largest at most both. The metric must have
/// no empty direction.
inline Eigen::Matrix2d clampedInMetric(const Eigen::Matrix2d& covariance, const Eigen::Matrix2d& metric, double lo, double hi) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> f(metric);
  const Eigen::Vector2d sd = f.eigenvalues().cwiseSqrt();
  const Eigen::Matrix2d whiten = sd.cwiseInverse().asDiagonal() * f.eigenvectors().transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> w(whiten * covariance * whiten.transpose());
  const Eigen::Vector2d clamped = w.eigenvalues().cwiseMax(lo).cwiseMin(hi);
  const Eigen::Matrix2d unwhiten = f.eigenvectors() * sd.asDiagonal();
  return unwhiten * w.eigenvectors() * clamped.asDiagonal() * w.eigenvectors().transpose() * unwhiten.transpose();
}

/// At most `covariance` and at most `ceiling` in every direction (clampedInMetric to [0, 1]). Below
/// the ceiling it is unchanged; it keeps its shape where it can. A ceiling with no variance in some
/// direction holds the result to a billionth of its other there.
inline Eigen::Matrix2d coveredAtMost(const Eigen::Matrix2d& covariance, const Eigen::Matrix2d& ceiling) {
  const Eigen::Matrix2d symmetric = 0.5 * (covariance + covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> c(0.5 * (ceiling + ceiling.transpose()));
  if (c.info() != Eigen::Success) return symmetric;
  const double top = std::max(c.eigenvalues()[1], 0.0);
  if (!(top > 0.0)) return Eigen::Matrix2d::Zero();
  const Eigen::Vector2d held = c.eigenvalues().cwiseMax(1e-18 * top);
  const Eigen::Matrix2d out = clampedInMetric(symmetric, c.eigenvectors() * held.asDiagonal() * c.eigenvectors().transpose(), 0.0, 1.0);
  return 0.5 * (out + out.transpose());
}

/// The largest variance in any direction (the larger eigenvalue of the symmetric part), at least 0;
/// NaN if the covariance has no real eigen-decomposition.
inline double largestPrincipalVariance(const Eigen::Matrix2d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> e(0.5 * (covariance + covariance.transpose()));
  return e.info() == Eigen::Success ? std::max(0.0, e.eigenvalues()[1]) : std::nan("");
}

}  // namespace coloc
