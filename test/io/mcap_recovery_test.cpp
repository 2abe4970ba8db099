// MCAP files that were never closed (the recorder stopped by a crash or a power cut): refused by
// default with a hint, read up to where their whole records end when opened with recovery.
#include <gtest/gtest.h>

#include <cstring>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/mcap_writer.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;
using testing::nav2Bag;
using testing::readAllMessages;
using testing::readBytes;
using testing::ScratchDir;
using testing::writeBytes;

struct TopRecord {
  std::uint8_t opcode = 0;
  std::size_t offset = 0, end = 0;
};

/// The top-level records of a whole file, walked from the specification's framing alone (opcode, u64
/// length), up to the Data End record.
std::vector<TopRecord> topRecords(const std::vector<std::uint8_t>& file) {
  std::vector<TopRecord> records;
  for (std::size_t at = 8; at + 9 <= file.size();) {
    std::uint64_t length = 0;
    std::memcpy(&length, file.data() + at + 1, 8);
    records.push_back({file[at], at, at + 9 + static_cast<std::size_t>(length)});
    if (file[at] == 0x0F) break;  // Data End
    at = records.back().end;
  }
  return records;
}

/// The Chunk records among them.
std::vector<TopRecord> chunkRecords(const std::vector<std::uint8_t>& file) {
  std::vector<TopRecord> chunks;
  for (const TopRecord& r : topRecords(file))
    if (r.opcode == 0x06) chunks.push_back(r);
  return chunks;
}

std::vector<BagMessage> readRecovering(const std::string& path, std::vector<RecoveredFile>* recovered = nullptr,
                                       std::uint64_t* counted = nullptr) {
  BagReader reader = BagReader::open(path, BagReadOptions{true});
  if (recovered) *recovered = reader.recovered();
  if (counted) *counted = reader.messageCount();
  std::vector<BagMessage> messages;
  BagMessage message;
  while (reader.next(message)) messages.push_back(message);
  return messages;
}

void expectSameMessages(const std::vector<BagMessage>& got, const std::vector<BagMessage>& expected, std::size_t count) {
  ASSERT_EQ(got.size(), count);
  ASSERT_LE(count, expected.size());
  for (std::size_t i = 0; i < count; ++i) {
    EXPECT_EQ(got[i].topic, expected[i].topic) << i;
    EXPECT_EQ(got[i].log_time, expected[i].log_time) << i;
    EXPECT_EQ(got[i].data, expected[i].data) << i;
  }
}

std::string cutCopy(const ScratchDir& dir, const std::vector<std::uint8_t>& full, std::size_t size) {
  const std::string path = dir / ("cut_" + std::to_string(size) + ".mcap");
  writeBytes(path, std::vector<std::uint8_t>(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(size)));
  return path;
}

/// One message per uncompressed chunk, so that the messages a cut leaves whole are known from the
/// framing alone.
std::string oneMessagePerChunk(const ScratchDir& dir, std::size_t messages) {
  McapWriterOptions options;
  options.compression = McapCompression::kNone;
  options.chunk_size = 1;  // every message closes its chunk
  options.write_message_indexes = false;
  return testing::rewriteNav2(dir / "one_per_chunk.mcap", options, messages);
}

