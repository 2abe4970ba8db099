// rosbag2 sqlite3 bag writer in Humble's layout (database schema 3, metadata.yaml version 5), which
// Humble plays natively and Iron/Jazzy read as an older bag. The metadata row in the database lets
// Jazzy's sqlite3 plugin parse the QoS profiles with the version they were written in.
#include "coloc/io/bag_writer.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include "bag_compression.hpp"
#include "bag_metadata.hpp"
#include "coloc/core/error.hpp"
#include "qos_profiles.hpp"
#include "sqlite_database.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;

// What ROS_DISTRO rosbag2 would record; Humble is the distribution whose layout this is.
constexpr const char* kRosDistro = "humble";
constexpr int kSchemaVersion = 3;

const char* const kCreateTables[] = {
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);",
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,metadata TEXT NOT NULL);",
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);",
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER NOT NULL, "
    "data BLOB NOT NULL);",
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
};

/// The bag's name: the directory's last component ("out/run1/" -> "run1").
std::string bagName(const fs::path& directory) {
  fs::path normal = directory.lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();
  const std::string name = normal.filename().string();
  return name.empty() || name == "." || name == ".." ? "bag" : name;
}

void prepareDirectory(const fs::path& directory) {
  std::error_code ec;
  if (fs::exists(directory, ec)) {
    if (!fs::is_directory(directory, ec)) {
      throw Error(directory.string() + ": exists and is not a directory; refusing to overwrite it");
    }
    if (!fs::is_empty(directory, ec)) {
      throw Error(directory.string() + ": exists and is not empty; refusing to overwrite a bag");
    }
  }
  fs::create_directories(directory, ec);
  if (ec) throw Error(directory.string() + ": cannot create the bag directory: " + ec.message());
}

}  // namespace

struct BagWriter::Impl {
  fs::path directory;
  std::string file_name;
  std::string db_path;
  std::unique_ptr<detail::SqliteDatabase> db;
  std::optional<detail::SqliteStatement> insert_message;
  std::vector<TopicInfo> topics;
  std::map<std::string, std::pair<std::int64_t, std::size_t>> topic_ids;  // name -> (row id, index)
  std::uint64_t message_count = 0;
  Stamp first_time = 0, last_time = 0;
  bool closed = false;
  BagCompression compression = BagCompression::kNone;

  [[noreturn]] void fail(const std::string& reason) const { throw Error(db_path + ": " + reason); }

  void createDatabase() {
    db = std::make_unique<detail::SqliteDatabase>(detail::sqliteFileUri(db_path),
                                                  SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_URI,
                                                  db_path);
    // rosbag2's write-optimised defaults; the single transaction makes the journal small anyway.
    db->execute("PRAGMA journal_mode=MEMORY;");
    db->execute("PRAGMA synchronous=OFF;");
    for (const char* sql : kCreateTables) db->execute(sql);
    db->prepare("INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)")
        .bind(1, std::int64_t{kSchemaVersion})
        .bind(2, std::string(kRosDistro))
        .execute();
    db->execute("BEGIN TRANSACTION;");
    insert_message.emplace(db->prepare("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)"));
  }

  detail::BagMetadata metadata() const {
    detail::BagMetadata m;
    m.storage_identifier = "sqlite3";
    const std::string stored = compression == BagCompression::kZstdFile ? file_name + ".zstd" : file_name;
    if (compression != BagCompression::kNone) {
      m.compression_format = "zstd";
      m.compression_mode = compression == BagCompression::kZstdFile ? "FILE" : "MESSAGE";
    }
    m.relative_file_paths = {stored};
    m.starting_time = first_time;
    m.duration = last_time - first_time;
    m.message_count = message_count;
    m.topics = topics;
    m.files = {{stored, first_time, last_time - first_time, message_count}};
    return m;
  }

  void writeMetadataFile(const detail::BagMetadata& m) const {
    const fs::path path = directory / "metadata.yaml";
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << detail::bagMetadataYaml(m, true);
    out.close();
    if (!out) throw Error(path.string() + ": cannot write the bag metadata");
  }

  void close() {
    const detail::BagMetadata m = metadata();
    db->prepare("INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)")
        .bind(1, std::int64_t{5})
        .bind(2, detail::bagMetadataYaml(m, false))
        .execute();
    db->execute("COMMIT;");
    insert_message.reset();
    db->close();
    if (compression == BagCompression::kZstdFile) {
      detail::compressZstdFile(db_path, db_path + ".zstd");
      std::error_code ec;
      fs::remove(db_path, ec);
    }
    writeMetadataFile(m);
  }
};

BagWriter BagWriter::create(const std::string& directory, BagCompression compression) {
  auto impl = std::make_unique<Impl>();
  impl->compression = compression;
  impl->directory = fs::path(directory);
  prepareDirectory(impl->directory);
  impl->file_name = bagName(impl->directory) + "_0.db3";
  impl->db_path = (impl->directory / impl->file_name).string();
  impl->createDatabase();
  return BagWriter(std::move(impl));
}

BagWriter::BagWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

BagWriter::~BagWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() reports errors to callers that want them.
  }
}

BagWriter::BagWriter(BagWriter&&) noexcept = default;
BagWriter& BagWriter::operator=(BagWriter&&) noexcept = default;

void BagWriter::addTopic(const TopicInfo& topic) {
  Impl& w = *impl_;
  if (w.closed) w.fail("addTopic after close");
  if (w.topic_ids.count(topic.name)) w.fail("topic " + topic.name + " declared twice");
  TopicInfo stored = topic;
  stored.serialization_format = topic.serialization_format.empty() ? "cdr" : topic.serialization_format;
  stored.offered_qos_profiles = detail::qosProfilesWithNumericEnums(topic.offered_qos_profiles);
  stored.message_count = 0;
  w.db->prepare("INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES (?, ?, ?, ?)")
      .bind(1, stored.name)
      .bind(2, stored.type)
      .bind(3, stored.serialization_format)
      .bind(4, stored.offered_qos_profiles)
      .execute();
  w.topic_ids[topic.name] = {w.db->lastInsertRowId(), w.topics.size()};
  w.topics.push_back(std::move(stored));
}

void BagWriter::write(const std::string& topic, Stamp log_time, const std::uint8_t* data, std::size_t size) {
  Impl& w = *impl_;
  if (w.closed) w.fail("write after close");
  const auto found = w.topic_ids.find(topic);
  if (found == w.topic_ids.end()) w.fail("topic " + topic + " was not declared with addTopic");
  if (w.compression == BagCompression::kZstdMessage) {
    const std::vector<std::uint8_t> packed = detail::compressZstdMessage(data, size);
    w.insert_message->bind(1, log_time).bind(2, found->second.first).bindBlob(3, packed.data(), packed.size()).execute();
  } else {
    w.insert_message->bind(1, log_time).bind(2, found->second.first).bindBlob(3, data, size).execute();
  }
  w.first_time = w.message_count == 0 ? log_time : std::min(w.first_time, log_time);
  w.last_time = w.message_count == 0 ? log_time : std::max(w.last_time, log_time);
  ++w.message_count;
  ++w.topics[found->second.second].message_count;
}

void BagWriter::write(const BagMessage& message) {
  write(message.topic, message.log_time, message.data.data(), message.data.size());
}

void BagWriter::close() {
  if (impl_->closed) return;
  impl_->closed = true;
  impl_->close();
}

const std::string& BagWriter::databasePath() const { return impl_->db_path; }

}  // namespace coloc::io
