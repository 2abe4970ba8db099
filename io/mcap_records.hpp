#pragma once
// MCAP building blocks shared by the reader and the writer: opcodes, the records coloc interprets,
// and little-endian field cursors. Layouts follow the MCAP specification (mcap.dev/spec).
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "coloc/io/bag_message.hpp"

namespace coloc::io::detail::mcap {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::size_t kRecordPrefixSize = 1 + 8;            // opcode, content length
constexpr std::size_t kFooterContentSize = 8 + 8 + 4;       // summary_start, summary_offset_start, summary_crc
constexpr std::size_t kFooterRecordSize = kRecordPrefixSize + kFooterContentSize;

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// "Chunk", "Message", ... or "opcode 0x42".
std::string opcodeName(std::uint8_t opcode);

struct SchemaRecord {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  std::string data;
};

struct ChannelRecord {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
  std::map<std::string, std::string> metadata;
};

/// The fixed part of a Message record; the payload is the rest of the record.
struct MessageHeader {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
};
constexpr std::size_t kMessageHeaderSize = 2 + 4 + 8 + 8;

struct ChunkHeader {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

struct Footer {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

/// Reads the fields of one record's content. Every read is bounds-checked; a short record throws
/// coloc::Error naming `where` (file and byte offset of the record) and the field.
class RecordCursor {
 public:
  RecordCursor(const std::uint8_t* data, std::size_t size, std::string where)
      : data_(data), size_(size), where_(std::move(where)) {}

  std::uint8_t u8(const char* field);
  std::uint16_t u16(const char* field);
  std::uint32_t u32(const char* field);
  std::uint64_t u64(const char* field);
  std::string string(const char* field);
  /// uint32- or uint64-length-prefixed bytes, returned as a pointer into the record.
  std::pair<const std::uint8_t*, std::size_t> bytes32(const char* field);
  std::pair<const std::uint8_t*, std::size_t> bytes64(const char* field);
  std::map<std::string, std::string> stringMap(const char* field);
  std::map<std::uint16_t, std::uint64_t> u16u64Map(const char* field);

  std::size_t position() const { return position_; }
  std::size_t remaining() const { return size_ - position_; }
  const std::uint8_t* current() const { return data_ + position_; }
  /// The record this cursor reads, as its errors name it (file and byte offset).
  const std::string& where() const { return where_; }
  [[noreturn]] void fail(const std::string& reason) const;

 private:
  const std::uint8_t* take(std::size_t n, const char* field);

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
  std::string where_;
};

SchemaRecord parseSchema(RecordCursor& c);
ChannelRecord parseChannel(RecordCursor& c);
MessageHeader parseMessageHeader(RecordCursor& c);
ChunkHeader parseChunkHeader(RecordCursor& c);
Statistics parseStatistics(RecordCursor& c);
Footer parseFooter(RecordCursor& c);
/// An Attachment record; its CRC, when not 0, is checked (the record's fields before it).
BagAttachment parseAttachment(RecordCursor& c);
BagMetadataRecord parseMetadata(RecordCursor& c);

/// Appends little-endian fields to a record's content.
class RecordBuilder {
 public:
  RecordBuilder& u8(std::uint8_t v);
  RecordBuilder& u16(std::uint16_t v);
  RecordBuilder& u32(std::uint32_t v);
  RecordBuilder& u64(std::uint64_t v);
  RecordBuilder& string(const std::string& s);
  RecordBuilder& bytes(const void* data, std::size_t size);
  RecordBuilder& stringMap(const std::map<std::string, std::string>& map);
  RecordBuilder& u16u64Map(const std::map<std::uint16_t, std::uint64_t>& map);
  const std::vector<std::uint8_t>& content() const { return content_; }

 private:
  std::vector<std::uint8_t> content_;
};

/// Appends opcode, content length and content.
void appendRecord(std::vector<std::uint8_t>& out, std::uint8_t opcode, const std::vector<std::uint8_t>& content);

std::vector<std::uint8_t> schemaContent(const SchemaRecord& schema);
std::vector<std::uint8_t> channelContent(const ChannelRecord& channel);
std::vector<std::uint8_t> attachmentContent(const BagAttachment& attachment);
std::vector<std::uint8_t> metadataContent(const BagMetadataRecord& metadata);

std::uint64_t readU64Le(const std::uint8_t* p);

}  // namespace coloc::io::detail::mcap