TEST(McapRecovery, ACutFileGivesExactlyTheMessagesOfTheChunksThatEndBeforeTheCut) {
  ScratchDir dir;
  const std::string whole = oneMessagePerChunk(dir, 40);
  const std::vector<BagMessage> expected = readAllMessages(whole);
  const std::vector<std::uint8_t> full = readBytes(whole);
  const std::vector<TopRecord> chunks = chunkRecords(full);
  ASSERT_EQ(chunks.size(), expected.size());  // the layout the expectation rests on
  // Cuts at a chunk's first byte, inside its prefix, inside its content, one byte short of its end.
  for (const std::size_t k : {std::size_t{0}, std::size_t{1}, std::size_t{17}, chunks.size() - 1}) {
    for (const std::size_t size : {chunks[k].offset, chunks[k].offset + 5, (chunks[k].offset + chunks[k].end) / 2, chunks[k].end - 1}) {
      SCOPED_TRACE("cut at byte " + std::to_string(size) + ", inside chunk " + std::to_string(k));
      std::vector<RecoveredFile> recovered;
      std::uint64_t counted = 0;
      const std::string path = cutCopy(dir, full, size);
      const std::vector<BagMessage> got = readRecovering(path, &recovered, &counted);
      expectSameMessages(got, expected, k);
      EXPECT_EQ(counted, k);
      ASSERT_EQ(recovered.size(), 1u);
      EXPECT_EQ(recovered[0].file, path);
      EXPECT_EQ(recovered[0].file_bytes, size);
      EXPECT_EQ(recovered[0].messages, k);
      EXPECT_EQ(recovered[0].read_bytes, chunks[k].offset);
      EXPECT_FALSE(recovered[0].reason.empty());
    }
  }
  // Cut right after the last chunk, and after the Data End record: every message, nothing cut but the end.
  for (const std::size_t size : {chunks.back().end, chunks.back().end + 13}) {
    std::vector<RecoveredFile> recovered;
    expectSameMessages(readRecovering(cutCopy(dir, full, size), &recovered), expected, expected.size());
    ASSERT_EQ(recovered.size(), 1u);
    EXPECT_EQ(recovered[0].read_bytes, size);
  }
}

TEST(McapRecovery, ARecordingCutInsideACompressedChunkKeepsEveryMessageBeforeThatChunk) {
  ScratchDir dir;
  McapWriterOptions options;  // zstd, as rosbag2 writes, in chunks of 64 KB
  options.chunk_size = 64 * 1024;
  const std::string whole = testing::rewriteNav2(dir / "zstd.mcap", options, 100000);
  const std::vector<BagMessage> expected = readAllMessages(whole);
  const std::vector<std::uint8_t> full = readBytes(whole);
  const std::vector<TopRecord> records = topRecords(full);
  std::size_t cut_chunk = 0, chunks = 0;
  for (std::size_t i = 0; i < records.size(); ++i)
    if (records[i].opcode == 0x06 && ++chunks == 2) cut_chunk = i;  // the second chunk, cut in its middle
  ASSERT_GT(cut_chunk, 0u) << "the recording has fewer than two chunks";
  const std::size_t size = (records[cut_chunk].offset + records[cut_chunk].end) / 2;
  // The messages of the first chunk: those of a copy ending right after it (read with recovery too).
  const std::size_t before = readRecovering(cutCopy(dir, full, records[cut_chunk].offset)).size();
  ASSERT_GT(before, 0u);
  ASSERT_LT(before, expected.size());
  std::vector<RecoveredFile> recovered;
  expectSameMessages(readRecovering(cutCopy(dir, full, size), &recovered), expected, before);
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_EQ(recovered[0].read_bytes, records[cut_chunk].offset);
  EXPECT_NE(recovered[0].reason.find("Chunk record at byte offset " + std::to_string(records[cut_chunk].offset)), std::string::npos)
      << recovered[0].reason;
}

TEST(McapRecovery, WithoutRecoveryACutFileIsRefusedSayingHowToReadIt) {
  ScratchDir dir;
  const std::vector<std::uint8_t> full = readBytes(nav2Bag());
  const std::string path = cutCopy(dir, full, full.size() / 2);
  const std::string message = errorMessage([&] { readAllMessages(path); });
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  EXPECT_NE(message.find("--recover"), std::string::npos) << message;
}

TEST(McapRecovery, AClosedFileReadsTheSameWithRecoveryAndReportsNothingRecovered) {
  const std::vector<BagMessage> expected = readAllMessages(nav2Bag());
  std::vector<RecoveredFile> recovered;
  expectSameMessages(readRecovering(nav2Bag(), &recovered), expected, expected.size());
  EXPECT_TRUE(recovered.empty());
}

