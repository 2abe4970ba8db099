#include "scan_pool.hpp"

namespace coloc::twin {

namespace {

std::size_t roomOf(const ndt::PointCloud& c) {
  return c.points.capacity() * sizeof(Eigen::Vector3f) + c.times.capacity() * sizeof(float);
}

}  // namespace

ScanPool::ScanPool(std::size_t max_bytes) : max_bytes_(max_bytes) {}

ScanPool& ScanPool::shared() {
  static ScanPool* pool = new ScanPool(std::size_t{512} << 20);  // never destroyed: scans may be let go at exit
  return *pool;
}

std::size_t ScanPool::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

std::unique_ptr<ndt::PointCloud> ScanPool::take(std::size_t points) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // The best fit: a smaller one would be reallocated (fresh memory all the same), a larger one is
    // better kept for a larger scan.
    std::size_t best = spare_.size();
    for (std::size_t i = 0; i < spare_.size(); ++i) {
      const ndt::PointCloud& c = *spare_[i];
      if (c.points.capacity() >= points && c.times.capacity() >= points &&
          (best == spare_.size() || c.points.capacity() < spare_[best]->points.capacity()))
        best = i;
    }
    if (best < spare_.size()) {
      std::unique_ptr<ndt::PointCloud> cloud = std::move(spare_[best]);
      spare_[best] = std::move(spare_.back());
      spare_.pop_back();
      bytes_ -= roomOf(*cloud);
      cloud->points.clear();
      cloud->times.clear();
      return cloud;
    }
  }
  return std::make_unique<ndt::PointCloud>();
}

void ScanPool::give(ndt::PointCloud* cloud) {
  std::unique_ptr<ndt::PointCloud> owned(cloud);
  const std::size_t room = roomOf(*owned);
  std::lock_guard<std::mutex> lock(mutex_);
  if (bytes_ + room > max_bytes_) return;  // freed
  bytes_ += room;
  spare_.push_back(std::move(owned));
}

}  // namespace coloc::twin
