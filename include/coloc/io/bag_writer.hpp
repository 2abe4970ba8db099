#pragma once
// Writes rosbag2 sqlite3 bags that ROS 2 Humble and Jazzy play and inspect (`ros2 bag play`,
// `ros2 bag info`): a directory OUT/ holding OUT_0.db3 (database schema 3: schema, metadata, topics,
// messages, index on timestamp) and metadata.yaml (version 5). All messages go in one transaction,
// committed by close(). And convert(): any bag BagReader reads -> sqlite3 directory or .mcap file.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "coloc/io/bag_message.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/mcap_writer.hpp"

namespace coloc::io {

/// rosbag2's compression of a sqlite3 bag: none, the whole database file (FILE mode, "OUT_0.db3.zstd")
/// or each message (MESSAGE mode), zstd as rosbag2 writes it.
enum class BagCompression : std::uint8_t { kNone, kZstdFile, kZstdMessage };

class BagWriter {
 public:
  /// Creates the bag directory (and its parents); refuses an existing non-empty directory or a file.
  static BagWriter create(const std::string& directory, BagCompression compression = BagCompression::kNone);

  ~BagWriter();  ///< closes if close() was not called, swallowing errors: call close() to see them
  BagWriter(BagWriter&&) noexcept;
  BagWriter& operator=(BagWriter&&) noexcept;

  /// Declares a topic (its message_count is ignored). The QoS profiles are stored in the v5 form
  /// (numeric enums) Humble reads; a topic without them gets RELIABLE / VOLATILE / KEEP_LAST 10.
  void addTopic(const TopicInfo& topic);
  void write(const std::string& topic, Stamp log_time, const std::uint8_t* data, std::size_t size);
  void write(const BagMessage& message);
  /// Commits the messages, writes the metadata row and metadata.yaml. Throws coloc::Error.
  void close();

  /// The database file, e.g. "OUT/OUT_0.db3".
  const std::string& databasePath() const;

 private:
  struct Impl;
  explicit BagWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct ConvertOptions {
  McapWriterOptions mcap;  ///< used when the output is a .mcap file
  BagCompression sqlite_compression = BagCompression::kNone;  ///< used when the output is a sqlite3 bag
  /// Read an input that was never closed up to where it stops: the output is then a closed recording
  /// of what it held.
  BagReadOptions read;
};

struct ConvertSummary {
  std::vector<TopicInfo> topics;
  std::uint64_t message_count = 0;
  /// MCAP attachments and metadata records read: copied to an MCAP output, which rosbag2 sqlite3 cannot hold.
  std::uint64_t attachments = 0, metadata_records = 0;
  std::vector<RecoveredFile> recovered;  ///< the input's files read up to their cut (ConvertOptions::read)
};

/// Copies every message of `input` (anything BagReader::open accepts) to `output`: an MCAP file if the
/// name ends in ".mcap", else a rosbag2 sqlite3 directory. Payload bytes and log times are preserved
/// exactly; MCAP publish times too when both sides are MCAP. Refuses to overwrite existing output.
ConvertSummary convert(const std::string& input, const std::string& output, const ConvertOptions& options = {});

}  // namespace coloc::io
