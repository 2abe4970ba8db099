#include "coloc/ndt/tile_map.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/ndt/pcd_file.hpp"

namespace coloc::ndt {

namespace {

TileInfo boundsOf(const PointCloud& cloud, std::string path) {
  TileInfo t;
  t.path = std::move(path);
  t.points = cloud.size();
  t.min = t.max = cloud.points.front().head<2>().cast<double>();
  for (const auto& p : cloud.points) {
    t.min = t.min.cwiseMin(p.head<2>().cast<double>());
    t.max = t.max.cwiseMax(p.head<2>().cast<double>());
  }
  return t;
}

}  // namespace

void TileMap::checkPath(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return;
  if (!fs::is_directory(path, ec)) throw Error(path + ": no such map file or folder");
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".pcd") return;
  throw Error(path + ": the map folder holds no .pcd tile");
}

TileMap TileMap::open(const std::string& path, double tile_size) {
  namespace fs = std::filesystem;
  std::error_code ec;
  checkPath(path);
  if (fs::is_regular_file(path, ec)) {
    TileMap map = fromCloud(loadPcd(path), tile_size);
    std::ostringstream id;
    id.precision(17);
    id << fs::absolute(path, ec).string() << '@' << tile_size;
    map.id_ = id.str();
    return map;
  }
  std::vector<std::string> files;  // a folder with at least one tile (checked)
  for (const auto& entry : fs::directory_iterator(path, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".pcd") files.push_back(entry.path().string());
  if (files.empty()) throw Error(path + ": the map folder holds no .pcd tile");  // emptied since the check
  std::sort(files.begin(), files.end());  // a stable order, whatever the file system lists
  TileMap map;
  map.id_ = fs::absolute(path, ec).string();
  for (const std::string& file : files) map.tiles_.push_back(boundsOf(loadPcd(file), file));
  return map;
}

TileMap TileMap::fromCloud(const PointCloud& cloud, double tile_size) {
  if (cloud.empty()) throw Error("map: the cloud is empty");
  if (!(tile_size > 0.0)) throw Error("map: tile size must be > 0");
  std::map<std::pair<long, long>, PointCloud> cells;  // ordered: tiles come out in a stable order
  for (const auto& p : cloud.points)
    cells[{static_cast<long>(std::floor(p.x() / tile_size)), static_cast<long>(std::floor(p.y() / tile_size))}].points.push_back(p);
  TileMap map;
  auto tiles = std::make_shared<std::vector<PointCloud>>();
  for (auto& [key, tile] : cells) {
    map.tiles_.push_back(boundsOf(tile, ""));
    tiles->push_back(std::move(tile));
  }
  map.in_memory_ = std::move(tiles);
  return map;
}

std::vector<std::size_t> TileMap::tilesWithin(const Eigen::Vector2d& center, double radius) const {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < tiles_.size(); ++i) {
    const Eigen::Vector2d nearest = center.cwiseMax(tiles_[i].min).cwiseMin(tiles_[i].max);
    if ((nearest - center).norm() <= radius) out.push_back(i);
  }
  return out;
}

PointCloud TileMap::load(std::size_t tile) const {
  if (tile >= tiles_.size()) throw Error("map: no tile " + std::to_string(tile));
  if (in_memory_) return (*in_memory_)[tile];
  return loadPcd(tiles_[tile].path);
}

DynamicMap::DynamicMap(TileMap map, const NdtConfig& ndt, const MapUpdateConfig& config, std::shared_ptr<TargetCache> targets)
    : map_(std::move(map)), ndt_(ndt), config_(config), targets_(std::move(targets)) {
  if (config_.background) thread_ = std::thread([this] { worker(); });
}

DynamicMap::~DynamicMap() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void DynamicMap::build(const Eigen::Vector2d& center) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::size_t> tiles = map_.tilesWithin(center, config_.radius);
  auto make = [&]() -> std::shared_ptr<const NdtTarget> {
    std::map<std::size_t, PointCloud> loaded;
    PointCloud cloud;
    for (std::size_t t : tiles) {
      auto kept = loaded_.find(t);
      PointCloud& tile = loaded[t] = kept != loaded_.end() ? std::move(kept->second) : map_.load(t);
      cloud.points.insert(cloud.points.end(), tile.points.begin(), tile.points.end());
    }
    loaded_ = std::move(loaded);  // tiles out of range are released here
    return cloud.empty() ? nullptr : std::make_shared<const NdtTarget>(cloud, ndt_);
  };
  std::shared_ptr<const NdtTarget> next;
  if (targets_ && !map_.id().empty() && !tiles.empty()) {
    next = targets_->get(map_.id(), tiles, ndt_, make);
    // While the cache serves, tiles read for earlier builds are released once out of range, as above.
    for (auto it = loaded_.begin(); it != loaded_.end();)
      it = std::binary_search(tiles.begin(), tiles.end(), it->first) ? std::next(it) : loaded_.erase(it);
  } else {
    next = make();
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard<std::mutex> lock(mutex_);
  target_ = std::move(next);  // alignments holding the old target keep it alive until they finish
  ++stats_.builds;
  stats_.tiles_in_target = tiles.size();
  stats_.points_in_target = target_ ? target_->pointCount() : 0;
  stats_.voxels_in_target = target_ ? target_->voxelCount() : 0;
  stats_.last_build_ms = ms;
}

void DynamicMap::worker() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || pending_; });
    if (stopping_) return;
    const Eigen::Vector2d center = pending_center_;
    pending_ = false;
    busy_ = true;
    lock.unlock();
    build(center);
    lock.lock();
    busy_ = false;
    if (!pending_) idle_.notify_all();
  }
}

void DynamicMap::update(const Eigen::Vector2d& position) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool first = !has_center_;
  if (!first && (position - center_).norm() < config_.update_distance) return;
  has_center_ = true;
  center_ = position;
  if (first || !config_.background) {
    lock.unlock();
    build(position);  // nothing to align against yet (or inline by choice): build now
    return;
  }
  pending_ = true;  // a newer request replaces one not yet started
  pending_center_ = position;
  wake_.notify_one();
}

std::shared_ptr<const NdtTarget> DynamicMap::target() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return target_;
}

void DynamicMap::waitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return !pending_ && !busy_; });
}

DynamicMapStats DynamicMap::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace coloc::ndt
