#pragma once
// Marginal covariances of a chain of states, fast. The smoother's problem is a chain: every residual
// touches one state, two neighbouring states, or a state and a few global blocks (the RSU calibrations).
// Its information matrix is therefore block-tridiagonal with an "arrow" of global columns, and the
// diagonal blocks of its inverse follow from one forward elimination and one backward sweep (the
// Rauch-Tung-Striebel recursion), plus a rank update for the global blocks through their Schur
// complement: linear in the number of states, where a general sparse QR (ceres::Covariance) is not.
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace ceres {
class Problem;
}

namespace coloc::smoother {

struct ChainMarginals {
  std::vector<Eigen::MatrixXd> states;  ///< one per state block, in order
  /// The global blocks' joint covariance, in their tangent spaces, in order; empty without them.
  /// Unset when the problem does not determine them (its Schur complement is singular): the states'
  /// covariances are then unset too, as they are not determined either.
  std::optional<Eigen::MatrixXd> globals;
  bool ok = false;  ///< false: not a chain, or not determined; `states` is then empty
};

/// `states` are the `size`-parameter blocks in chain order; `globals` any number of other blocks (each in
/// the problem with at least one residual). The robust losses are applied to the Jacobian, as
/// ceres::Covariance does.
ChainMarginals chainMarginals(ceres::Problem& problem, const std::vector<double*>& states, const std::vector<double*>& globals, int threads,
                              int size);

}  // namespace coloc::smoother
