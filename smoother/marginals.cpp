#include "marginals.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace coloc::smoother {

using Block = Eigen::MatrixXd;

ChainMarginals chainMarginals(ceres::Problem& problem, const std::vector<double*>& states, const std::vector<double*>& globals, int threads,
                              int size) {
  ChainMarginals out;
  const std::size_t n = states.size();
  if (n == 0) return out;

  // The Jacobian, losses applied, with columns in the order asked for: states first, then the globals.
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = states;
  eo.parameter_blocks.insert(eo.parameter_blocks.end(), globals.begin(), globals.end());
  eo.apply_loss_function = true;
  eo.num_threads = threads;
  ceres::CRSMatrix J;
  if (!problem.Evaluate(eo, nullptr, nullptr, nullptr, &J)) return out;
  const int state_columns = static_cast<int>(size * n);
  const int m = J.num_cols - state_columns;  // the globals' tangent dimensions together

  // H = J^T J as D (diagonal blocks), E (the block right of each diagonal one), B (states x globals), C.
  std::vector<Block> D(n, Block::Zero(size, size)), E(n, Block::Zero(size, size));
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(state_columns, m), C = Eigen::MatrixXd::Zero(m, m);
  for (int r = 0; r < J.num_rows; ++r) {
    const int begin = J.rows[r], end = J.rows[r + 1];
    for (int a = begin; a < end; ++a) {
      const int ca = J.cols[a];
      const double va = J.values[a];
      if (va == 0.0) continue;
      for (int b = begin; b < end; ++b) {
        const int cb = J.cols[b];
        const double v = va * J.values[b];
        if (ca < state_columns && cb < state_columns) {
          const int ka = ca / size, kb = cb / size;
          if (ka == kb) D[ka](ca % size, cb % size) += v;
          else if (kb == ka + 1) E[ka](ca % size, cb % size) += v;
          else if (ka != kb + 1) return out;  // not a chain
        } else if (ca < state_columns) {
          B(ca, cb - state_columns) += v;
        } else if (cb >= state_columns) {
          C(ca - state_columns, cb - state_columns) += v;
        }
      }
    }
  }

  // Forward elimination: S_k = D_k - E_{k-1}^T S_{k-1}^-1 E_{k-1}, and Y = L^-1 B alongside.
  std::vector<Eigen::LLT<Block>> S(n);
  Eigen::MatrixXd Y = B;
  for (std::size_t k = 0; k < n; ++k) {
    Block s = D[k];
    if (k > 0) {
      s -= E[k - 1].transpose() * S[k - 1].solve(E[k - 1]);
      if (m > 0) Y.middleRows(size * k, size) -= E[k - 1].transpose() * S[k - 1].solve(Y.middleRows(size * (k - 1), size));
    }
    S[k].compute(s);
    if (S[k].info() != Eigen::Success) return out;
  }
  // Backward: X = A^-1 B, and the diagonal blocks of A^-1 (Sigma_k = S_k^-1 + G_k Sigma_{k+1} G_k^T,
  // G_k = S_k^-1 E_k).
  Eigen::MatrixXd X(state_columns, m);
  out.states.resize(n);
  const Block I = Block::Identity(size, size);
  out.states[n - 1] = S[n - 1].solve(I);
  if (m > 0) X.middleRows(size * (n - 1), size) = S[n - 1].solve(Y.middleRows(size * (n - 1), size));
  for (std::size_t k = n - 1; k-- > 0;) {
    const Block G = S[k].solve(E[k]);
    out.states[k] = S[k].solve(I) + G * out.states[k + 1] * G.transpose();
    if (m > 0) X.middleRows(size * k, size) = S[k].solve(Y.middleRows(size * k, size)) - G * X.middleRows(size * (k + 1), size);
  }

  // The globals: their covariance is the inverse of their Schur complement C - B^T A^-1 B, and each
  // state's marginal grows by X_k (that inverse) X_k^T.
  if (m > 0) {
    Eigen::MatrixXd schur = C - B.transpose() * X;
    schur = 0.5 * (schur + schur.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(schur);
    const double largest = std::max(eig.eigenvalues().maxCoeff(), C.diagonal().maxCoeff());
    if (eig.info() != Eigen::Success || eig.eigenvalues().minCoeff() <= 1e-12 * largest) {
      out.states.clear();
      return out;
    }
    const Eigen::MatrixXd inverse = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
    for (std::size_t k = 0; k < n; ++k) {
      const auto Xk = X.middleRows(size * k, size);
      out.states[k] += Xk * inverse * Xk.transpose();
    }
    out.globals = inverse;
  }
  out.ok = true;
  return out;
}

}  // namespace coloc::smoother
