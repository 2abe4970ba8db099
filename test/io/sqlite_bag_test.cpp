// rosbag2 sqlite3 bags: written as Humble writes them, read in every database schema rosbag2 used.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;
using testing::errorMessage;
using testing::nav2Bag;
using testing::readAllMessages;
using testing::readBytes;
using testing::ScratchDir;
using testing::writeText;

/// A raw SQLite connection for building and inspecting databases the way other tools do.
class Database {
 public:
  explicit Database(const std::string& path) {
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) ADD_FAILURE() << sqlite3_errmsg(db_);
  }
  ~Database() { sqlite3_close(db_); }
  void exec(const std::string& sql) {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) ADD_FAILURE() << sql << ": " << error;
    sqlite3_free(error);
  }
  /// The first column of every row, as text.
  std::vector<std::string> column(const std::string& sql) {
    std::vector<std::string> values;
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db_);
      return values;
    }
    while (sqlite3_step(statement) == SQLITE_ROW) {
      const auto* text = sqlite3_column_text(statement, 0);
      values.emplace_back(text ? reinterpret_cast<const char*>(text) : "");
    }
    sqlite3_finalize(statement);
    return values;
  }
  void insertMessage(int topic_id, std::int64_t timestamp, const std::string& data) {
    exec("INSERT INTO messages (topic_id, timestamp, data) VALUES (" + std::to_string(topic_id) + ", " +
         std::to_string(timestamp) + ", X'" + hex(data) + "')");
  }

 private:
  static std::string hex(const std::string& data) {
    std::string out;
    char digits[3];
    for (unsigned char c : data) std::snprintf(digits, sizeof digits, "%02X", c), out += digits;
    return out;
  }
  sqlite3* db_ = nullptr;
};

std::vector<std::string> topicNames(const BagReader& reader) {
  std::vector<std::string> names;
  for (const auto& topic : reader.topics()) names.push_back(topic.name);
  return names;
}

TEST(SqliteBag, ConvertedRecordingReadsBackWithIdenticalTopicsLogTimesAndPayloads) {
  ScratchDir dir;
  const std::string out = dir / "nav2";
  const ConvertSummary summary = convert(nav2Bag(), out);
  EXPECT_EQ(summary.message_count, 8197u);
  EXPECT_TRUE(fs::exists(dir / "nav2/nav2_0.db3"));
  EXPECT_TRUE(fs::exists(dir / "nav2/metadata.yaml"));

  const BagReader original = BagReader::open(nav2Bag());
  const BagReader copy = BagReader::open(out);
  EXPECT_EQ(copy.storageIdentifier(), "sqlite3");
  ASSERT_EQ(copy.topics().size(), original.topics().size());
  for (std::size_t i = 0; i < copy.topics().size(); ++i) {
    EXPECT_EQ(copy.topics()[i].name, original.topics()[i].name);
    EXPECT_EQ(copy.topics()[i].type, original.topics()[i].type);
    EXPECT_EQ(copy.topics()[i].serialization_format, "cdr");
    EXPECT_EQ(copy.topics()[i].message_count, original.topics()[i].message_count);
  }
  // The recording is in log-time order, so the sqlite3 order (timestamp, then id) is the same.
  const auto before = readAllMessages(nav2Bag());
  const auto after = readAllMessages(out);
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    ASSERT_EQ(after[i].topic, before[i].topic) << i;
    ASSERT_EQ(after[i].log_time, before[i].log_time) << i;
    ASSERT_EQ(after[i].data, before[i].data) << i;
    ASSERT_FALSE(after[i].publish_time.has_value());
  }
}

