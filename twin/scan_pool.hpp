#pragma once
// The memory of the scans of drives already replayed, handed to the next drives to fill. A drive kept
// in memory holds about 250 decoded scans of 640 KB; fresh memory costs a page fault and the kernel's
// zeroing every 4 KB, which was half of the experiment's page faults. A scan given back by its last
// holder goes to the pool while the pool holds less than its bound, else back to the system.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "coloc/ndt/point_cloud.hpp"

namespace coloc::twin {

class ScanPool {
 public:
  /// A pool must outlive the scans it hands out (their last holder gives them back to it).
  explicit ScanPool(std::size_t max_bytes);
  ScanPool(const ScanPool&) = delete;
  ScanPool& operator=(const ScanPool&) = delete;

  /// The process's pool (512 MB at most), which outlives every scan it hands out.
  static ScanPool& shared();

  /// An empty cloud with the room of a scan given back, the smallest with room for `points` points
  /// and times (else fresh memory, with room for a quarter more); `fill` fills it, and it is given
  /// back to this pool when its last holder lets go.
  template <typename Fill>
  std::shared_ptr<const ndt::PointCloud> make(std::size_t points, Fill&& fill) {
    Spare taken = take(points);
    fill(*taken.cloud);
    const std::size_t touched = std::max(taken.touched, filledBytes(*taken.cloud));
    return std::shared_ptr<const ndt::PointCloud>(taken.cloud.release(),
                                                  [this, touched](const ndt::PointCloud* c) { give(const_cast<ndt::PointCloud*>(c), touched); });
  }

  /// Bytes the scans the pool holds now have filled: the memory they hold (room never filled is
  /// never given memory by the system).
  std::size_t bytes() const;

 private:
  struct Spare {
    std::unique_ptr<ndt::PointCloud> cloud;
    std::size_t touched = 0;  ///< the most its points and times ever filled, bytes
  };
  static std::size_t filledBytes(const ndt::PointCloud& c);
  Spare take(std::size_t points);
  void give(ndt::PointCloud* cloud, std::size_t touched);

  const std::size_t max_bytes_;
  mutable std::mutex mutex_;
  std::vector<Spare> spare_;
  std::size_t bytes_ = 0;
};

}  // namespace coloc::twin
