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

// Gathers the voxels whose means lie within resolution + margin of xt, in the order a 27-cell search
// from any cell visits them (lexicographic in cell coordinates: x, then y, then z). Returns their
// count, or NeighbourCache's overflow mark.
template <int kMax>
std::uint8_t gatherNeighbours(const VoxelLookup& voxels, double resolution, double margin, const Vector3d& xt, std::uint32_t* out) {
  const double reach = resolution + margin, reach_sq = reach * reach;
  const Vector3d scaled = xt / resolution;
  const Eigen::Vector3i base = scaled.array().floor().cast<int>();
  const Vector3d frac = scaled - base.cast<double>();
  // Distance along one axis from the point to the cell at offset d (cells are half-open boxes; a mean
  // lies in its cell's box). The reach is under two resolutions, so offsets of +-2 cover it.
  auto axis = [&](int d, double u) { return d == 0 ? 0.0 : (d > 0 ? (d - u) : (u + (-d - 1))) * resolution; };
  const double slack = 1e-6 * resolution;  // a mean rounded to just outside its box
  int n = 0;
  for (int dx = -2; dx <= 2; ++dx) {
    const double ax = std::max(0.0, axis(dx, frac.x()) - slack);
    if (ax * ax > reach_sq) continue;
    for (int dy = -2; dy <= 2; ++dy) {
      const double ay = std::max(0.0, axis(dy, frac.y()) - slack);
      if (ax * ax + ay * ay > reach_sq) continue;
      for (int dz = -2; dz <= 2; ++dz) {
        const double az = std::max(0.0, axis(dz, frac.z()) - slack);
        if (ax * ax + ay * ay + az * az > reach_sq) continue;
        const std::int64_t v = voxels.indexOf(base + Eigen::Vector3i(dx, dy, dz));
        if (v < 0 || (xt - voxels.voxels()[static_cast<std::size_t>(v)].mean).squaredNorm() > reach_sq) continue;
        if (n == kMax) return NeighbourCache::kOverflow;
        out[n++] = static_cast<std::uint32_t>(v);
      }
    }
  }
  return static_cast<std::uint8_t>(n);
}

}  // namespace

NeighbourCache::NeighbourCache(std::size_t points, double resolution, double margin)
    : resolution_(resolution), margin_(margin), at_(points), count_(points, kUnset), candidates_(points * kMaxCandidates) {}

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
  if (cache && (cache->at_.size() != source.size() || cache->resolution_ != resolution)) cache = nullptr;  // not this alignment's
  const bool cached_search = cache && options.neighborhood == Neighborhood::kRadius;
  const double margin_sq = cache ? cache->margin_ * cache->margin_ : 0.0;
  // Calls visit(voxel) for every voxel of the radius neighbourhood's 27 cells, from the cache when
  // the point is still near where its list was gathered.
  auto forRadius = [&](long idx, const Vector3d& xt, const Eigen::Vector3i& cell, auto&& visit) {
    if (cache) {
      const std::size_t i = static_cast<std::size_t>(idx);
      std::uint8_t& count = cache->count_[i];
      std::uint32_t* list = &cache->candidates_[i * NeighbourCache::kMaxCandidates];
      if (count == NeighbourCache::kUnset || (count != NeighbourCache::kOverflow && (xt - cache->at_[i]).squaredNorm() > margin_sq)) {
        count = gatherNeighbours<NeighbourCache::kMaxCandidates>(voxels, resolution, cache->margin_, xt, list);
        cache->at_[i] = xt;
      }
      if (count != NeighbourCache::kOverflow) {
        for (int c = 0; c < count; ++c) visit(voxels.voxels()[list[c]]);
        return;
      }
    }
    for (const Eigen::Vector3i& offset : offsets(Neighborhood::kRadius))
      if (const Voxel* v = voxels.find(cell + offset)) visit(*v);
  };

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
      // The derivatives factor per point: with g = Cq, f = d1 d2 e and J = [I | Jang] the same for every
      // voxel of the point, the gradient is J'b and the Hessian J'AJ + sum_ij b.d2x_ij, where
      // b = sum f g and A = sum f (C - d2 g g') run over the voxels. So a voxel costs a 3x3 update and
      // the 6x6 work is done once per point, on the upper triangle.
      double point_score = 0.0;
      Vector3d b = Vector3d::Zero();
      Matrix3d A = Matrix3d::Zero();
      bool any = false;
      auto visit = [&](const Voxel& v) {
        const Vector3d q = xt - v.mean;
        if (options.neighborhood == Neighborhood::kRadius && q.squaredNorm() > radius_sq) return;
        const Vector3d Cq = v.inverse_covariance * q;
        const double e = std::exp(-0.5 * k.d2 * q.dot(Cq));
        point_score += -k.d1 * e;
        any = true;
        if (!options.gradient) return;
        const double f = k.d1 * k.d2 * e;
        b += f * Cq;
        if (options.hessian) A.noalias() += f * (v.inverse_covariance - k.d2 * Cq * Cq.transpose());
      };
      if (cached_search) {
        forRadius(idx, xt, cell, visit);
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
      if (options.nvtl) {
        double best = 0.0;
        bool found = false;
        forRadius(idx, xt, cell, [&](const Voxel& v) {
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

}  // namespace coloc::ndt
