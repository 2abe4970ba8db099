#include "scan_pool.hpp"

namespace coloc::twin {

ScanPool::ScanPool(std::size_t max_bytes) : max_bytes_(max_bytes) {}

ScanPool& ScanPool::shared() {
  static ScanPool* pool = new ScanPool(std::size_t{512} << 20);  // never destroyed: scans may be let go at exit
  return *pool;
}

std::size_t ScanPool::filledBytes(const ndt::PointCloud& c) { return c.points.size() * sizeof(Eigen::Vector3f) + c.times.size() * sizeof(float); }

std::size_t ScanPool::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

ScanPool::Spare ScanPool::take(std::size_t points) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // The best fit: a smaller one would be reallocated (fresh memory all the same), a larger one is
    // better kept for a larger scan.
    std::size_t best = spare_.size();
    for (std::size_t i = 0; i < spare_.size(); ++i) {
      const ndt::PointCloud& c = *spare_[i].cloud;
      if (c.points.capacity() >= points && c.times.capacity() >= points &&
          (best == spare_.size() || c.points.capacity() < spare_[best].cloud->points.capacity()))
        best = i;
    }
    if (best < spare_.size()) {
      Spare taken = std::move(spare_[best]);
      spare_[best] = std::move(spare_.back());
      spare_.pop_back();
      bytes_ -= taken.touched;
      taken.cloud->points.clear();
      taken.cloud->times.clear();
      return taken;
    }
  }
  // Room to spare: a drive's scans differ in size by a few percent to a third along the road, and
  // a scan given back is then large enough for most of the next drive's. The room a scan does not
  // fill costs address space only.
  Spare fresh{std::make_unique<ndt::PointCloud>(), 0};
  fresh.cloud->points.reserve(points + points / 4);
  fresh.cloud->times.reserve(points + points / 4);
  return fresh;
}

void ScanPool::give(ndt::PointCloud* cloud, std::size_t touched) {
  Spare spare{std::unique_ptr<ndt::PointCloud>(cloud), touched};
  std::lock_guard<std::mutex> lock(mutex_);
  if (bytes_ + touched > max_bytes_) return;  // freed
  bytes_ += touched;
  spare_.push_back(std::move(spare));
}

}  // namespace coloc::twin