TEST(McapRecovery, ACorruptChunkInAClosedFileIsStillAnErrorWithRecoveryOn) {
  ScratchDir dir;
  std::vector<std::uint8_t> bytes = readBytes(oneMessagePerChunk(dir, 10));
  const std::vector<TopRecord> records = topRecords(bytes);
  const auto chunk = std::find_if(records.begin(), records.end(), [](const TopRecord& r) { return r.opcode == 0x06; });
  ASSERT_NE(chunk, records.end());
  bytes[chunk->end - 1] ^= 0xFF;  // a byte of its (uncompressed, CRC-checked) records
  const std::string path = dir / "flipped.mcap";
  writeBytes(path, bytes);
  const std::string message = errorMessage([&] { readRecovering(path); });
  EXPECT_NE(message.find("CRC mismatch"), std::string::npos) << message;
}

TEST(McapRecovery, ZerosAfterTheCutAsAPowerCutLeavesThemEndReadingAtTheFirstOfThem) {
  ScratchDir dir;
  const std::string whole = oneMessagePerChunk(dir, 20);
  const std::vector<BagMessage> expected = readAllMessages(whole);
  std::vector<std::uint8_t> bytes = readBytes(whole);
  const std::vector<TopRecord> chunks = chunkRecords(bytes);
  ASSERT_EQ(chunks.size(), expected.size());
  // The file's blocks were allocated, their data never written: zeros from chunk 12 on.
  bytes.resize(chunks[12].offset);
  bytes.resize(bytes.size() + 4096, 0);
  const std::string path = dir / "zeros.mcap";
  writeBytes(path, bytes);
  std::vector<RecoveredFile> recovered;
  expectSameMessages(readRecovering(path, &recovered), expected, 12);
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_EQ(recovered[0].read_bytes, chunks[12].offset);
  EXPECT_NE(recovered[0].reason.find("invalid opcode"), std::string::npos) << recovered[0].reason;
}

/// Little-endian bytes of records the writer would never produce.
struct Bytes : std::vector<std::uint8_t> {
  Bytes& le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Bytes& str(const std::string& text) {
    le(text.size(), 4);
    insert(end(), text.begin(), text.end());
    return *this;
  }
  Bytes& record(std::uint8_t opcode, const Bytes& content) {
    push_back(opcode);
    le(content.size(), 8);
    insert(end(), content.begin(), content.end());
    return *this;
  }
};

