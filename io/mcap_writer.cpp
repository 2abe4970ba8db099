// MCAP writer (ros2 profile). Layout: magic, Header, chunks each followed by their Message Index
// records, Data End, then optionally the summary (Schema, Channel, Statistics, Chunk Index groups and
// their Summary Offsets), Footer, magic. Schema and Channel records go into the chunk that first needs
// them, so a reader streaming the data section meets them before their messages.
#include "coloc/io/mcap_writer.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include "chunk_compression.hpp"
#include "coloc/core/error.hpp"
#include "coloc/io/ros_messages.hpp"
#include "crc32.hpp"
#include "mcap_records.hpp"

namespace coloc::io {

using namespace detail::mcap;

namespace {

struct SummaryGroup {
  std::uint8_t opcode;
  std::uint64_t start;
  std::uint64_t length;
};

void appendLe(std::vector<std::uint8_t>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

}  // namespace

struct McapWriter::Impl {
  std::string path;
  McapWriterOptions options;
  std::ofstream out;
  std::uint64_t position = 0;
  detail::Crc32 data_crc;
  detail::Crc32 summary_crc;
  bool in_data_section = true;
  bool in_summary = false;
  bool closed = false;

  std::vector<SchemaRecord> schemas;
  std::map<std::tuple<std::string, std::string, std::string>, std::uint16_t> schema_ids;
  std::vector<ChannelRecord> channels;
  std::map<std::string, std::uint16_t> channel_of_topic;
  std::map<std::uint16_t, std::uint32_t> next_sequence;

  std::vector<std::uint8_t> chunk;
  std::uint64_t chunk_start_time = 0, chunk_end_time = 0;
  bool chunk_has_message = false;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_message_index;
  std::vector<std::vector<std::uint8_t>> chunk_indexes;
  std::vector<std::vector<std::uint8_t>> attachment_indexes, metadata_indexes;

  std::uint64_t message_count = 0;
  std::uint64_t start_time = 0, end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_counts;
  std::uint32_t chunk_count = 0;

  [[noreturn]] void fail(const std::string& reason) const { throw Error(path + ": " + reason); }

  void emit(const void* data, std::size_t size) {
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail("write failed at byte offset " + std::to_string(position));
    position += size;
    if (in_data_section && options.write_crcs) data_crc.update(data, size);
    if (in_summary && options.write_crcs) summary_crc.update(data, size);
  }

  void emitRecord(std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
    std::vector<std::uint8_t> prefix{opcode};
    appendLe(prefix, content.size(), 8);
    emit(prefix.data(), prefix.size());
    emit(content.data(), content.size());
  }

  std::uint16_t schemaFor(const TopicInfo& topic) {
    if (topic.type.empty()) return 0;  // no schema
    // The topic's own definition if it has one, else coloc's for the types it knows, else none.
    std::string data = topic.message_definition;
    std::string encoding = topic.message_definition_encoding.empty() ? "ros2msg" : topic.message_definition_encoding;
    if (data.empty()) {
      data = rosMessageDefinition(topic.type);
      // A type coloc has no definition of gets an empty encoding, as rosbag2 writes it: "ros2msg" with
      // no text would tell readers the type has no fields, and they decode its messages to {}.
      encoding = data.empty() ? "" : "ros2msg";
    }
    const auto key = std::make_tuple(topic.type, encoding, data);
    if (const auto found = schema_ids.find(key); found != schema_ids.end()) return found->second;
    if (schemas.size() >= UINT16_MAX) fail("more than 65535 schemas");
    SchemaRecord schema{static_cast<std::uint16_t>(schemas.size() + 1), topic.type, encoding, data};
    schema_ids.emplace(key, schema.id);
    schemas.push_back(schema);
    appendRecord(chunk, kSchema, schemaContent(schema));
    return schema.id;
  }

  void appendMessage(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                     const std::uint8_t* data, std::size_t size) {
    const std::uint64_t offset = chunk.size();
    chunk.push_back(kMessage);
    appendLe(chunk, kMessageHeaderSize + size, 8);
    appendLe(chunk, channel_id, 2);
    appendLe(chunk, next_sequence[channel_id]++, 4);
    appendLe(chunk, log_time, 8);
    appendLe(chunk, publish_time, 8);
    chunk.insert(chunk.end(), data, data + size);
    chunk_message_index[channel_id].emplace_back(log_time, offset);
    chunk_start_time = chunk_has_message ? std::min(chunk_start_time, log_time) : log_time;
    chunk_end_time = chunk_has_message ? std::max(chunk_end_time, log_time) : log_time;
    chunk_has_message = true;
  }

  void countMessage(std::uint16_t channel_id, std::uint64_t log_time) {
    start_time = message_count == 0 ? log_time : std::min(start_time, log_time);
    end_time = message_count == 0 ? log_time : std::max(end_time, log_time);
    ++message_count;
    ++channel_counts[channel_id];
  }

