#pragma once
// What an RSU's LiDAR sees when nothing moves, learned from frames of a busy scene. A real intersection
// never shows an empty frame: cars pass, wait and park. Space is cut into voxels in the sensor frame
// (the LiDAR stands still), and each voxel's occupancy is the share of frames that returned a point
// in it. Walls, poles and the road return one in nearly every frame; a passing car in a few. Voxels
// occupied in at least `min_occupancy` of the frames are the background (the density-statistics
// filtering of roadside LiDAR work, over time rather than over one accumulated cloud). With a decay
// the learner forgets: a car parked for a while becomes background, and once it has left, the wall
// behind it comes back.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace coloc::roadside {

struct BackgroundConfig {
  double voxel = 0.1;          ///< m, the voxel's edge
  double min_occupancy = 0.2;  ///< share of frames a background voxel returns a point in
  /// Each frame, the weight of what came before is multiplied by 1 - decay: 0 counts every frame
  /// alike; 1/3000 forgets with a time constant of five minutes at 10 Hz.
  double decay = 0.0;
  double max_range = 100.0;  ///< m; farther points are not learned (nor needed by the perception)
};

class BackgroundLearner {
 public:
  explicit BackgroundLearner(BackgroundConfig config = {});
  ~BackgroundLearner();
  BackgroundLearner(BackgroundLearner&&) noexcept;
  BackgroundLearner& operator=(BackgroundLearner&&) noexcept;

  /// One frame, in the sensor frame. Non-finite points are skipped.
  void add(const std::vector<Eigen::Vector3f>& frame);
  /// Frames learned (their decayed weight, with a decay).
  double frames() const { return frames_ * scale_; }
  /// One point per background voxel, the mean of its returns, in the sensor frame; in the voxels'
  /// order (by index), so that what is built from it does not depend on how the voxels are stored.
  std::vector<Eigen::Vector3f> background() const;
  /// Voxels seen at all (background or not).
  std::size_t voxels() const;
  const BackgroundConfig& config() const { return config_; }

 private:
  // Weights are kept divided by the decay's product so far (`scale_`), so that a frame touches only
  // the voxels it hits; they are brought back to scale before that product underflows.
  struct Cells;  // the voxels seen, by index (a flat hash table: one lookup per return of every frame)
  BackgroundConfig config_;
  std::unique_ptr<Cells> cells_;
  double frames_ = 0.0;  ///< at scale
  std::uint64_t frame_index_ = 0;
  double scale_ = 1.0;
  void rescale();
};

}  // namespace coloc::roadside
