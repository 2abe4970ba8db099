#pragma once
// Chi-square tail probabilities and quantiles for the small dimensions gates and robust losses need
// (1..6): the filter's gates and the smoother's loss use the same figures.

namespace coloc {

/// P(X > x) for X ~ chi-square with `dof` degrees of freedom, dof in 1..6.
double chiSquareSurvival(int dof, double x);

/// The x with P(X > x) = alpha, i.e. the (1 - alpha) quantile; alpha in (0, 1), dof in 1..6.
double chiSquareQuantile(int dof, double alpha);

}  // namespace coloc