  void flushChunk() {
    if (chunk.empty()) return;
    const std::uint32_t crc = options.write_crcs ? detail::crc32(chunk.data(), chunk.size()) : 0;
    const std::vector<std::uint8_t> compressed = detail::compressChunk(options.compression, chunk.data(), chunk.size());
    const std::string compression(detail::compressionName(options.compression));

    RecordBuilder fixed;
    fixed.u64(chunk_start_time).u64(chunk_end_time).u64(chunk.size()).u32(crc).string(compression).u64(compressed.size());
    const std::uint64_t chunk_offset = position;
    std::vector<std::uint8_t> prefix{kChunk};
    appendLe(prefix, fixed.content().size() + compressed.size(), 8);
    emit(prefix.data(), prefix.size());
    emit(fixed.content().data(), fixed.content().size());
    emit(compressed.data(), compressed.size());
    const std::uint64_t chunk_length = position - chunk_offset;

    std::map<std::uint16_t, std::uint64_t> index_offsets;
    const std::uint64_t indexes_start = position;
    if (options.write_message_indexes) {
      for (const auto& [channel_id, entries] : chunk_message_index) {
        RecordBuilder index;
        index.u16(channel_id).u32(static_cast<std::uint32_t>(entries.size() * 16));
        for (const auto& [time, offset] : entries) index.u64(time).u64(offset);
        index_offsets[channel_id] = position;
        emitRecord(kMessageIndex, index.content());
      }
    }
    RecordBuilder chunk_index;
    chunk_index.u64(chunk_start_time).u64(chunk_end_time).u64(chunk_offset).u64(chunk_length).u16u64Map(index_offsets);
    chunk_index.u64(position - indexes_start).string(compression).u64(compressed.size()).u64(chunk.size());
    chunk_indexes.push_back(chunk_index.content());

    ++chunk_count;
    chunk.clear();
    chunk_message_index.clear();
    chunk_has_message = false;
    chunk_start_time = chunk_end_time = 0;
  }

  std::vector<std::uint8_t> statisticsContent() const {
    RecordBuilder b;
    b.u64(message_count).u16(static_cast<std::uint16_t>(schemas.size())).u32(static_cast<std::uint32_t>(channels.size()));
    b.u32(static_cast<std::uint32_t>(attachment_indexes.size())).u32(static_cast<std::uint32_t>(metadata_indexes.size()));
    b.u32(chunk_count).u64(start_time).u64(end_time);
    std::map<std::uint16_t, std::uint64_t> counts;
    for (const auto& channel : channels) counts[channel.id] = 0;
    for (const auto& [id, count] : channel_counts) counts[id] = count;
    b.u16u64Map(counts);
    return b.content();
  }

  void writeGroup(std::vector<SummaryGroup>& groups, std::uint8_t opcode,
                  const std::vector<std::vector<std::uint8_t>>& records) {
    if (records.empty()) return;
    const std::uint64_t start = position;
    for (const auto& content : records) emitRecord(opcode, content);
    groups.push_back({opcode, start, position - start});
  }

  void writeSummary(std::uint64_t& summary_start, std::uint64_t& summary_offset_start) {
    summary_start = position;
    in_summary = true;
    std::vector<SummaryGroup> groups;
    std::vector<std::vector<std::uint8_t>> records;
    for (const auto& schema : schemas) records.push_back(schemaContent(schema));
    writeGroup(groups, kSchema, records);
    records.clear();
    for (const auto& channel : channels) records.push_back(channelContent(channel));
    writeGroup(groups, kChannel, records);
    writeGroup(groups, kStatistics, {statisticsContent()});
    writeGroup(groups, kChunkIndex, chunk_indexes);
    writeGroup(groups, kAttachmentIndex, attachment_indexes);
    writeGroup(groups, kMetadataIndex, metadata_indexes);
    summary_offset_start = position;
    for (const auto& group : groups) {
      RecordBuilder b;
      b.u8(group.opcode).u64(group.start).u64(group.length);
      emitRecord(kSummaryOffset, b.content());
    }
  }

