// MCAP storage reader, written from the MCAP specification. It checks both magics and the footer on
// open, takes schemas, channels and message counts from the summary section when the file has one
// (else from one scan of the data section), and then streams the data section record by record,
// holding at most one decompressed chunk in memory.
//
// A file without its closing magic and footer was not closed: its writer stopped (a crash, a power
// cut) and left it cut, usually inside a chunk. Refused by default; opened to be recovered, its data
// section is read from the start until a record is cut or unreadable, and the same scan that counts
// its messages finds that place, so that counts and messages agree.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>

#include "chunk_compression.hpp"
#include "coloc/core/error.hpp"
#include "crc32.hpp"
#include "mcap_records.hpp"
#include "storage_reader.hpp"

namespace coloc::io::detail {
namespace {

using namespace mcap;

std::string hex32(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

/// A record located in memory (a decompressed chunk or the summary section).
struct RecordSpan {
  std::uint8_t opcode = 0;
  const std::uint8_t* content = nullptr;
  std::size_t size = 0;
};

/// Reads the record at `position` of a buffer and advances past it. `where` names the buffer and
/// how its offsets are meant ("... at byte offset" / "... at offset ... of the decompressed records").
RecordSpan nextBufferedRecord(const std::vector<std::uint8_t>& buffer, std::size_t& position,
                              const std::string& where) {
  const std::size_t left = buffer.size() - position;
  if (left < kRecordPrefixSize) {
    throw Error(where + " " + std::to_string(position) + ": truncated record header (" + std::to_string(left) +
                " bytes left)");
  }
  RecordSpan span;
  span.opcode = buffer[position];
  const std::uint64_t length = readU64Le(buffer.data() + position + 1);
  if (length > left - kRecordPrefixSize) {
    throw Error(where + " " + std::to_string(position) + ": " + opcodeName(span.opcode) + " record claims " +
                std::to_string(length) + " bytes, only " + std::to_string(left - kRecordPrefixSize) + " left");
  }
  span.content = buffer.data() + position + kRecordPrefixSize;
  span.size = static_cast<std::size_t>(length);
  position += kRecordPrefixSize + span.size;
  return span;
}

// Appended to the errors that mean a file was not closed.
const char* const kNotClosedHint = " (a recording that was never closed is read up to where it stops with recovery on: --recover)";

class McapReader final : public StorageReader {
 public:
  McapReader(const std::string& path, bool recover);
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  bool next(BagMessage& message) override;
  void keepAttachments(bool keep) override { keep_attachments_ = keep; }
  std::vector<BagAttachment> takeAttachments() override { return std::move(attachments_); }
  std::vector<BagMetadataRecord> takeMetadata() override { return std::move(metadata_); }
  std::optional<RecoveredFile> recovery() const override { return recovery_; }

 private:
  struct RecordHead {
    std::uint8_t opcode = 0;
    std::uint64_t offset = 0;  // of the opcode byte
    std::uint64_t length = 0;  // of the content
  };

  [[noreturn]] void fail(const std::string& reason) const { throw Error(path_ + ": " + reason); }
  void readAt(std::uint64_t offset, void* out, std::size_t size);
  RecordHead readRecordHead(std::uint64_t offset, std::uint64_t section_end);
  void loadContent(const RecordHead& head);
  std::string where(const RecordHead& head) const;

  void checkMagic(std::uint64_t offset, const char* which);
  bool looksClosed();
  bool nextRecord(BagMessage& message);
  Footer readFooter();
  void readHeaderRecord();
  void readSummary(const Footer& footer);
  void countMessagesByScanning();
  void rewind();

  void registerSchema(SchemaRecord schema);
  void registerChannel(const ChannelRecord& channel, const std::string& where);
  bool dispatch(std::uint8_t opcode, RecordCursor& cursor, BagMessage& message);
  bool fillMessage(RecordCursor& cursor, BagMessage& message);
  void loadChunk(const RecordHead& head);
  bool nextInChunk(BagMessage& message);

  std::string path_;
  std::ifstream file_;
  std::uint64_t file_size_ = 0;
  std::uint64_t data_start_ = 0;  // first record after the Header
  std::uint64_t data_end_ = 0;    // where the data section must end

  std::map<std::uint16_t, SchemaRecord> schemas_;
  std::map<std::uint16_t, ChannelRecord> channels_;
  std::vector<TopicInfo> topics_;
  std::map<std::uint16_t, std::size_t> topic_of_channel_;
  bool keep_attachments_ = false;
  std::vector<BagAttachment> attachments_;  // met in the data section, for conversion
  std::vector<BagMetadataRecord> metadata_;

  std::uint64_t offset_ = 0;  // next top-level record
  bool done_ = false;
  std::vector<std::uint8_t> content_;  // current top-level record's content
  std::vector<std::uint8_t> chunk_;    // current decompressed chunk
  std::size_t chunk_position_ = 0;
  std::uint64_t chunk_offset_ = 0;

  // Recovery of a file that was not closed: reading ends, without an error, where a record is cut
  // or unreadable (the top-level record's offset: a chunk's, for a record inside it).
  bool cut_ = false;
  std::uint64_t record_start_ = 0;
  std::optional<RecoveredFile> recovery_;
};

McapReader::McapReader(const std::string& path, bool recover) : path_(path) {
  file_.open(path, std::ios::binary);
  if (!file_) fail("cannot open the file for reading");
  file_.seekg(0, std::ios::end);
  file_size_ = static_cast<std::uint64_t>(file_.tellg());
  if (file_size_ < sizeof kMagic) {
    fail("truncated or not an MCAP file: " + std::to_string(file_size_) + " bytes, shorter than the magic");
  }
  checkMagic(0, "leading");
  if (recover && !looksClosed()) {
    cut_ = true;
    data_end_ = file_size_;
    readHeaderRecord();  // a file cut inside its Header holds nothing to recover: refused
    recovery_.emplace();
    recovery_->file = path_;
    recovery_->file_bytes = file_size_;
    countMessagesByScanning();
    for (const TopicInfo& topic : topics_) recovery_->messages += topic.message_count;
    // The reading starts from where the scan started (the topics stay, with their counts), so that it
    // stops where the scan did.
    schemas_.clear();
    channels_.clear();
    topic_of_channel_.clear();
    rewind();
    return;
  }
  if (file_size_ < 2 * sizeof kMagic + kFooterRecordSize) {
    fail("truncated: " + std::to_string(file_size_) + " bytes, too short to hold a Footer and the closing magic" + kNotClosedHint);
  }
  checkMagic(file_size_ - sizeof kMagic, "closing");
  const Footer footer = readFooter();
  readHeaderRecord();
  if (footer.summary_start != 0) readSummary(footer);
  if (topics_.empty() || channels_.empty()) countMessagesByScanning();
  rewind();
}

void McapReader::readAt(std::uint64_t offset, void* out, std::size_t size) {
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(offset));
  file_.read(static_cast<char*>(out), static_cast<std::streamsize>(size));
  if (!file_) fail("read of " + std::to_string(size) + " bytes at byte offset " + std::to_string(offset) + " failed");
}

void McapReader::checkMagic(std::uint64_t offset, const char* which) {
  std::uint8_t magic[sizeof kMagic];
  readAt(offset, magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    if (offset == 0) fail("not an MCAP file: bad magic at byte offset 0");
    fail(std::string("no ") + which + " MCAP magic at byte offset " + std::to_string(offset) +
         ": the file is truncated or corrupt" + kNotClosedHint);
  }
}

// A closed file ends with a Footer record and the magic; anything else was cut.
bool McapReader::looksClosed() {
  if (file_size_ < 2 * sizeof kMagic + kFooterRecordSize) return false;
  std::uint8_t tail[kFooterRecordSize + sizeof kMagic];
  readAt(file_size_ - sizeof tail, tail, sizeof tail);
  return tail[0] == kFooter && readU64Le(tail + 1) == kFooterContentSize &&
         std::memcmp(tail + kFooterRecordSize, kMagic, sizeof kMagic) == 0;
}

Footer McapReader::readFooter() {
  const std::uint64_t offset = file_size_ - sizeof kMagic - kFooterRecordSize;
  std::uint8_t bytes[kFooterRecordSize];
  readAt(offset, bytes, sizeof bytes);
  if (bytes[0] != kFooter || readU64Le(bytes + 1) != kFooterContentSize) {
    fail("no Footer record at byte offset " + std::to_string(offset) + ": the file is truncated or corrupt" + kNotClosedHint);
  }
  RecordCursor cursor(bytes + kRecordPrefixSize, kFooterContentSize, path_ + ": Footer");
  const Footer footer = parseFooter(cursor);
  data_end_ = offset;
  for (const std::uint64_t start : {footer.summary_start, footer.summary_offset_start}) {
    if (start == 0) continue;
    if (start < sizeof kMagic || start > offset) {
      fail("Footer at byte offset " + std::to_string(offset) + " points to a summary at byte offset " +
           std::to_string(start) + ", outside the file's records");
    }
    data_end_ = std::min(data_end_, start);
  }
  return footer;
}

void McapReader::readHeaderRecord() {
  const RecordHead head = readRecordHead(sizeof kMagic, data_end_);
  if (head.opcode != kHeader) {
    fail("the first record (byte offset 8) is " + opcodeName(head.opcode) + ", not Header");
  }
  loadContent(head);
  RecordCursor cursor(content_.data(), content_.size(), where(head));
  cursor.string("profile");
  cursor.string("library");
  data_start_ = head.offset + kRecordPrefixSize + head.length;
}

McapReader::RecordHead McapReader::readRecordHead(std::uint64_t offset, std::uint64_t section_end) {
  if (offset > section_end || section_end - offset < kRecordPrefixSize) {
    fail("truncated record header at byte offset " + std::to_string(offset) + " (the section ends at byte " +
         std::to_string(section_end) + ")");
  }
  std::uint8_t prefix[kRecordPrefixSize];
  readAt(offset, prefix, sizeof prefix);
  RecordHead head{prefix[0], offset, readU64Le(prefix + 1)};
  if (head.opcode == 0) fail("invalid opcode 0x00 at byte offset " + std::to_string(offset) + ": corrupt file");
  const std::uint64_t left = section_end - offset - kRecordPrefixSize;
  if (head.length > left) {
    fail(opcodeName(head.opcode) + " record at byte offset " + std::to_string(offset) + " claims " +
         std::to_string(head.length) + " bytes, only " + std::to_string(left) + " remain before byte " +
         std::to_string(section_end) + ": the file is truncated or corrupt");
  }
  return head;
}

void McapReader::loadContent(const RecordHead& head) {
  content_.resize(static_cast<std::size_t>(head.length));
  if (!content_.empty()) readAt(head.offset + kRecordPrefixSize, content_.data(), content_.size());
}

std::string McapReader::where(const RecordHead& head) const {
  return path_ + ": " + opcodeName(head.opcode) + " record at byte offset " + std::to_string(head.offset);
}

void McapReader::readSummary(const Footer& footer) {
  // The summary CRC covers the summary section and the Footer up to its summary_crc field.
  const std::uint64_t footer_offset = file_size_ - sizeof kMagic - kFooterRecordSize;
  std::vector<std::uint8_t> summary(static_cast<std::size_t>(footer_offset - footer.summary_start) +
                                    kRecordPrefixSize + 16);
  readAt(footer.summary_start, summary.data(), summary.size());
  if (footer.summary_crc != 0) {
    const std::uint32_t computed = crc32(summary.data(), summary.size());
    if (computed != footer.summary_crc) {
      fail("summary section CRC mismatch (stored " + hex32(footer.summary_crc) + ", computed " + hex32(computed) +
           "): the summary at byte offset " + std::to_string(footer.summary_start) + " is corrupt");
    }
  }
  summary.resize(static_cast<std::size_t>(footer_offset - footer.summary_start));
  const std::string where_prefix = path_ + ": summary record at byte offset";
  std::vector<std::pair<ChannelRecord, std::string>> channels;  // with where each was read
  std::optional<Statistics> statistics;
  for (std::size_t position = 0; position < summary.size();) {
    const std::size_t record_offset = position;
    const RecordSpan span = nextBufferedRecord(summary, position, where_prefix);
    RecordCursor cursor(span.content, span.size,
                        where_prefix + " " + std::to_string(footer.summary_start + record_offset));
    if (span.opcode == kSchema) registerSchema(parseSchema(cursor));
    if (span.opcode == kChannel) channels.emplace_back(parseChannel(cursor), cursor.where());
    if (span.opcode == kStatistics) statistics = parseStatistics(cursor);
  }
  // A summary may repeat channels without their schemas (valid MCAP: repeatSchemas false): the
  // schemas are then only in the data section, and one scan of it finds both.
  for (const auto& [channel, where] : channels)
    if (channel.schema_id != 0 && schemas_.count(channel.schema_id) == 0) {
      topics_.clear();
      topic_of_channel_.clear();
      return;
    }
  // Channels after all schemas: the specification groups summary records by opcode but does not
  // order the groups.
  for (const auto& [channel, where] : channels) registerChannel(channel, where);
  if (!statistics || statistics->channel_message_counts.empty()) {
    topics_.clear();  // no counts: the scan rebuilds topics with them
    topic_of_channel_.clear();
    return;
  }
  for (const auto& [channel_id, count] : statistics->channel_message_counts) {
    const auto topic = topic_of_channel_.find(channel_id);
    if (topic != topic_of_channel_.end()) topics_[topic->second].message_count += count;
  }
}

void McapReader::registerSchema(SchemaRecord schema) {
  if (schema.id == 0) return;  // invalid by specification; readers ignore it
  schemas_.emplace(schema.id, std::move(schema));
}

void McapReader::registerChannel(const ChannelRecord& channel, const std::string& where) {
  if (channels_.count(channel.id)) return;
  TopicInfo info;
  info.name = channel.topic;
  info.serialization_format = channel.message_encoding;
  if (channel.schema_id != 0) {
    const auto schema = schemas_.find(channel.schema_id);
    if (schema == schemas_.end()) {
      throw Error(where + ": Channel " + std::to_string(channel.id) + " (" + channel.topic + ") refers to schema " +
                  std::to_string(channel.schema_id) + ", which no Schema record defines before it");
    }
    info.type = schema->second.name;
    info.message_definition = schema->second.data;
    info.message_definition_encoding = schema->second.encoding;
  }
  channels_.emplace(channel.id, channel);  // only once it is known good
  info.metadata = channel.metadata;
  const auto qos = info.metadata.find("offered_qos_profiles");
  if (qos != info.metadata.end()) {
    info.offered_qos_profiles = qos->second;
    info.metadata.erase(qos);
  }
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    if (topics_[i].name == info.name) {
      topic_of_channel_[channel.id] = i;
      return;
    }
  }
  topic_of_channel_[channel.id] = topics_.size();
  topics_.push_back(std::move(info));
}

// Without summary statistics the only way to know the counts is to read every message once; the
// channels met on the way become the topics.
void McapReader::countMessagesByScanning() {
  rewind();
  channels_.clear();
  topics_.clear();
  topic_of_channel_.clear();
  BagMessage message;
  while (next(message)) {
    const auto topic = std::find_if(topics_.begin(), topics_.end(),
                                    [&](const TopicInfo& t) { return t.name == message.topic; });
    ++topic->message_count;  // next() only returns messages on registered topics
  }
}

void McapReader::rewind() {
  offset_ = data_start_;
  done_ = false;
  // Release the buffers: a bag of many files keeps every reader open until its turn.
  std::vector<std::uint8_t>().swap(chunk_);
  std::vector<std::uint8_t>().swap(content_);
  chunk_position_ = 0;
  attachments_.clear();
  metadata_.clear();
}

bool McapReader::next(BagMessage& message) {
  if (!cut_) return nextRecord(message);
  try {
    if (nextRecord(message)) return true;
    if (recovery_->reason.empty()) {
      recovery_->read_bytes = offset_;
      recovery_->reason = offset_ < data_end_ ? "the data section is whole (its Data End record ends at byte " + std::to_string(offset_) +
                                                    "); what follows it (summary, footer) is cut"
                                              : "the file ends after a whole record, without Data End, summary or footer";
    }
  } catch (const Error& e) {
    // Where the writer stopped: everything from this record on is left unread.
    done_ = true;
    std::vector<std::uint8_t>().swap(chunk_);
    chunk_position_ = 0;
    if (recovery_->reason.empty()) {
      recovery_->read_bytes = record_start_;
      const std::string what = e.what(), prefix = path_ + ": ";
      recovery_->reason = what.compare(0, prefix.size(), prefix) == 0 ? what.substr(prefix.size()) : what;
    }
  }
  return false;
}

bool McapReader::nextRecord(BagMessage& message) {
  for (;;) {
    if (chunk_position_ < chunk_.size()) {
      if (nextInChunk(message)) return true;
      continue;
    }
    if (done_) return false;
    if (offset_ >= data_end_) {  // no Data End record: tolerated, the footer checks passed (or the file was cut)
      done_ = true;
      return false;
    }
    record_start_ = offset_;
    const RecordHead head = readRecordHead(offset_, data_end_);
    offset_ = head.offset + kRecordPrefixSize + head.length;
    switch (head.opcode) {
      case kChunk:
        loadChunk(head);
        break;
      case kMessage:
      case kSchema:
      case kChannel: {
        loadContent(head);
        RecordCursor cursor(content_.data(), content_.size(), where(head));
        if (dispatch(head.opcode, cursor, message)) return true;
        break;
      }
      case kAttachment:
      case kMetadata: {
        // A replay has no use for them: not even read, unless the file was cut, where an unreadable one
        // ends what is read whether or not it is kept (the counting scan keeps none).
        if (!keep_attachments_ && !cut_) break;
        loadContent(head);
        RecordCursor cursor(content_.data(), content_.size(), where(head));
        if (head.opcode == kAttachment) {
          BagAttachment attachment = parseAttachment(cursor);
          if (keep_attachments_) attachments_.push_back(std::move(attachment));
        } else {
          BagMetadataRecord metadata = parseMetadata(cursor);
          if (keep_attachments_) metadata_.push_back(std::move(metadata));
        }
        break;
      }
      case kDataEnd:
        done_ = true;
        return false;
      case kHeader:
      case kFooter:
        fail("unexpected " + opcodeName(head.opcode) + " record at byte offset " + std::to_string(head.offset) +
             " inside the data section");
      default:
        break;  // indexes and extension records carry no messages
    }
  }
}

bool McapReader::dispatch(std::uint8_t opcode, RecordCursor& cursor, BagMessage& message) {
  switch (opcode) {
    case kMessage:
      return fillMessage(cursor, message);
    case kSchema:
      registerSchema(parseSchema(cursor));
      return false;
    case kChannel:
      registerChannel(parseChannel(cursor), cursor.where());
      return false;
    default:
      return false;
  }
}

bool McapReader::fillMessage(RecordCursor& cursor, BagMessage& message) {
  const MessageHeader header = parseMessageHeader(cursor);
  const auto topic = topic_of_channel_.find(header.channel_id);
  if (topic == topic_of_channel_.end()) {
    cursor.fail("message on channel " + std::to_string(header.channel_id) +
                ", which no Channel record defines before it");
  }
  if (header.log_time > static_cast<std::uint64_t>(INT64_MAX) ||
      header.publish_time > static_cast<std::uint64_t>(INT64_MAX)) {
    cursor.fail("time stamp beyond the int64 nanosecond range");
  }
  message.topic = topics_[topic->second].name;
  message.log_time = static_cast<Stamp>(header.log_time);
  message.publish_time = static_cast<Stamp>(header.publish_time);
  message.data.assign(cursor.current(), cursor.current() + cursor.remaining());
  return true;
}

void McapReader::loadChunk(const RecordHead& head) {
  loadContent(head);
  const std::string chunk_where = where(head);
  RecordCursor cursor(content_.data(), content_.size(), chunk_where);
  const ChunkHeader header = parseChunkHeader(cursor);
  const auto [records, size] = cursor.bytes64("records");
  chunk_ = decompressChunk(header.compression, records, size, header.uncompressed_size, chunk_where);
  if (header.uncompressed_crc != 0) {
    const std::uint32_t computed = crc32(chunk_.data(), chunk_.size());
    if (computed != header.uncompressed_crc) {
      chunk_.clear();
      fail("CRC mismatch in the Chunk record at byte offset " + std::to_string(head.offset) + " (stored " +
           hex32(header.uncompressed_crc) + ", computed " + hex32(computed) + "): the chunk is corrupt");
    }
  }
  chunk_position_ = 0;
  chunk_offset_ = head.offset;
}

bool McapReader::nextInChunk(BagMessage& message) {
  const std::string where_prefix =
      path_ + ": Chunk at byte offset " + std::to_string(chunk_offset_) + ", decompressed record offset";
  const std::size_t record_offset = chunk_position_;
  const RecordSpan span = nextBufferedRecord(chunk_, chunk_position_, where_prefix);
  RecordCursor cursor(span.content, span.size, where_prefix + " " + std::to_string(record_offset));
  return dispatch(span.opcode, cursor, message);
}

}  // namespace

std::unique_ptr<StorageReader> openMcapStorage(const std::string& path, bool recover) {
  return std::make_unique<McapReader>(path, recover);
}

}  // namespace coloc::io::detail