/// Magic, Header, a schema and its channel 1 (/chatter), unchunked, nothing closing it.
Bytes chatterStart() {
  Bytes file;
  file.reserve(256);  // GCC 12 otherwise warns of an overflow in the first insert (a false positive)
  file.insert(file.end(), {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'});
  file.record(0x01, Bytes().str("ros2").str("test"));
  file.record(0x03, Bytes().le(1, 2).str("std_msgs/msg/String").str("ros2msg").str("string data"));
  file.record(0x04, Bytes().le(1, 2).le(1, 2).str("/chatter").str("cdr").le(0, 4));
  return file;
}

/// A Message record's content on channel 1.
Bytes chatterMessage() { return Bytes().le(1, 2).le(0, 4).le(5, 8).le(5, 8).str("hello"); }

TEST(McapRecovery, AnUnreadableAttachmentEndsReadingAtTheSamePlaceWhetherAttachmentsAreKeptOrNot) {
  // Unchunked: a schema, a channel, a message, an attachment whose name claims 2^25 bytes, a message.
  Bytes file = chatterStart();
  const Bytes message = chatterMessage();
  file.record(0x05, message);
  file.record(0x09, Bytes().le(0, 8).le(0, 8).le(1u << 25, 4));
  file.record(0x05, message);
  ScratchDir dir;
  const std::string path = dir / "attachment.mcap";
  writeBytes(path, file);
  for (const bool keep : {false, true}) {
    BagReader reader = BagReader::open(path, BagReadOptions{true});
    reader.keepAttachments(keep);
    std::uint64_t read = 0;
    BagMessage m;
    while (reader.next(m)) ++read;
    EXPECT_EQ(read, 1u) << "attachments kept: " << keep;
    EXPECT_EQ(reader.messageCount(), read);
    ASSERT_EQ(reader.recovered().size(), 1u);
    EXPECT_NE(reader.recovered()[0].reason.find("Attachment record"), std::string::npos) << reader.recovered()[0].reason;
  }
}

TEST(McapRecovery, AChannelOnAnUndefinedSchemaEndsTheReadingWhereTheCountingScanEnded) {
  // The scan that counts and the pass that reads meet the same records from the same start.
  Bytes file = chatterStart();
  const Bytes message = chatterMessage();
  file.record(0x05, message);
  file.record(0x04, Bytes().le(3, 2).le(44, 2).str("/other").str("cdr").le(0, 4));
  file.record(0x05, message);
  ScratchDir dir;
  const std::string path = dir / "channel.mcap";
  writeBytes(path, file);
  std::vector<RecoveredFile> recovered;
  std::uint64_t counted = 0;
  EXPECT_EQ(readRecovering(path, &recovered, &counted).size(), 1u);
  EXPECT_EQ(counted, 1u);
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_NE(recovered[0].reason.find("refers to schema 44"), std::string::npos) << recovered[0].reason;
}

TEST(McapRecovery, TheFuzzersFindingsReadExactlyAsManyMessagesAsTheirOpeningCountedKeptOrNot) {
  for (const char* name : {"mcap_cut_attachment_read_only_when_kept.mcap", "mcap_cut_channel_registered_before_its_refusal.mcap"})
    for (const bool keep : {false, true}) {
      BagReader reader = BagReader::open(std::string(COLOC_SOURCE_DIR "/test/support/fuzz_findings/") + name, BagReadOptions{true});
      reader.keepAttachments(keep);
      std::uint64_t read = 0;
      BagMessage m;
      while (reader.next(m)) ++read;
      EXPECT_EQ(read, reader.messageCount()) << name << ", attachments kept: " << keep;
      EXPECT_EQ(reader.recovered().size(), 1u) << name;
    }
}

TEST(McapRecovery, AFileCutInsideItsHeaderHasNothingToRecoverAndIsRefused) {
  ScratchDir dir;
  const std::vector<std::uint8_t> full = readBytes(nav2Bag());
  for (const std::size_t size : {std::size_t{8}, std::size_t{12}, std::size_t{20}}) {
    const std::string path = cutCopy(dir, full, size);
    const std::string message = errorMessage([&] { readRecovering(path); });
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  }
}

TEST(McapRecovery, AnUnclosedSplitRecordingReadsItsWholeFilesAndTheLastUpToItsCut) {
  // A rosbag2 directory whose recorder died: no metadata.yaml, the last split file cut.
  ScratchDir dir;
  ScratchDir source;
  const std::string whole = oneMessagePerChunk(source, 30);
  const std::vector<BagMessage> expected = readAllMessages(whole);
  const std::vector<std::uint8_t> full = readBytes(whole);
  const std::vector<TopRecord> chunks = chunkRecords(full);
  const std::string bag = dir / "bag";
  std::filesystem::create_directory(bag);
  writeBytes(bag + "/bag_0.mcap", full);
  writeBytes(bag + "/bag_1.mcap", std::vector<std::uint8_t>(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(chunks[7].end + 3)));
  std::vector<RecoveredFile> recovered;
  std::uint64_t counted = 0;
  const std::vector<BagMessage> got = readRecovering(bag, &recovered, &counted);
  ASSERT_EQ(got.size(), expected.size() + 8);
  EXPECT_EQ(counted, got.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    const BagMessage& want = expected[i < expected.size() ? i : i - expected.size()];
    EXPECT_EQ(got[i].log_time, want.log_time) << i;
    EXPECT_EQ(got[i].data, want.data) << i;
  }
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_EQ(recovered[0].file, bag + "/bag_1.mcap");
  EXPECT_EQ(recovered[0].messages, 8u);
}

}  // namespace
}  // namespace coloc::io