TEST(SqliteBag, WrittenBagHasHumblesSchemaAndMetadata) {
  ScratchDir dir;
  convert(nav2Bag(), dir / "run1");
  Database db(dir / "run1/run1_0.db3");
  EXPECT_EQ(db.column("SELECT schema_version || ' ' || ros_distro FROM schema"),
            std::vector<std::string>{"3 humble"});
  EXPECT_EQ(db.column("SELECT name FROM sqlite_master WHERE type = 'index'"), std::vector<std::string>{"timestamp_idx"});
  EXPECT_EQ(db.column("SELECT name FROM pragma_table_info('topics')"),
            (std::vector<std::string>{"id", "name", "type", "serialization_format", "offered_qos_profiles"}));
  EXPECT_EQ(db.column("SELECT metadata_version FROM metadata"), std::vector<std::string>{"5"});
  const std::string table_metadata = db.column("SELECT metadata FROM metadata").at(0);
  EXPECT_EQ(table_metadata.rfind("version: 5\nstorage_identifier: sqlite3\n", 0), 0u) << table_metadata;
  // Jazzy recorded names ("transient_local"); Humble reads numbers.
  const std::string qos = db.column("SELECT offered_qos_profiles FROM topics WHERE name = '/amcl_pose'").at(0);
  EXPECT_EQ(qos.rfind("- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n", 0), 0u) << qos;
  EXPECT_NE(qos.find("avoid_ros_namespace_conventions: false"), std::string::npos);
  EXPECT_EQ(db.column("SELECT COUNT(*) FROM messages"), std::vector<std::string>{"8197"});

  std::ifstream in(dir / "run1/metadata.yaml");
  const std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* expected :
       {"rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n",
        "  duration:\n    nanoseconds: 97355296000\n",
        "  starting_time:\n    nanoseconds_since_epoch: 1778234353382747000\n", "  message_count: 8197\n",
        "    - topic_metadata:\n        name: /odom\n        type: nav_msgs/msg/Odometry\n"
        "        serialization_format: cdr\n        offered_qos_profiles: \"- history: 1\\n  depth: 10\\n",
        "      message_count: 2639\n", "  compression_format: \"\"\n  compression_mode: \"\"\n",
        "  relative_file_paths:\n    - run1_0.db3\n",
        "  files:\n    - path: run1_0.db3\n      starting_time:\n        nanoseconds_since_epoch: 1778234353382747000\n"
        "      duration:\n        nanoseconds: 97355296000\n      message_count: 8197\n"}) {
    EXPECT_NE(yaml.find(expected), std::string::npos) << expected << "\n---\n" << yaml;
  }
  EXPECT_EQ(yaml.find("custom_data"), std::string::npos);
}

TEST(SqliteBag, DatabaseFileAloneIsReadable) {
  ScratchDir dir;
  convert(nav2Bag(), dir / "b");
  const BagReader reader = BagReader::open(dir / "b/b_0.db3");
  EXPECT_EQ(reader.messageCount(), 8197u);
  EXPECT_EQ(topicNames(reader), topicNames(BagReader::open(nav2Bag())));
}

TEST(SqliteBag, WriterRefusesANonEmptyDirectoryAndAcceptsAnEmptyOne) {
  ScratchDir dir;
  fs::create_directories(dir / "full");
  writeText(dir / "full/keep.txt", "precious");
  const std::string message = errorMessage([&] { BagWriter::create(dir / "full"); });
  EXPECT_NE(message.find("full: exists and is not empty"), std::string::npos) << message;
  EXPECT_EQ(readBytes(dir / "full/keep.txt").size(), 8u);

  fs::create_directories(dir / "empty");
  BagWriter writer = BagWriter::create(dir / "empty/");
  EXPECT_EQ(writer.databasePath(), (fs::path(dir / "empty/") / "empty_0.db3").string());
  writer.close();
  const BagReader reader = BagReader::open(dir / "empty");
  EXPECT_EQ(reader.messageCount(), 0u);

  writeText(dir / "file", "x");
  EXPECT_NE(errorMessage([&] { BagWriter::create(dir / "file"); }).find("not a directory"), std::string::npos);
}

