#include "marginals.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "residuals.hpp"

namespace coloc::smoother {

namespace {

// The recursion with blocks of `Size` rows (Eigen::Dynamic: `size`). The smoother's states have a size
// known when compiling, and blocks of that size live on the stack: the dynamic blocks' allocations and
// general products took most of the sweep.
template <int Size>
ChainMarginals chainMarginalsOf(ceres::Problem& problem, const std::vector<double*>& states, const std::vector<double*>& globals, int threads,
                                int size) {
  using Block = Eigen::Matrix<double, Size, Size>;
  using Rows = Eigen::Matrix<double, Size, Eigen::Dynamic>;
  ChainMarginals out;
  const std::size_t n = states.size();

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
  // Each entry's block and place in it, once per entry rather than once per product.
  std::vector<int> block_of(J.cols.size()), within(J.cols.size());
  for (std::size_t e = 0; e < J.cols.size(); ++e) block_of[e] = J.cols[e] / size, within[e] = J.cols[e] % size;
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
          const int ka = block_of[static_cast<std::size_t>(a)], kb = block_of[static_cast<std::size_t>(b)];
          const int ia = within[static_cast<std::size_t>(a)], ib = within[static_cast<std::size_t>(b)];
          if (ka == kb) D[static_cast<std::size_t>(ka)](ia, ib) += v;
          else if (kb == ka + 1) E[static_cast<std::size_t>(ka)](ia, ib) += v;
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
      const Block solved = S[k - 1].solve(E[k - 1]);
      s -= E[k - 1].transpose() * solved;
      if (m > 0) {
        const Rows y = S[k - 1].solve(Rows(Y.middleRows(size * (k - 1), size)));
        Y.middleRows(size * k, size) -= E[k - 1].transpose() * y;
      }
    }
    S[k].compute(s);
    if (S[k].info() != Eigen::Success) return out;
  }
  // Backward: X = A^-1 B, and the diagonal blocks of A^-1 (Sigma_k = S_k^-1 + G_k Sigma_{k+1} G_k^T,
  // G_k = S_k^-1 E_k).
  Eigen::MatrixXd X(state_columns, m);
  out.states.resize(n);
  const Block I = Block::Identity(size, size);
  Block next = S[n - 1].solve(I);  // the marginal of the state after k, kept in a block of its size
  out.states[n - 1] = next;
  if (m > 0) X.middleRows(size * (n - 1), size) = S[n - 1].solve(Rows(Y.middleRows(size * (n - 1), size)));
  for (std::size_t k = n - 1; k-- > 0;) {
    const Block G = S[k].solve(E[k]);
    const Block marginal = S[k].solve(I) + G * next * G.transpose();
    out.states[k] = marginal;
    next = marginal;
    if (m > 0) {
      const Rows later = X.middleRows(size * (k + 1), size);
      X.middleRows(size * k, size) = S[k].solve(Rows(Y.middleRows(size * k, size))) - G * later;
    }
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

}  // namespace

ChainMarginals chainMarginals(ceres::Problem& problem, const std::vector<double*>& states, const std::vector<double*>& globals, int threads,
                              int size) {
  if (states.empty()) return {};
  if (size == residuals::kState) return chainMarginalsOf<residuals::kState>(problem, states, globals, threads, size);
  return chainMarginalsOf<Eigen::Dynamic>(problem, states, globals, threads, size);
}

}  // namespace coloc::smoother
