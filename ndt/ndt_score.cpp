#include "ndt_score.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>

namespace coloc::ndt {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// R = Rx(a) Ry(b) Rz(c), its three first and six second partial derivatives.
struct RotationDerivatives {
  Matrix3d R;
  std::array<Matrix3d, 3> first;   // d/da, d/db, d/dc
  std::array<Matrix3d, 6> second;  // aa, ab, ac, bb, bc, cc
};

RotationDerivatives rotationDerivatives(double a, double b, double c) {
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b), cc = std::cos(c), sc = std::sin(c);
  Matrix3d X, X1, X2, Y, Y1, Y2, Z, Z1, Z2;
  X << 1, 0, 0, 0, ca, -sa, 0, sa, ca;
  X1 << 0, 0, 0, 0, -sa, -ca, 0, ca, -sa;
  X2 << 0, 0, 0, 0, -ca, sa, 0, -sa, -ca;
  Y << cb, 0, sb, 0, 1, 0, -sb, 0, cb;
  Y1 << -sb, 0, cb, 0, 0, 0, -cb, 0, -sb;
  Y2 << -cb, 0, -sb, 0, 0, 0, sb, 0, -cb;
  Z << cc, -sc, 0, sc, cc, 0, 0, 0, 1;
  Z1 << -sc, -cc, 0, cc, -sc, 0, 0, 0, 0;
  Z2 << -cc, sc, 0, -sc, -cc, 0, 0, 0, 0;
  RotationDerivatives d;
  d.R = X * Y * Z;
  d.first = {X1 * Y * Z, X * Y1 * Z, X * Y * Z1};
  d.second = {X2 * Y * Z, X1 * Y1 * Z, X1 * Y * Z1, X * Y2 * Z, X * Y1 * Z1, X * Y * Z2};
  return d;
}

// Index of the second derivative of the rotation for angles i, j (0..2).
constexpr int kSecondIndex[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};

const std::vector<Eigen::Vector3i>& offsets(Neighborhood n) {
  static const std::vector<Eigen::Vector3i> single = {Eigen::Vector3i(0, 0, 0)};
  static const std::vector<Eigen::Vector3i> face7 = {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                                      {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const std::vector<Eigen::Vector3i> cube27 = [] {
    std::vector<Eigen::Vector3i> v;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) v.emplace_back(x, y, z);
    return v;
  }();
  switch (n) {
    case Neighborhood::kSingle: return single;
    case Neighborhood::kFace7: return face7;
    case Neighborhood::kRadius: return cube27;
  }
  return cube27;
}

}  // namespace

ScoreConstants scoreConstants(double resolution, double outlier_ratio) {
  // The mixture of a Gaussian and a uniform outlier density, approximated by one scaled Gaussian.
  const double c1 = 10.0 * (1.0 - outlier_ratio);
  const double c2 = outlier_ratio / (resolution * resolution * resolution);
  const double d3 = -std::log(c2);
  ScoreConstants k;
  k.d1 = -std::log(c1 + c2) - d3;
  k.d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / k.d1);
  return k;
}

Eigen::Matrix4d poseToMatrix(const Vector6d& p) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = (Eigen::AngleAxisd(p[3], Vector3d::UnitX()) * Eigen::AngleAxisd(p[4], Vector3d::UnitY()) *
                             Eigen::AngleAxisd(p[5], Vector3d::UnitZ()))
                                .toRotationMatrix();
  T.topRightCorner<3, 1>() = p.head<3>();
  return T;
}

Vector6d matrixToPose(const Eigen::Matrix4d& T) {
  Vector6d p;
  p.head<3>() = T.topRightCorner<3, 1>();
  p.tail<3>() = T.topLeftCorner<3, 3>().eulerAngles(0, 1, 2);
  return p;
}

