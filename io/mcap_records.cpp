#include "mcap_records.hpp"

#include <cstdio>
#include <cstring>

#include "coloc/core/error.hpp"
#include "crc32.hpp"

namespace coloc::io::detail::mcap {

std::string opcodeName(std::uint8_t opcode) {
  switch (opcode) {
    case kHeader: return "Header";
    case kFooter: return "Footer";
    case kSchema: return "Schema";
    case kChannel: return "Channel";
    case kMessage: return "Message";
    case kChunk: return "Chunk";
    case kMessageIndex: return "Message Index";
    case kChunkIndex: return "Chunk Index";
    case kAttachment: return "Attachment";
    case kAttachmentIndex: return "Attachment Index";
    case kStatistics: return "Statistics";
    case kMetadata: return "Metadata";
    case kMetadataIndex: return "Metadata Index";
    case kSummaryOffset: return "Summary Offset";
    case kDataEnd: return "Data End";
    default: {
      char text[24];
      std::snprintf(text, sizeof text, "opcode 0x%02x", opcode);
      return text;
    }
  }
}

std::uint64_t readU64Le(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void RecordCursor::fail(const std::string& reason) const { throw Error(where_ + ": " + reason); }

const std::uint8_t* RecordCursor::take(std::size_t n, const char* field) {
  if (n > remaining()) {
    fail("truncated at field " + std::string(field) + ": needs " + std::to_string(n) + " bytes, " +
         std::to_string(remaining()) + " left in the record");
  }
  const std::uint8_t* p = data_ + position_;
  position_ += n;
  return p;
}

std::uint8_t RecordCursor::u8(const char* field) { return *take(1, field); }

std::uint16_t RecordCursor::u16(const char* field) {
  const std::uint8_t* p = take(2, field);
  return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}

std::uint32_t RecordCursor::u32(const char* field) {
  const std::uint8_t* p = take(4, field);
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

std::uint64_t RecordCursor::u64(const char* field) { return readU64Le(take(8, field)); }

std::pair<const std::uint8_t*, std::size_t> RecordCursor::bytes32(const char* field) {
  const std::uint32_t n = u32(field);
  return {take(n, field), n};
}

std::pair<const std::uint8_t*, std::size_t> RecordCursor::bytes64(const char* field) {
  const std::uint64_t n = u64(field);
  if (n > remaining()) take(remaining() + 1, field);  // reports the truncation without narrowing n first
  return {take(static_cast<std::size_t>(n), field), static_cast<std::size_t>(n)};
}

std::string RecordCursor::string(const char* field) {
  const auto [p, n] = bytes32(field);
  return std::string(reinterpret_cast<const char*>(p), n);
}

std::map<std::string, std::string> RecordCursor::stringMap(const char* field) {
  const auto [p, n] = bytes32(field);
  RecordCursor entries(p, n, where_ + " (" + field + ")");
  std::map<std::string, std::string> map;
  while (entries.remaining() > 0) {
    std::string key = entries.string("key");
    map[std::move(key)] = entries.string("value");
  }
  return map;
}

std::map<std::uint16_t, std::uint64_t> RecordCursor::u16u64Map(const char* field) {
  const auto [p, n] = bytes32(field);
  RecordCursor entries(p, n, where_ + " (" + field + ")");
  std::map<std::uint16_t, std::uint64_t> map;
  while (entries.remaining() > 0) {
    const std::uint16_t key = entries.u16("key");
    map[key] = entries.u64("value");
  }
  return map;
}

SchemaRecord parseSchema(RecordCursor& c) {
  SchemaRecord s;
  s.id = c.u16("id");
  s.name = c.string("name");
  s.encoding = c.string("encoding");
  const auto [p, n] = c.bytes32("data");
  s.data.assign(reinterpret_cast<const char*>(p), n);
  return s;
}

ChannelRecord parseChannel(RecordCursor& c) {
  ChannelRecord ch;
  ch.id = c.u16("id");
  ch.schema_id = c.u16("schema_id");
  ch.topic = c.string("topic");
  ch.message_encoding = c.string("message_encoding");
  ch.metadata = c.stringMap("metadata");
  return ch;
}

MessageHeader parseMessageHeader(RecordCursor& c) {
  MessageHeader m;
  m.channel_id = c.u16("channel_id");
  m.sequence = c.u32("sequence");
  m.log_time = c.u64("log_time");
  m.publish_time = c.u64("publish_time");
  return m;
}

ChunkHeader parseChunkHeader(RecordCursor& c) {
  ChunkHeader h;
  h.message_start_time = c.u64("message_start_time");
  h.message_end_time = c.u64("message_end_time");
  h.uncompressed_size = c.u64("uncompressed_size");
  h.uncompressed_crc = c.u32("uncompressed_crc");
  h.compression = c.string("compression");
  return h;
}

Statistics parseStatistics(RecordCursor& c) {
  Statistics s;
  s.message_count = c.u64("message_count");
  c.u16("schema_count");
  c.u32("channel_count");
  c.u32("attachment_count");
  c.u32("metadata_count");
  c.u32("chunk_count");
  c.u64("message_start_time");
  c.u64("message_end_time");
  s.channel_message_counts = c.u16u64Map("channel_message_counts");
  return s;
}

BagAttachment parseAttachment(RecordCursor& c) {
  BagAttachment a;
  const std::uint8_t* start = c.current();
  const std::uint64_t log_time = c.u64("log_time"), create_time = c.u64("create_time");
  if (log_time > static_cast<std::uint64_t>(INT64_MAX) || create_time > static_cast<std::uint64_t>(INT64_MAX))
    c.fail("time stamp beyond the int64 nanosecond range");
  a.log_time = static_cast<Stamp>(log_time);
  a.create_time = static_cast<Stamp>(create_time);
  a.name = c.string("name");
  a.media_type = c.string("media_type");
  const auto [p, n] = c.bytes64("data");
  a.data.assign(p, p + n);
  const std::size_t covered = static_cast<std::size_t>(c.current() - start);
  const std::uint32_t stored = c.u32("crc");
  if (stored != 0) {
    const std::uint32_t computed = crc32(start, covered);
    if (computed != stored) c.fail("attachment '" + a.name + "' CRC mismatch: the attachment is corrupt");
  }
  return a;
}

BagMetadataRecord parseMetadata(RecordCursor& c) {
  BagMetadataRecord m;
  m.name = c.string("name");
  m.entries = c.stringMap("metadata");
  return m;
}

Footer parseFooter(RecordCursor& c) {
  Footer f;
  f.summary_start = c.u64("summary_start");
  f.summary_offset_start = c.u64("summary_offset_start");
  f.summary_crc = c.u32("summary_crc");
  return f;
}

RecordBuilder& RecordBuilder::u8(std::uint8_t v) {
  content_.push_back(v);
  return *this;
}

RecordBuilder& RecordBuilder::u16(std::uint16_t v) {
  for (int i = 0; i < 2; ++i) content_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  return *this;
}

RecordBuilder& RecordBuilder::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) content_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  return *this;
}

RecordBuilder& RecordBuilder::u64(std::uint64_t v) {
  for (int i = 0; i < 8; ++i) content_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  return *this;
}

RecordBuilder& RecordBuilder::bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const std::uint8_t*>(data);
  content_.insert(content_.end(), p, p + size);
  return *this;
}

