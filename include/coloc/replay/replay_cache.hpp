#pragma once
// What replays of one log share when they run side by side with different configurations (the
// experiment replays each simulated drive about twenty times): the log read once, its scans decoded
// once, the map's tile index read once, NDT targets built once per set of tiles, and NDT's outcome for a
// scan computed once per question asked of it. Everything shared is immutable once made, so a replay
// with the cache gives the same bytes as one without.
//
// Thread-safe. Memory: a log is held whole (its messages and decoded scans) while the cache lives.
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/io/bag_message.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/ndt/alignment_memo.hpp"
#include "coloc/ndt/point_cloud.hpp"
#include "coloc/ndt/target_cache.hpp"
#include "coloc/ndt/tile_map.hpp"

namespace coloc::replay {

/// A log read whole into memory.
class RecordedLog {
 public:
  /// Throws coloc::Error as io::BagReader does for a log it cannot read.
  explicit RecordedLog(const std::string& path);
  struct Scan {
    Stamp stamp = 0;
    std::shared_ptr<const ndt::PointCloud> cloud;
    std::string frame_id;  ///< the message's header.frame_id (empty for a scan given decoded)
  };
  /// A log made in memory (a simulated drive): `messages` in the order they were written, put in the
  /// order a rosbag2 reader gives them (by log time, then as written) and numbered; each topic's
  /// message_count counted. Throws coloc::Error for a message on a topic not in `topics`.
  /// `decoded` (empty, or one per message as written): a point cloud message given already decoded,
  /// as scan() would decode it; its bytes may then be left empty (a drive made to be replayed at once
  /// need not be serialised for it).
  RecordedLog(std::vector<io::TopicInfo> topics, std::vector<io::BagMessage> messages, std::vector<Scan> decoded = {});
  ~RecordedLog();

  const std::vector<io::TopicInfo>& topics() const { return topics_; }
  const std::vector<io::BagMessage>& messages() const { return messages_; }

  /// Message i decoded as a point cloud (PointCloud2 as `kind`), on its first request only. Throws
  /// coloc::Error, every time it is asked, for a message that does not decode.
  Scan scan(std::size_t i, io::MessageKind kind) const;

 private:
  struct Slot;
  std::vector<io::TopicInfo> topics_;
  std::vector<io::BagMessage> messages_;
  std::unique_ptr<Slot[]> slots_;
};

class ReplayCache {
 public:
  /// `targets`: NDT targets shared beyond this cache (drives on one site); none: a cache of its own.
  explicit ReplayCache(std::shared_ptr<ndt::TargetCache> targets = nullptr);

  /// The log at `path`, read on its first request (a concurrent request waits for that read), or the
  /// one added under that name.
  std::shared_ptr<const RecordedLog> log(const std::string& path);
  /// Replays of `name` use `log` (one made in memory, never written) instead of reading a file.
  void add(const std::string& name, std::shared_ptr<const RecordedLog> log);
  /// The map at `path` (ndt::TileMap::open), indexed on its first request.
  ndt::TileMap map(const std::string& path, double tile_size);
  const std::shared_ptr<ndt::TargetCache>& targets() const { return targets_; }
  /// NDT's outcomes per scan, shared by the replays: those that differ only in their RSU fixes match
  /// each scan before the first fix once (ndt/alignment_memo.hpp).
  const std::shared_ptr<ndt::AlignmentMemo>& alignments() const { return alignments_; }

 private:
  std::mutex mutex_;
  std::vector<std::pair<std::string, std::shared_ptr<const RecordedLog>>> logs_;
  std::vector<std::pair<std::string, std::shared_ptr<const ndt::TileMap>>> maps_;
  std::shared_ptr<ndt::TargetCache> targets_;
  std::shared_ptr<ndt::AlignmentMemo> alignments_;
};

}  // namespace coloc::replay