ScoreEvaluation evaluateScore(const VoxelLookup& voxels, double resolution, const ScoreConstants& k,
                              const std::vector<Eigen::Vector3f>& source, const Vector6d& pose, const ScoreOptions& options) {
  const RotationDerivatives rot = rotationDerivatives(pose[3], pose[4], pose[5]);
  const Vector3d t = pose.head<3>();
  const double inverse_resolution = 1.0 / resolution;
  const double radius_sq = resolution * resolution;
  const std::vector<Eigen::Vector3i>& search = offsets(options.neighborhood);
  const std::vector<Eigen::Vector3i>& nvtl_search = offsets(Neighborhood::kRadius);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const long n = static_cast<long>(source.size());

  // One partial sum per thread, added in thread order afterwards: with a static schedule the result is
  // the same bits on every run.
  std::vector<ScoreEvaluation> partial(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads)
  {
    ScoreEvaluation& local = partial[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static) nowait
    for (long idx = 0; idx < n; ++idx) {
      const Vector3d x = source[static_cast<std::size_t>(idx)].cast<double>();
      const Vector3d xt = rot.R * x + t;
      const Eigen::Vector3i cell = (xt * inverse_resolution).array().floor().cast<int>();
      // Per-point derivative terms, computed on the first voxel in reach.
      bool have_terms = false;
      Matrix3d Jang = Matrix3d::Zero();  // columns: dR/da x, dR/db x, dR/dc x
      std::array<Vector3d, 6> second_terms;  // d2R x for the six angle pairs
      second_terms.fill(Vector3d::Zero());
      double best = 0.0;
      bool found = false;
      for (const Eigen::Vector3i& offset : search) {
        const Voxel* v = voxels.find(cell + offset);
        if (!v) continue;
        const Vector3d q = xt - v->mean;
        if (options.neighborhood == Neighborhood::kRadius && q.squaredNorm() > radius_sq) continue;
        const Vector3d Cq = v->inverse_covariance * q;
        const double e = std::exp(-0.5 * k.d2 * q.dot(Cq));
        const double s = -k.d1 * e;
        local.score += s;
        if (!options.gradient) continue;
        if (!have_terms) {
          for (int i = 0; i < 3; ++i) Jang.col(i) = rot.first[i] * x;
          if (options.hessian)
            for (int i = 0; i < 6; ++i) second_terms[i] = rot.second[i] * x;
          have_terms = true;
        }
        // Gradient: f (Cq . J_i), J = [I | Jang].
        const double f = k.d1 * k.d2 * e;
        Eigen::Matrix<double, 6, 1> CqJ;
        CqJ.head<3>() = Cq;
        CqJ.tail<3>() = Jang.transpose() * Cq;
        local.gradient += f * CqJ;
        if (!options.hessian) continue;
        // Hessian: f ( -d2 (Cq.J_i)(Cq.J_j) + J_j' C J_i + Cq . d2x/dp_i dp_j ).
        Eigen::Matrix<double, 3, 6> CJ;
        CJ.leftCols<3>() = v->inverse_covariance;
        CJ.rightCols<3>() = v->inverse_covariance * Jang;
        Eigen::Matrix<double, 6, 6> JCJ;
        JCJ.topLeftCorner<3, 6>() = CJ;  // J' for the translation rows is the identity
        JCJ.bottomRows<3>() = Jang.transpose() * CJ;
        Matrix6d h = -k.d2 * CqJ * CqJ.transpose() + JCJ;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) h(3 + i, 3 + j) += Cq.dot(second_terms[kSecondIndex[i][j]]);
        local.hessian += f * h;
      }
      if (options.nvtl) {
        for (const Eigen::Vector3i& offset : nvtl_search) {
          const Voxel* v = voxels.find(cell + offset);
          if (!v) continue;
          const Vector3d q = xt - v->mean;
          if (q.squaredNorm() > radius_sq) continue;
          const double s = -k.d1 * std::exp(-0.5 * k.d2 * q.dot(v->inverse_covariance * q));
          if (!found || s > best) best = s;
          found = true;
        }
        if (found) {
          local.nvtl_sum += best;
          ++local.nvtl_points;
        }
      }
    }
  }
  ScoreEvaluation total;
  for (const ScoreEvaluation& local : partial) {
    total.score += local.score;
    total.gradient += local.gradient;
    total.hessian += local.hessian;
    total.nvtl_sum += local.nvtl_sum;
    total.nvtl_points += local.nvtl_points;
  }
  // Summation order across threads varies; symmetrising keeps the Hessian exactly symmetric.
  total.hessian = 0.5 * (total.hessian + total.hessian.transpose()).eval();
  return total;
}

}  // namespace coloc::ndt
