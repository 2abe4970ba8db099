#include "coloc/replay/replay_cache.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/pipeline/message_inputs.hpp"

namespace coloc::replay {

struct RecordedLog::Slot {
  std::once_flag once;
  Scan scan;
  std::string error;
};

RecordedLog::RecordedLog(const std::string& path) {
  io::BagReader bag = io::BagReader::open(path);
  topics_ = bag.topics();
  messages_.reserve(bag.messageCount());
  io::BagMessage message;
  while (bag.next(message)) messages_.push_back(std::move(message));
  slots_ = std::make_unique<Slot[]>(messages_.size());
}

RecordedLog::RecordedLog(std::vector<io::TopicInfo> topics, std::vector<io::BagMessage> messages, std::vector<Scan> decoded)
    : topics_(std::move(topics)) {
  if (!decoded.empty() && decoded.size() != messages.size())
    throw Error("recorded log: " + std::to_string(decoded.size()) + " decoded entries for " + std::to_string(messages.size()) + " messages");
  std::map<std::string, std::size_t> topic_at;
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    topic_at[topics_[i].name] = i;
    topics_[i].message_count = 0;
  }
  for (const io::BagMessage& m : messages) {
    const auto t = topic_at.find(m.topic);
    if (t == topic_at.end()) throw Error("recorded log: a message on topic " + m.topic + ", which the log does not list");
    ++topics_[t->second].message_count;
  }
  std::vector<std::size_t> order(messages.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return messages[a].log_time < messages[b].log_time; });
  messages_.reserve(messages.size());
  for (std::size_t i : order) messages_.push_back(std::move(messages[i]));
  for (std::size_t i = 0; i < messages_.size(); ++i) messages_[i].index = i;
  slots_ = std::make_unique<Slot[]>(messages_.size());
  for (std::size_t i = 0; i < order.size() && !decoded.empty(); ++i) {
    Scan& given = decoded[order[i]];
    if (!given.cloud) continue;
    Slot& slot = slots_[i];
    std::call_once(slot.once, [&] { slot.scan = std::move(given); });
  }
}

RecordedLog::~RecordedLog() = default;

RecordedLog::Scan RecordedLog::scan(std::size_t i, io::MessageKind kind) const {
  if (i >= messages_.size()) throw Error("recorded log: no message " + std::to_string(i));
  Slot& slot = slots_[i];
  std::call_once(slot.once, [&] {
    try {
      const io::RosMessage decoded = io::decodeMessage(kind, messages_[i].data);
      const io::PointCloud2& cloud = std::get<io::PointCloud2>(decoded);
      slot.scan.stamp = cloud.header.stamp;
      slot.scan.frame_id = cloud.header.frame_id;
      slot.scan.cloud = std::make_shared<const ndt::PointCloud>(pipeline::toPointCloud(cloud));
    } catch (const Error& e) {
      slot.error = e.what();
    } catch (const std::bad_variant_access&) {
      slot.error = "not a point cloud";
    }
  });
  if (!slot.error.empty()) throw Error(slot.error);
  return slot.scan;
}

ReplayCache::ReplayCache(std::shared_ptr<ndt::TargetCache> targets)
    : targets_(targets ? std::move(targets) : std::make_shared<ndt::TargetCache>()), alignments_(std::make_shared<ndt::AlignmentMemo>()) {}

std::shared_ptr<const RecordedLog> ReplayCache::log(const std::string& path) {
  // Held while reading: replays of one drive start together and all want the same log.
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [p, log] : logs_)
    if (p == path) return log;
  auto log = std::make_shared<const RecordedLog>(path);
  logs_.emplace_back(path, log);
  return log;
}

void ReplayCache::add(const std::string& name, std::shared_ptr<const RecordedLog> log) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [p, held] : logs_)
    if (p == name) {
      held = std::move(log);
      return;
    }
  logs_.emplace_back(name, std::move(log));
}

ndt::TileMap ReplayCache::map(const std::string& path, double tile_size) {
  std::ostringstream key;
  key.precision(17);
  key << path << '@' << tile_size;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [k, map] : maps_)
    if (k == key.str()) return *map;
  auto map = std::make_shared<const ndt::TileMap>(ndt::TileMap::open(path, tile_size));
  maps_.emplace_back(key.str(), map);
  return *map;
}

}  // namespace coloc::replay