TEST(SqliteBag, WrittenMessagesComeBackInTimestampOrder) {
  ScratchDir dir;
  {
    BagWriter writer = BagWriter::create(dir / "order");
    writer.addTopic({"/a", "std_msgs/msg/String", "cdr", "", "", "", 0, {}});
    const std::uint8_t payload[] = {1, 2, 3};
    for (const Stamp t : {30, 10, 20, 10}) writer.write("/a", t, payload, sizeof payload);
    EXPECT_NE(errorMessage([&] { writer.write("/b", 1, payload, 1); }).find("/b was not declared"), std::string::npos);
    writer.close();
  }
  std::vector<Stamp> times;
  for (const auto& message : readAllMessages(dir / "order")) times.push_back(message.log_time);
  EXPECT_EQ(times, (std::vector<Stamp>{10, 10, 20, 30}));
}

TEST(SqliteBag, WalModeDatabaseIsReadWithoutCreatingFiles) {
  ScratchDir dir;
  const std::string path = dir / "wal.db3";
  {
    Database db(path);
    db.exec("PRAGMA journal_mode=WAL;");
    db.exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
            "INSERT INTO schema VALUES (4, 'jazzy');"
            "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);"
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL,"
            " type_description_hash TEXT NOT NULL);"
            "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL,"
            " encoding TEXT NOT NULL, encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
            " data BLOB NOT NULL);"
            "INSERT INTO topics VALUES (1, '/chatter', 'std_msgs/msg/String', 'cdr', '', 'RIHS01_00');"
            "INSERT INTO message_definitions VALUES (1, 'std_msgs/msg/String', 'ros2msg', 'string data', 'RIHS01_00');");
    db.insertMessage(1, 5, "hello");
    db.insertMessage(1, 6, "world");
  }  // closing checkpoints the log and removes -wal
  const std::vector<std::uint8_t> header = readBytes(path);
  ASSERT_EQ(header[18], 2);  // WAL mode recorded in the file header
  ASSERT_EQ(header[19], 2);
  ASSERT_FALSE(fs::exists(path + "-wal"));

  BagReader reader = BagReader::open(path);
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].message_definition, "string data");
  EXPECT_EQ(reader.topics()[0].message_definition_encoding, "ros2msg");
  EXPECT_EQ(reader.topics()[0].message_count, 2u);
  const auto messages = readAllMessages(path);
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_EQ(std::string(messages[1].data.begin(), messages[1].data.end()), "world");
  EXPECT_FALSE(fs::exists(path + "-wal"));
  EXPECT_FALSE(fs::exists(path + "-shm"));
}

TEST(SqliteBag, MessagesStillInTheWriteAheadLogAreRead) {
  ScratchDir dir;
  const std::string path = dir / "live.db3";
  Database db(path);
  db.exec("PRAGMA journal_mode=WAL; PRAGMA wal_autocheckpoint=0;");
  db.exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
          " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
          "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
          " data BLOB NOT NULL);"
          "INSERT INTO topics VALUES (1, '/x', 'std_msgs/msg/String', 'cdr', '');");
  db.insertMessage(1, 1, "a");
  ASSERT_GT(fs::file_size(path + "-wal"), 0u);  // the writer is still open: nothing checkpointed
  EXPECT_EQ(readAllMessages(path).size(), 1u);
}

TEST(SqliteBag, FoxyDatabaseWithoutSchemaOrQosColumnIsRead) {
  ScratchDir dir;
  const std::string path = dir / "foxy.db3";
  {
    Database db(path);
    db.exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
            " data BLOB NOT NULL);"
            "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
            "INSERT INTO topics VALUES (3, '/odom', 'nav_msgs/msg/Odometry', 'cdr');"
            "INSERT INTO topics VALUES (4, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr');");
    db.insertMessage(4, 20, "s");
    db.insertMessage(3, 10, "o");
    db.insertMessage(3, 20, "p");
  }
  BagReader reader = BagReader::open(path);
  EXPECT_EQ(topicNames(reader), (std::vector<std::string>{"/odom", "/scan"}));
  EXPECT_EQ(reader.topics()[0].message_count, 2u);
  EXPECT_EQ(reader.topics()[0].offered_qos_profiles, "");
  std::string order;
  BagMessage message;
  while (reader.next(message)) order += std::string(message.data.begin(), message.data.end());
  EXPECT_EQ(order, "osp");  // timestamp, then row id
}