  void close() {
    flushChunk();
    RecordBuilder data_end;
    data_end.u32(options.write_crcs ? data_crc.value() : 0);
    emitRecord(kDataEnd, data_end.content());
    in_data_section = false;

    std::uint64_t summary_start = 0, summary_offset_start = 0;
    if (options.write_summary) writeSummary(summary_start, summary_offset_start);
    std::vector<std::uint8_t> footer{kFooter};
    appendLe(footer, kFooterContentSize, 8);
    appendLe(footer, summary_start, 8);
    appendLe(footer, summary_offset_start, 8);
    emit(footer.data(), footer.size());
    in_summary = false;
    const std::uint32_t crc = options.write_summary && options.write_crcs ? summary_crc.value() : 0;
    std::vector<std::uint8_t> tail;
    appendLe(tail, crc, 4);
    tail.insert(tail.end(), std::begin(kMagic), std::end(kMagic));
    emit(tail.data(), tail.size());
    out.close();
    if (!out) fail("closing the file failed");
  }
};

McapWriter McapWriter::create(const std::string& path, const McapWriterOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec)) throw Error(path + ": already exists; refusing to overwrite it");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = options;
  if (impl->options.chunk_size == 0) impl->options.chunk_size = 1;
  impl->out.open(path, std::ios::binary | std::ios::trunc);
  if (!impl->out) throw Error(path + ": cannot create the file");
  impl->emit(kMagic, sizeof kMagic);
  RecordBuilder header;
  header.string("ros2").string("coloc");
  impl->emitRecord(kHeader, header.content());
  return McapWriter(std::move(impl));
}

McapWriter::McapWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

McapWriter::~McapWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() reports errors to callers that want them.
  }
}

McapWriter::McapWriter(McapWriter&&) noexcept = default;
McapWriter& McapWriter::operator=(McapWriter&&) noexcept = default;

void McapWriter::addTopic(const TopicInfo& topic) {
  Impl& w = *impl_;
  if (w.closed) w.fail("addTopic after close");
  if (w.channel_of_topic.count(topic.name)) w.fail("topic " + topic.name + " declared twice");
  if (w.channels.size() >= UINT16_MAX) w.fail("more than 65535 topics");
  ChannelRecord channel;
  channel.id = static_cast<std::uint16_t>(w.channels.size() + 1);
  channel.schema_id = w.schemaFor(topic);
  channel.topic = topic.name;
  channel.message_encoding = topic.serialization_format.empty() ? "cdr" : topic.serialization_format;
  channel.metadata = topic.metadata;
  channel.metadata["offered_qos_profiles"] = topic.offered_qos_profiles;
  appendRecord(w.chunk, kChannel, channelContent(channel));
  w.channel_of_topic[topic.name] = channel.id;
  w.channels.push_back(std::move(channel));
}

void McapWriter::write(const std::string& topic, Stamp log_time, Stamp publish_time, const std::uint8_t* data,
                       std::size_t size) {
  Impl& w = *impl_;
  if (w.closed) w.fail("write after close");
  const auto channel = w.channel_of_topic.find(topic);
  if (channel == w.channel_of_topic.end()) w.fail("topic " + topic + " was not declared with addTopic");
  if (log_time < 0 || publish_time < 0) {
    w.fail("message on " + topic + " has a negative time stamp, which MCAP (uint64 nanoseconds) cannot hold");
  }
  w.appendMessage(channel->second, static_cast<std::uint64_t>(log_time), static_cast<std::uint64_t>(publish_time),
                  data, size);
  w.countMessage(channel->second, static_cast<std::uint64_t>(log_time));
  if (w.chunk.size() >= w.options.chunk_size) w.flushChunk();
}

void McapWriter::write(const BagMessage& message) {
  write(message.topic, message.log_time, message.publish_time.value_or(message.log_time), message.data.data(),
        message.data.size());
}

// Attachments and metadata records stand between chunks, never inside one, and are indexed in the summary.
void McapWriter::writeAttachment(const BagAttachment& attachment) {
  Impl& w = *impl_;
  if (w.closed) w.fail("writeAttachment after close");
  if (attachment.log_time < 0 || attachment.create_time < 0) w.fail("attachment '" + attachment.name + "' has a negative time stamp");
  w.flushChunk();
  const std::uint64_t offset = w.position;
  w.emitRecord(kAttachment, attachmentContent(attachment));
  RecordBuilder index;
  index.u64(offset).u64(w.position - offset).u64(static_cast<std::uint64_t>(attachment.log_time));
  index.u64(static_cast<std::uint64_t>(attachment.create_time)).u64(attachment.data.size()).string(attachment.name).string(attachment.media_type);
  w.attachment_indexes.push_back(index.content());
}

void McapWriter::writeMetadata(const BagMetadataRecord& metadata) {
  Impl& w = *impl_;
  if (w.closed) w.fail("writeMetadata after close");
  w.flushChunk();
  const std::uint64_t offset = w.position;
  w.emitRecord(kMetadata, metadataContent(metadata));
  RecordBuilder index;
  index.u64(offset).u64(w.position - offset).string(metadata.name);
  w.metadata_indexes.push_back(index.content());
}

void McapWriter::close() {
  if (impl_->closed) return;
  impl_->closed = true;  // even if closing fails: a half-written file must not be appended to
  impl_->close();
}

}  // namespace coloc::io