RecordBuilder& RecordBuilder::string(const std::string& s) {
  if (s.size() > UINT32_MAX) throw Error("MCAP string field longer than 4 GiB");
  u32(static_cast<std::uint32_t>(s.size()));
  return bytes(s.data(), s.size());
}

RecordBuilder& RecordBuilder::stringMap(const std::map<std::string, std::string>& map) {
  RecordBuilder entries;
  for (const auto& [key, value] : map) entries.string(key).string(value);
  u32(static_cast<std::uint32_t>(entries.content().size()));
  return bytes(entries.content().data(), entries.content().size());
}

RecordBuilder& RecordBuilder::u16u64Map(const std::map<std::uint16_t, std::uint64_t>& map) {
  u32(static_cast<std::uint32_t>(map.size() * (2 + 8)));
  for (const auto& [key, value] : map) u16(key).u64(value);
  return *this;
}

void appendRecord(std::vector<std::uint8_t>& out, std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
  out.push_back(opcode);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(std::uint64_t{content.size()} >> (8 * i)));
  out.insert(out.end(), content.begin(), content.end());
}

std::vector<std::uint8_t> schemaContent(const SchemaRecord& schema) {
  RecordBuilder b;
  b.u16(schema.id).string(schema.name).string(schema.encoding).string(schema.data);
  return b.content();
}

std::vector<std::uint8_t> channelContent(const ChannelRecord& channel) {
  RecordBuilder b;
  b.u16(channel.id).u16(channel.schema_id).string(channel.topic).string(channel.message_encoding).stringMap(channel.metadata);
  return b.content();
}

std::vector<std::uint8_t> attachmentContent(const BagAttachment& a) {
  RecordBuilder b;
  b.u64(static_cast<std::uint64_t>(a.log_time)).u64(static_cast<std::uint64_t>(a.create_time)).string(a.name).string(a.media_type);
  b.u64(a.data.size()).bytes(a.data.data(), a.data.size());
  b.u32(crc32(b.content().data(), b.content().size()));
  return b.content();
}

std::vector<std::uint8_t> metadataContent(const BagMetadataRecord& m) {
  RecordBuilder b;
  b.string(m.name).stringMap(m.entries);
  return b.content();
}

}  // namespace coloc::io::detail::mcap