TEST(SqliteBag, QosProfilesComeFromMetadataWhenTheDatabaseHasNone) {
  ScratchDir dir;
  fs::create_directories(dir / "foxy");
  {
    Database db(dir / "foxy/foxy_0.db3");
    db.exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
            " data BLOB NOT NULL);"
            "INSERT INTO topics VALUES (1, '/odom', 'nav_msgs/msg/Odometry', 'cdr');");
    db.insertMessage(1, 1, "o");
  }
  writeText(dir / "foxy/metadata.yaml",
            "rosbag2_bagfile_information:\n  version: 4\n  storage_identifier: sqlite3\n"
            "  relative_file_paths:\n    - foxy_0.db3\n  topics_with_message_count:\n    - topic_metadata:\n"
            "        name: /odom\n        type: nav_msgs/msg/Odometry\n        serialization_format: cdr\n"
            "        offered_qos_profiles: \"- history: 1\\n  depth: 5\\n\"\n      message_count: 1\n");
  const BagReader reader = BagReader::open(dir / "foxy");
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].offered_qos_profiles, "- history: 1\n  depth: 5\n");
}

TEST(SqliteBag, MessageOnAnUndefinedTopicIdIsReported) {
  ScratchDir dir;
  const std::string path = dir / "dangling.db3";
  {
    Database db(path);
    db.exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
            " data BLOB NOT NULL);");
    db.insertMessage(9, 1, "x");
  }
  const std::string message = errorMessage([&] { BagReader::open(path); });
  EXPECT_NE(message.find(path + ": 1 messages refer to topic_id 9"), std::string::npos) << message;
}

TEST(SqliteBag, FilesThatAreNotBagsAreReported) {
  ScratchDir dir;
  writeText(dir / "junk.db3", std::string(4096, 'j'));
  std::string message = errorMessage([&] { BagReader::open(dir / "junk.db3"); });
  EXPECT_EQ(message.rfind(dir / "junk.db3: ", 0), 0u) << message;
  EXPECT_NE(message.find("not a database"), std::string::npos) << message;

  { Database db(dir / "other.db3"); db.exec("CREATE TABLE t(x);"); }
  message = errorMessage([&] { BagReader::open(dir / "other.db3"); });
  EXPECT_NE(message.find("not a rosbag2 database"), std::string::npos) << message;

  writeText(dir / "notes.txt", "hello");
  message = errorMessage([&] { BagReader::open(dir / "notes.txt"); });
  EXPECT_NE(message.find("neither an MCAP file"), std::string::npos) << message;
}

TEST(SqliteBag, MissingDatabaseListedInMetadataIsReported) {
  ScratchDir dir;
  convert(nav2Bag(), dir / "gone");
  fs::remove(dir / "gone/gone_0.db3");
  const std::string message = errorMessage([&] { BagReader::open(dir / "gone"); });
  EXPECT_NE(message.find("metadata.yaml: lists storage file 'gone_0.db3', which does not exist"), std::string::npos)
      << message;
}

TEST(SqliteBag, DirectoryWithoutMetadataReadsItsSplitFilesInOrder) {
  ScratchDir dir;
  fs::create_directories(dir / "split");
  for (const int part : {0, 1, 2, 10}) {
    Database db(dir / ("split/split_" + std::to_string(part) + ".db3"));
    db.exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
            " data BLOB NOT NULL);"
            "INSERT INTO topics VALUES (1, '/x', 'std_msgs/msg/String', 'cdr', '');");
    db.insertMessage(1, part, std::to_string(part));
  }
  std::string order;
  for (const auto& message : readAllMessages(dir / "split")) order += std::string(message.data.begin(), message.data.end()) + ",";
  EXPECT_EQ(order, "0,1,2,10,");
  EXPECT_EQ(BagReader::open(dir / "split").topics().at(0).message_count, 4u);
}

}  // namespace
}  // namespace coloc::io
