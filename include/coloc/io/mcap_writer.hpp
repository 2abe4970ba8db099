#pragma once
// Writes MCAP files with the ros2 profile: schemas in ros2msg encoding (the definition the topic
// carries, else coloc's own for the types it knows, else an empty schema with an empty encoding, as
// rosbag2 writes it), channels with message_encoding "cdr", the offered_qos_profiles and the topic's
// other metadata, attachments and metadata records, messages in chunks compressed with zstd, lz4 (frame format)
// or not at all, and optionally message indexes and a summary section. Output is deterministic: the
// same calls give the same bytes.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "coloc/io/bag_message.hpp"

namespace coloc::io {

enum class McapCompression : std::uint8_t { kNone, kZstd, kLz4 };

struct McapWriterOptions {
  McapCompression compression = McapCompression::kZstd;
  std::size_t chunk_size = 1u << 20;   ///< uncompressed bytes collected before a chunk is written
  bool write_message_indexes = true;   ///< Message Index records after each chunk
  bool write_summary = true;           ///< schemas, channels, statistics, chunk indexes, summary offsets
  bool write_crcs = true;              ///< chunk, data section and summary CRC32s
};

class McapWriter {
 public:
  /// Creates `path`; refuses to overwrite an existing file. Throws coloc::Error.
  static McapWriter create(const std::string& path, const McapWriterOptions& options = {});

  ~McapWriter();  ///< closes if close() was not called, swallowing errors: call close() to see them
  McapWriter(McapWriter&&) noexcept;
  McapWriter& operator=(McapWriter&&) noexcept;

  /// Declares a topic (its message_count is ignored). Declaring the same name again is an error.
  void addTopic(const TopicInfo& topic);
  void write(const std::string& topic, Stamp log_time, Stamp publish_time, const std::uint8_t* data,
             std::size_t size);
  /// Writes a read message; publish_time defaults to log_time as MCAP requires.
  void write(const BagMessage& message);
  /// A file stored beside the messages, and named key-value pairs (MCAP Attachment and Metadata
  /// records, indexed in the summary).
  void writeAttachment(const BagAttachment& attachment);
  void writeMetadata(const BagMetadataRecord& metadata);
  /// Flushes the last chunk, writes the summary and footer. Further writes are errors.
  void close();

 private:
  struct Impl;
  explicit McapWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::io
