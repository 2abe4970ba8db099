#include "ndt_score.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

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

NeighbourCache::NeighbourCache(std::size_t points, const CellNeighbours& cells) : cells_(&cells), cell_(points, kNoCell), list_(points) {}

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
                              const std::vector<Eigen::Vector3f>& source, const Vector6d& pose, const ScoreOptions& options,
                              NeighbourCache* cache) {
  const RotationDerivatives rot = rotationDerivatives(pose[3], pose[4], pose[5]);
  const Vector3d t = pose.head<3>();
  const double inverse_resolution = 1.0 / resolution;
  const double radius_sq = resolution * resolution;
  const std::vector<Eigen::Vector3i>& search = offsets(options.neighborhood);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const long n = static_cast<long>(source.size());
  if (cache && (cache->cell_.size() != source.size() || cache->cells_->resolution() != resolution)) cache = nullptr;  // not this alignment's
  const bool cached_search = cache && options.neighborhood == Neighborhood::kRadius;
  // Calls visit(voxel) for every voxel of the radius neighbourhood's 27 cells that can be within reach,
  // from the cache when there is one. `scratch`: the thread's, backing a list the target does not keep.
  auto forRadius = [&](long idx, const Eigen::Vector3i& cell, std::vector<std::uint32_t>& scratch, auto&& visit) {
    if (!cache) {
      for (const Eigen::Vector3i& offset : offsets(Neighborhood::kRadius))
        if (const Voxel* v = voxels.find(cell + offset)) visit(*v);
      return;
    }
    const std::size_t i = static_cast<std::size_t>(idx);
    const std::uint64_t key = VoxelLookup::pack(cell);
    if (cache->cell_[i] != key) {
      const CellNeighbours::List list = cache->cells_->get(cell, key, scratch);
      cache->cell_[i] = list.kept ? key : NeighbourCache::kNoCell;
      cache->list_[i] = list;
    }
    const CellNeighbours::List& list = cache->list_[i];
    for (std::uint32_t k = 0; k < list.size; ++k) visit(voxels.voxels()[list.voxels[k]]);
  };

  // One partial sum per thread, added in thread order afterwards: with a static schedule the result is
  // the same bits on every run.
  std::vector<ScoreEvaluation> partial(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads)
  {
    const int thread = omp_get_thread_num();
    ScoreEvaluation& local = partial[static_cast<std::size_t>(thread)];
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(static) nowait
    for (long idx = 0; idx < n; ++idx) {
      const Vector3d x = source[static_cast<std::size_t>(idx)].cast<double>();
      const Vector3d xt = rot.R * x + t;
      const Eigen::Vector3i cell = (xt * inverse_resolution).array().floor().cast<int>();
      // The derivatives factor per point: with g = Cq, f = d1 d2 e and J = [I | Jang] the same for every
      // voxel of the point, the gradient is J'b and the Hessian J'AJ + sum_ij b.d2x_ij, where
      // b = sum f g and A = sum f (C - d2 g g') run over the voxels. So a voxel costs a 3x3 update and
      // the 6x6 work is done once per point, on the upper triangle.
      double point_score = 0.0;
      Vector3d b = Vector3d::Zero();
      Matrix3d A = Matrix3d::Zero();
      bool any = false;
      // Over the radius neighbourhood the score visits exactly NVTL's voxels: NVTL is taken in the same
      // pass, as the largest exponent (the score of a voxel rises with it, so exp of the largest is the
      // same bits as the largest of the exps).
      const bool nvtl_here = options.nvtl && options.neighborhood == Neighborhood::kRadius;
      double best_exponent = 0.0;
      // The best voxel's exp, when the score computed it: NVTL then costs no exp of its own.
      double best_e = 0.0;
      bool best_known = false;
      auto visit = [&](const Voxel& v) {
        const Vector3d q = xt - v.mean;
        if (options.neighborhood == Neighborhood::kRadius && q.squaredNorm() > radius_sq) return;
        const Vector3d Cq = v.inverse_covariance * q;
        const double exponent = -0.5 * k.d2 * q.dot(Cq);
        const bool best = nvtl_here && (!any || exponent > best_exponent);
        if (best) best_exponent = exponent, best_known = false;
        any = true;
        // Beyond e^-40 (4e-18 of a voxel's full weight) a term cannot change a double sum of terms up
        // to 1: skipping it saves the exp and the derivatives of the many voxels a point barely touches.
        if (exponent < -40.0) return;
        const double e = std::exp(exponent);
        if (best) best_e = e, best_known = true;
        point_score += -k.d1 * e;
        if (!options.gradient) return;
        const double f = k.d1 * k.d2 * e;
        b += f * Cq;
        if (options.hessian) A.noalias() += f * (v.inverse_covariance - k.d2 * Cq * Cq.transpose());
      };
      if (cached_search) {
        forRadius(idx, cell, scratch, visit);
      } else {
        for (const Eigen::Vector3i& offset : search)
          if (const Voxel* v = voxels.find(cell + offset)) visit(*v);
      }
      local.score += point_score;
      if (any && options.gradient) {
        Matrix3d Jang;  // columns: dR/da x, dR/db x, dR/dc x
        for (int i = 0; i < 3; ++i) Jang.col(i) = rot.first[i] * x;
        local.gradient.head<3>() += b;
        local.gradient.tail<3>() += Jang.transpose() * b;
        if (options.hessian) {
          const Matrix3d AJ = A * Jang;
          local.hessian.topLeftCorner<3, 3>() += A;
          local.hessian.topRightCorner<3, 3>() += AJ;
          Matrix3d angular = Jang.transpose() * AJ;
          for (int i = 0; i < 3; ++i)
            for (int j = i; j < 3; ++j) angular(i, j) += b.dot(rot.second[kSecondIndex[i][j]] * x);
          local.hessian.bottomRightCorner<3, 3>() += angular;
        }
      }
      if (nvtl_here) {
        if (any) {
          local.nvtl_sum += -k.d1 * (best_known ? best_e : std::exp(best_exponent));
          ++local.nvtl_points;
        }
      } else if (options.nvtl) {
        double best = 0.0;
        bool found = false;
        forRadius(idx, cell, scratch, [&](const Voxel& v) {
          const Vector3d q = xt - v.mean;
          if (q.squaredNorm() > radius_sq) return;
          const double s = -k.d1 * std::exp(-0.5 * k.d2 * q.dot(v.inverse_covariance * q));
          if (!found || s > best) best = s;
          found = true;
        });
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
  // Only the upper triangle was summed (the translation block A and the angular block's upper half).
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < i; ++j) total.hessian(i, j) = total.hessian(j, i);
  return total;
}

std::vector<double> nvtlAtTranslations(const VoxelLookup& voxels, double resolution, const ScoreConstants& k,
                                       const std::vector<Eigen::Vector3f>& source, const Vector6d& pose,
                                       const std::vector<Eigen::Vector3d>& translations, const CellNeighbours& target_cells,
                                       int threads_wanted, const NeighbourCache* cache) {
  const std::size_t m = translations.size();
  if (m == 0) return {};
  // The lists of a target built at another resolution do not describe this one's reach.
  std::unique_ptr<CellNeighbours> own;
  if (target_cells.resolution() != resolution) own = std::make_unique<CellNeighbours>(voxels, resolution);
  const CellNeighbours& cells = own ? *own : target_cells;
  if (cache && (cache->cell_.size() != source.size() || cache->cells_ != &cells)) cache = nullptr;  // not this alignment's
  const Eigen::Matrix3d R = poseToMatrix(pose).topLeftCorner<3, 3>();
  const Vector3d t = pose.head<3>();
  const double inverse_resolution = 1.0 / resolution;
  const double radius_sq = resolution * resolution;
  const int threads = threads_wanted > 0 ? threads_wanted : omp_get_max_threads();
  const long n = static_cast<long>(source.size());
  std::vector<std::vector<double>> sums(static_cast<std::size_t>(threads), std::vector<double>(m, 0.0));
  std::vector<std::vector<std::size_t>> counts(static_cast<std::size_t>(threads), std::vector<std::size_t>(m, 0));
#pragma omp parallel num_threads(threads)
  {
    const std::size_t thread = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<std::uint32_t> scratch;
    std::vector<Vector3d> shifted(m);
    std::vector<std::uint64_t> keys(m);
    std::vector<Eigen::Vector3i> cells_of(m);
    std::vector<double> best(m);
    std::vector<char> found(m), done(m);
    std::vector<std::size_t> group;
#pragma omp for schedule(static) nowait
    for (long idx = 0; idx < n; ++idx) {
      const Vector3d xt = R * source[static_cast<std::size_t>(idx)].cast<double>() + t;
      for (std::size_t j = 0; j < m; ++j) {
        shifted[j] = xt + translations[j];
        cells_of[j] = (shifted[j] * inverse_resolution).array().floor().cast<int>();
        keys[j] = VoxelLookup::pack(cells_of[j]);
        best[j] = 0.0, found[j] = 0, done[j] = 0;
      }
      for (std::size_t j = 0; j < m; ++j) {
        if (done[j]) continue;
        // Each shifted point looks at the voxels its own cell's list holds, as the score does: every
        // voxel within reach is in it, so the largest exponent is the one of the whole neighbourhood.
        // The shifts in the same cell walk its list together, each voxel read once for all of them (the
        // same sums per shift, in the same order): each list is looked up once per point.
        group.clear();
        for (std::size_t g = j; g < m; ++g)
          if (!done[g] && keys[g] == keys[j]) group.push_back(g), done[g] = 1;
        const std::uint64_t key = keys[j];
        CellNeighbours::List list;
        if (cache && cache->cell_[static_cast<std::size_t>(idx)] == key) {
          list = cache->list_[static_cast<std::size_t>(idx)];  // still in the cell the alignment last saw the point in
        } else {
          list = cells.get(cells_of[j], key, scratch);  // a list not kept (in `scratch`) is used here only
        }
        for (std::uint32_t i = 0; i < list.size; ++i) {
          const Voxel& v = voxels.voxels()[list.voxels[i]];
          for (const std::size_t g : group) {
            const Vector3d q = shifted[g] - v.mean;
            if (q.squaredNorm() > radius_sq) continue;
            const double exponent = -0.5 * k.d2 * q.dot(v.inverse_covariance * q);
            if (!found[g] || exponent > best[g]) best[g] = exponent;
            found[g] = 1;
          }
        }
      }
      for (std::size_t j = 0; j < m; ++j)
        if (found[j]) {
          sums[thread][j] += -k.d1 * std::exp(best[j]);
          ++counts[thread][j];
        }
    }
  }
  std::vector<double> nvtl(m, 0.0);
  for (std::size_t j = 0; j < m; ++j) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t th = 0; th < sums.size(); ++th) {
      sum += sums[th][j];
      count += counts[th][j];
    }
    nvtl[j] = count ? sum / static_cast<double>(count) : 0.0;
  }
  return nvtl;
}

}  // namespace coloc::ndt
