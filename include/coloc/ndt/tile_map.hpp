#pragma once
// A point-cloud map as tiles, and the NDT target built from the tiles around the vehicle.
//
// City maps do not fit in one NDT target. As Autoware's ndt_scan_matcher does, coloc keeps only the
// tiles within a radius of the vehicle (20 m tiles, 150 m radius, rebuilt every 20 m of travel), so the
// memory in use depends on the radius, not on the size of the map. The next target is built in the
// background while alignment goes on against the current one, then swapped in.
#include <Eigen/Core>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "coloc/ndt/ndt_config.hpp"
#include "coloc/ndt/ndt_target.hpp"
#include "coloc/ndt/point_cloud.hpp"
#include "coloc/ndt/target_cache.hpp"

namespace coloc::ndt {

struct TileInfo {
  std::string path;  ///< empty for tiles sliced from one cloud in memory
  Eigen::Vector2d min = Eigen::Vector2d::Zero(), max = Eigen::Vector2d::Zero();  ///< x-y bounds of its points
  std::size_t points = 0;
};

class TileMap {
 public:
  /// A folder: every *.pcd in it is a tile, indexed by reading each once (one tile in memory at a time).
  /// A file: one cloud, sliced into tile_size squares kept in memory. Throws coloc::Error naming the
  /// path for a missing, empty or unreadable map.
  static TileMap open(const std::string& path, double tile_size = 20.0);
  /// What open() checks before reading any tile: the path is a file, or a folder with a *.pcd in it.
  /// Throws coloc::Error naming the path otherwise.
  static void checkPath(const std::string& path);
  static TileMap fromCloud(const PointCloud& cloud, double tile_size);

  const std::vector<TileInfo>& tiles() const { return tiles_; }
  /// Tiles whose bounds come within `radius` of `center` (x-y).
  std::vector<std::size_t> tilesWithin(const Eigen::Vector2d& center, double radius) const;
  PointCloud load(std::size_t tile) const;
  /// Names the map for a TargetCache: its path and tile size; empty for a map made from a cloud in
  /// memory, whose targets are not shared.
  const std::string& id() const { return id_; }

 private:
  std::string id_;
  std::vector<TileInfo> tiles_;
  /// For sliced single-file maps; shared, so that copies of a map cost no copy of its points.
  std::shared_ptr<const std::vector<PointCloud>> in_memory_;
};

struct MapUpdateConfig {
  double radius = 150.0;          ///< m; tiles within this of the vehicle make the target
  double update_distance = 20.0;  ///< m of travel before the target is rebuilt
  bool background = true;         ///< build the next target on a worker thread (off: build inline, deterministic)
};

struct DynamicMapStats {
  std::size_t builds = 0;
  std::size_t tiles_in_target = 0;
  std::size_t points_in_target = 0;
  std::size_t voxels_in_target = 0;
  double last_build_ms = 0.0;
};

class DynamicMap {
 public:
  /// With `targets`, a target is taken from (or put into) the cache instead of always being built.
  DynamicMap(TileMap map, const NdtConfig& ndt, const MapUpdateConfig& config, std::shared_ptr<TargetCache> targets = nullptr);
  ~DynamicMap();
  DynamicMap(const DynamicMap&) = delete;
  DynamicMap& operator=(const DynamicMap&) = delete;

  /// Tells the map where the vehicle is. The first call builds the target before returning; later
  /// ones start a rebuild once the vehicle is update_distance from the last build's centre.
  void update(const Eigen::Vector2d& position);
  /// The target to align against now; null before the first update or if no tile is in range.
  std::shared_ptr<const NdtTarget> target() const;
  /// Waits for a background build to finish (tests, shutdown).
  void waitIdle();
  DynamicMapStats stats() const;
  const TileMap& map() const { return map_; }

 private:
  void build(const Eigen::Vector2d& center);
  void worker();

  TileMap map_;
  NdtConfig ndt_;
  MapUpdateConfig config_;
  std::shared_ptr<TargetCache> targets_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::shared_ptr<const NdtTarget> target_;
  DynamicMapStats stats_;
  /// Tiles of the last build, kept so that the next build reads only the tiles new to it. Touched by
  /// build() alone, which never runs twice at once.
  std::map<std::size_t, PointCloud> loaded_;
  bool has_center_ = false;
  Eigen::Vector2d center_ = Eigen::Vector2d::Zero();  ///< of the last build requested
  bool pending_ = false, busy_ = false, stopping_ = false;
  Eigen::Vector2d pending_center_ = Eigen::Vector2d::Zero();
  std::thread thread_;
};

}  // namespace coloc::ndt
