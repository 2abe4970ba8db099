#pragma once
// Whether any of a fixed set of points lies within a distance of a query point: the perception's test
// of a return against the reference (background) frame. The points are binned in cells of twice the
// distance, so a query's reach overlaps at most two cells along each axis. The squared distance is
// taken in float, summed x, y, z in that order, as a k-d tree of float points takes it: the answer is
// the exact nearest neighbour's against the same bound, without the tree's descent.
#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

namespace coloc::roadside {

class NearPoints {
 public:
  /// Points with a NaN or infinite coordinate are left out. Throws coloc::Error unless `distance` is
  /// finite and > 0.
  NearPoints(const std::vector<Eigen::Vector3f>& points, double distance);
  ~NearPoints();
  NearPoints(NearPoints&&) noexcept;
  NearPoints& operator=(NearPoints&&) noexcept;

  /// True if a point lies within the distance of `query` (its squared distance in float at most the
  /// distance squared); false for a query with a NaN or infinite coordinate.
  bool anyWithin(const Eigen::Vector3f& query) const;

  std::size_t size() const;  ///< the points kept

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::roadside
