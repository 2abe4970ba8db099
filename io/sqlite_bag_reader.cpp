// rosbag2 sqlite3 storage reader. Handles the three database schemas rosbag2 has written: none
// (Foxy/Galactic; the oldest without topics.offered_qos_profiles), 3 (Humble: schema and metadata
// tables) and 4 (Iron+: message_definitions, topics.type_description_hash).
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "coloc/core/error.hpp"
#include "sqlite_database.hpp"
#include "storage_reader.hpp"

namespace coloc::io::detail {
namespace {

namespace fs = std::filesystem;

bool hasPendingWal(const std::string& path) {
  std::error_code ec;
  const auto size = fs::file_size(path + "-wal", ec);
  return !ec && size > 0;
}

// immutable=1 makes SQLite read the file as it is, without creating -wal/-shm files or taking locks:
// bags on read-only media and WAL-mode bags (rosbag2's "resilient" preset) open the same way. A
// non-empty -wal file means committed messages that only a writable open can see.
std::unique_ptr<SqliteDatabase> openReadOnly(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": the bag file does not exist");
  if (fs::is_directory(path, ec)) throw Error(path + ": is a directory, not a .db3 file");
  if (!hasPendingWal(path)) {
    return std::make_unique<SqliteDatabase>(sqliteFileUri(path) + "?immutable=1",
                                            SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, path);
  }
  try {
    auto db = std::make_unique<SqliteDatabase>(sqliteFileUri(path) + "?mode=ro", SQLITE_OPEN_READONLY | SQLITE_OPEN_URI,
                                               path);
    db->prepare("SELECT COUNT(*) FROM sqlite_master").step();
    return db;
  } catch (const Error& e) {
    throw Error(path + ": the database has uncommitted write-ahead log content (" + path +
                "-wal) that cannot be read without write access (" + e.what() +
                "); checkpoint it first, e.g. sqlite3 FILE 'PRAGMA wal_checkpoint'");
  }
}

class SqliteReader final : public StorageReader {
 public:
  explicit SqliteReader(const std::string& path);
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  bool next(BagMessage& message) override;

 private:
  void checkIsBag();
  void readTopics();
  void readMessageDefinitions();
  void readCounts();

  std::string path_;
  std::unique_ptr<SqliteDatabase> db_;
  std::vector<TopicInfo> topics_;
  std::map<std::int64_t, std::size_t> topic_of_id_;
  std::optional<SqliteStatement> messages_;
};

SqliteReader::SqliteReader(const std::string& path) : path_(path), db_(openReadOnly(path)) {
  checkIsBag();
  readTopics();
  readMessageDefinitions();
  readCounts();
  // The index on timestamp orders rows by (timestamp, rowid), so this walks the index without sorting.
  messages_.emplace(db_->prepare("SELECT topic_id, timestamp, data, id FROM messages ORDER BY timestamp, id"));
}

void SqliteReader::checkIsBag() {
  if (!db_->tableExists("topics") || !db_->tableExists("messages")) {
    throw Error(path_ + ": not a rosbag2 database (no topics and messages tables)");
  }
}

void SqliteReader::readTopics() {
  const bool has_qos = db_->columnExists("topics", "offered_qos_profiles");
  auto statement = db_->prepare(std::string("SELECT id, name, type, serialization_format") +
                                (has_qos ? ", offered_qos_profiles" : "") + " FROM topics ORDER BY id");
  while (statement.step()) {
    TopicInfo info;
    info.name = statement.columnText(1);
    info.type = statement.columnText(2);
    info.serialization_format = statement.columnText(3);
    if (has_qos) info.offered_qos_profiles = statement.columnText(4);
    std::size_t index = topics_.size();
    for (std::size_t i = 0; i < topics_.size(); ++i) {
      if (topics_[i].name == info.name) index = i;
    }
    if (index == topics_.size()) topics_.push_back(std::move(info));
    topic_of_id_[statement.columnInt64(0)] = index;
  }
}

void SqliteReader::readMessageDefinitions() {
  if (!db_->tableExists("message_definitions")) return;
  auto statement =
      db_->prepare("SELECT topic_type, encoding, encoded_message_definition FROM message_definitions ORDER BY id");
  while (statement.step()) {
    const std::string type = statement.columnText(0);
    const std::string encoding = statement.columnText(1);
    if (encoding.empty() || encoding == "unknown") continue;  // rosbag2 writes "unknown" when it had none
    for (auto& topic : topics_) {
      if (topic.type == type && topic.message_definition.empty()) {
        topic.message_definition = statement.columnText(2);
        topic.message_definition_encoding = encoding;
      }
    }
  }
}

void SqliteReader::readCounts() {
  auto statement = db_->prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
  while (statement.step()) {
    const std::int64_t topic_id = statement.columnInt64(0);
    const auto topic = topic_of_id_.find(topic_id);
    if (topic == topic_of_id_.end()) {
      throw Error(path_ + ": " + std::to_string(statement.columnInt64(1)) + " messages refer to topic_id " +
                  std::to_string(topic_id) + ", which the topics table does not define");
    }
    topics_[topic->second].message_count += static_cast<std::uint64_t>(statement.columnInt64(1));
  }
}

bool SqliteReader::next(BagMessage& message) {
  if (!messages_->step()) return false;
  const auto topic = topic_of_id_.find(messages_->columnInt64(0));
  if (topic == topic_of_id_.end()) {
    throw Error(path_ + ": message row id " + std::to_string(messages_->columnInt64(3)) + " refers to topic_id " +
                std::to_string(messages_->columnInt64(0)) + ", which the topics table does not define");
  }
  message.topic = topics_[topic->second].name;
  message.log_time = messages_->columnInt64(1);
  message.publish_time.reset();
  const auto [data, size] = messages_->columnBlob(2);
  message.data.assign(data, data + size);
  return true;
}

}  // namespace

std::unique_ptr<StorageReader> openSqliteStorage(const std::string& path) {
  return std::make_unique<SqliteReader>(path);
}

}  // namespace coloc::io::detail
