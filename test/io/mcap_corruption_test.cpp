// Damaged and unusual MCAP files: every failure is a coloc::Error naming the file, the byte offset
// where it applies, and the reason; nothing crashes.
#include <gtest/gtest.h>

#include <cstring>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/mcap_writer.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;
using testing::nav2Bag;
using testing::openAndReadAll;
using testing::readBytes;
using testing::ScratchDir;
using testing::writeBytes;

/// Little-endian record builder for files the writer would never produce.
struct RawFile : std::vector<std::uint8_t> {
  RawFile& u8(std::uint8_t v) { return push_back(v), *this; }
  RawFile& u16(std::uint16_t v) { return le(v, 2); }
  RawFile& u32(std::uint32_t v) { return le(v, 4); }
  RawFile& u64(std::uint64_t v) { return le(v, 8); }
  RawFile& str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    insert(end(), s.begin(), s.end());
    return *this;
  }
  RawFile& raw(const std::vector<std::uint8_t>& b) {
    insert(end(), b.begin(), b.end());
    return *this;
  }
  RawFile& record(std::uint8_t opcode, const RawFile& content) { return u8(opcode).u64(content.size()).raw(content); }
  RawFile& le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
};

const std::vector<std::uint8_t> kMagic{0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

RawFile header() { return RawFile().str("ros2").str("test"); }
RawFile schema(std::uint16_t id) { return RawFile().u16(id).str("std_msgs/msg/String").str("ros2msg").str("string data"); }
RawFile channel(std::uint16_t id, std::uint16_t schema_id, const std::string& topic) {
  return RawFile().u16(id).u16(schema_id).str(topic).str("cdr").u32(0);
}
RawFile message(std::uint16_t channel_id, std::uint64_t time, const std::string& payload) {
  RawFile m;
  m.u16(channel_id).u32(0).u64(time).u64(time);
  m.insert(m.end(), payload.begin(), payload.end());
  return m;
}

/// Magic, Header, `records`, Data End, Footer without summary, magic.
RawFile unchunkedFile(const RawFile& records) {
  RawFile file;
  file.raw(kMagic).record(0x01, header()).raw(records).record(0x0F, RawFile().u32(0));
  file.record(0x02, RawFile().u64(0).u64(0).u32(0)).raw(kMagic);
  return file;
}

std::string writeFile(const ScratchDir& dir, const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const std::string path = dir / name;
  writeBytes(path, bytes);
  return path;
}

/// A small MCAP file of real messages, written by coloc with the given compression and CRCs.
std::string smallRecording(const ScratchDir& dir, McapCompression compression, std::size_t messages = 60) {
  McapWriterOptions options;
  options.compression = compression;
  return testing::rewriteNav2(dir / ("small_" + std::to_string(static_cast<int>(compression)) + ".mcap"), options, messages);
}

/// Offset of the first Chunk record (right after magic and Header).
std::size_t firstChunkOffset(const std::vector<std::uint8_t>& file) {
  std::uint64_t header_length = 0;
  std::memcpy(&header_length, file.data() + 9, 8);
  return 8 + 9 + static_cast<std::size_t>(header_length);
}

TEST(McapCorruption, FileCutAtAnyOfSeveralOffsetsIsReportedWithItsName) {
  ScratchDir dir;
  const std::vector<std::uint8_t> full = readBytes(nav2Bag());
  for (const std::size_t size : {std::size_t{0}, std::size_t{4}, std::size_t{8}, std::size_t{60}, std::size_t{1000},
                                 full.size() / 2, full.size() - 37, full.size() - 9, full.size() - 1}) {
    const std::string path = writeFile(dir, "cut_" + std::to_string(size) + ".mcap",
                                       std::vector<std::uint8_t>(full.begin(), full.begin() + size));
    const std::string message = errorMessage([&] { openAndReadAll(path); });
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    EXPECT_TRUE(message.find("truncated") != std::string::npos || message.find("magic") != std::string::npos)
        << message;
  }
}

TEST(McapCorruption, BadLeadingMagicSaysItIsNotMcap) {
  ScratchDir dir;
  std::vector<std::uint8_t> bytes = readBytes(nav2Bag());
  bytes[1] = 'X';
  const std::string path = writeFile(dir, "bad.mcap", bytes);
  EXPECT_NE(errorMessage([&] { openAndReadAll(path); }).find("bad.mcap: not an MCAP file: bad magic at byte offset 0"),
            std::string::npos);
}

TEST(McapCorruption, RecordLengthBeyondTheFileIsReportedWithItsOffset) {
  ScratchDir dir;
  std::vector<std::uint8_t> bytes = readBytes(nav2Bag());
  const std::size_t chunk = firstChunkOffset(bytes);
  ASSERT_EQ(bytes[chunk], 0x06);
  bytes[chunk + 8] = 0x7F;  // top byte of the chunk's length
  const std::string path = writeFile(dir, "long.mcap", bytes);
  const std::string message = errorMessage([&] { openAndReadAll(path); });
  EXPECT_NE(message.find("Chunk record at byte offset " + std::to_string(chunk) + " claims"), std::string::npos)
      << message;
}

TEST(McapCorruption, FlippedByteInAnUncompressedChunkIsACrcMismatch) {
  ScratchDir dir;
  const std::string source = smallRecording(dir, McapCompression::kNone);
  std::vector<std::uint8_t> bytes = readBytes(source);
  const std::size_t chunk = firstChunkOffset(bytes);
  bytes[chunk + 400] ^= 0x10;  // inside the first chunk's message payloads
  const std::string path = writeFile(dir, "flipped.mcap", bytes);
  const std::string message = errorMessage([&] { openAndReadAll(path); });
  EXPECT_EQ(message.rfind(path + ": CRC mismatch in the Chunk record at byte offset " + std::to_string(chunk), 0), 0u)
      << message;
}

TEST(McapCorruption, FlippedByteInACompressedChunkIsReportedWithTheChunkOffset) {
  ScratchDir dir;
  for (const auto compression : {McapCompression::kZstd, McapCompression::kLz4}) {
    const std::string source = smallRecording(dir, compression);
    const std::vector<std::uint8_t> original = readBytes(source);
    const std::size_t chunk = firstChunkOffset(original);
    for (const std::size_t at : {std::size_t{70}, std::size_t{200}, std::size_t{900}}) {
      std::vector<std::uint8_t> bytes = original;
      bytes[chunk + at] ^= 0x5A;
      const std::string path = writeFile(dir, "flipped.mcap", bytes);
      const std::string message = errorMessage([&] { openAndReadAll(path); });
      EXPECT_NE(message.find("Chunk record at byte offset " + std::to_string(chunk)), std::string::npos) << message;
    }
  }
}

TEST(McapCorruption, UnknownCompressionIsNamed) {
  ScratchDir dir;
  std::vector<std::uint8_t> bytes = readBytes(smallRecording(dir, McapCompression::kLz4));
  const std::size_t chunk = firstChunkOffset(bytes);
  // Chunk content: start, end, uncompressed size (24 bytes), crc (4), compression length (4), "lz4".
  const std::size_t name = chunk + 9 + 24 + 4 + 4;
  ASSERT_EQ(std::string(bytes.begin() + name, bytes.begin() + name + 3), "lz4");
  bytes[name + 2] = '5';
  const std::string path = writeFile(dir, "lz5.mcap", bytes);
  const std::string message = errorMessage([&] { openAndReadAll(path); });
  EXPECT_NE(message.find("unknown compression \"lz5\""), std::string::npos) << message;
}

TEST(McapCorruption, MessageOnAnUnknownChannelIsReported) {
  ScratchDir dir;
  RawFile records;
  records.record(0x03, schema(1)).record(0x04, channel(1, 1, "/chatter"));
  records.record(0x05, message(1, 10, "abcd")).record(0x05, message(7, 11, "efgh"));
  const std::string path = writeFile(dir, "channel7.mcap", unchunkedFile(records));
  const std::string error = errorMessage([&] { openAndReadAll(path); });
  EXPECT_NE(error.find("message on channel 7, which no Channel record defines before it"), std::string::npos) << error;
  EXPECT_EQ(error.rfind(path + ": Message record at byte offset", 0), 0u) << error;
}

TEST(McapCorruption, ChannelOnAnUndefinedSchemaIsReported) {
  ScratchDir dir;
  RawFile records;
  records.record(0x04, channel(1, 9, "/chatter"));
  const std::string path = writeFile(dir, "schema9.mcap", unchunkedFile(records));
  EXPECT_NE(errorMessage([&] { openAndReadAll(path); }).find("refers to schema 9"), std::string::npos);
}

TEST(McapCorruption, UnchunkedFileWithoutSummaryIsRead) {
  ScratchDir dir;
  RawFile records;
  records.record(0x03, schema(1)).record(0x04, channel(3, 1, "/chatter")).record(0x05, message(3, 10, "abcd"));
  records.record(0x0C, RawFile().str("info").u32(0));                      // Metadata: skipped
  records.record(0x80, RawFile().u64(42));                                 // an extension record: skipped
  records.record(0x05, message(3, 12, "efgh"));
  const std::string path = writeFile(dir, "plain.mcap", unchunkedFile(records));
  BagReader reader = BagReader::open(path);
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].message_count, 2u);
  EXPECT_EQ(reader.topics()[0].type, "std_msgs/msg/String");
  BagMessage m;
  ASSERT_TRUE(reader.next(m));
  EXPECT_EQ(std::string(m.data.begin(), m.data.end()), "abcd");
  ASSERT_TRUE(reader.next(m));
  EXPECT_EQ(m.log_time, 12);
  EXPECT_FALSE(reader.next(m));
}

TEST(McapCorruption, ASummaryRepeatingChannelsButNotSchemasFindsTheSchemasInTheDataSection) {
  // Valid MCAP (a writer with repeatSchemas off): the summary names channel 3 on schema 1, which only
  // the data section defines.
  ScratchDir dir;
  RawFile file;
  file.raw(kMagic).record(0x01, header());
  file.record(0x03, schema(1)).record(0x04, channel(3, 1, "/chatter")).record(0x05, message(3, 10, "abcd"));
  file.record(0x0F, RawFile().u32(0));
  const std::uint64_t summary_start = file.size();
  file.record(0x04, channel(3, 1, "/chatter"));
  file.record(0x02, RawFile().u64(summary_start).u64(0).u32(0)).raw(kMagic);
  const std::string path = writeFile(dir, "no_schemas_in_summary.mcap", file);
  BagReader reader = BagReader::open(path);
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].type, "std_msgs/msg/String");
  EXPECT_EQ(reader.topics()[0].message_definition, "string data");
  EXPECT_EQ(reader.topics()[0].message_count, 1u);
  BagMessage m;
  ASSERT_TRUE(reader.next(m));
  EXPECT_EQ(std::string(m.data.begin(), m.data.end()), "abcd");
}

TEST(McapCorruption, AChannelOnASchemaDefinedNowhereNamesItsByteOffset) {
  ScratchDir dir;
  RawFile records;
  records.record(0x03, schema(1)).record(0x04, channel(3, 7, "/chatter"));
  const std::string path = writeFile(dir, "schema7.mcap", unchunkedFile(records));
  const std::string error = errorMessage([&] { openAndReadAll(path); });
  EXPECT_NE(error.find("Channel record at byte offset"), std::string::npos) << error;
  EXPECT_NE(error.find("refers to schema 7"), std::string::npos) << error;
}

TEST(McapCorruption, TruncatedFieldInsideARecordNamesTheField) {
  ScratchDir dir;
  RawFile records;
  records.record(0x04, RawFile().u16(1).u16(0).u32(1000).raw({'a', 'b'}));  // topic claims 1000 bytes
  const std::string path = writeFile(dir, "field.mcap", unchunkedFile(records));
  const std::string error = errorMessage([&] { openAndReadAll(path); });
  EXPECT_NE(error.find("Channel record at byte offset"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated at field topic"), std::string::npos) << error;
}

TEST(McapCorruption, SummaryCrcMismatchIsReported) {
  ScratchDir dir;
  std::vector<std::uint8_t> bytes = readBytes(smallRecording(dir, McapCompression::kZstd));
  // The Statistics record sits in the summary; flip a byte of its message count.
  std::uint64_t summary_start = 0;
  std::memcpy(&summary_start, bytes.data() + bytes.size() - 8 - 20, 8);
  bytes[summary_start + 3] ^= 0x01;
  const std::string path = writeFile(dir, "summary.mcap", bytes);
  EXPECT_NE(errorMessage([&] { openAndReadAll(path); }).find("summary section CRC mismatch"), std::string::npos);
}

/// A few tiny messages on two topics without schemas: small enough to corrupt every byte in turn.
std::string tinyFile(const ScratchDir& dir, bool crcs) {
  const std::string path = dir / (crcs ? "tiny_crc.mcap" : "tiny.mcap");
  McapWriterOptions options;
  options.compression = McapCompression::kNone;
  options.write_crcs = crcs;
  options.chunk_size = 80;
  McapWriter writer = McapWriter::create(path, options);
  writer.addTopic({"/a", "", "cdr", "q", "", "", 0, {}});
  writer.addTopic({"/b", "", "cdr", "", "", "", 0, {}});
  const std::uint8_t payload[6] = {0, 1, 0, 0, 42, 43};
  for (int i = 0; i < 5; ++i) writer.write(i % 2 ? "/a" : "/b", 100 + i, 100 + i, payload, sizeof payload);
  writer.close();
  return path;
}

TEST(McapCorruption, AnyCorruptedByteGivesAColocErrorOrValidData) {
  ScratchDir dir;
  for (const bool crcs : {true, false}) {
    const std::vector<std::uint8_t> original = readBytes(tinyFile(dir, crcs));
    const std::string path = dir / "fuzz.mcap";
    for (std::size_t i = 0; i < original.size(); ++i) {
      for (const std::uint8_t value : {0x00, 0x01, 0x80, 0xFF}) {
        std::vector<std::uint8_t> bytes = original;
        if (bytes[i] == value) continue;
        bytes[i] = value;
        writeBytes(path, bytes);
        try {
          openAndReadAll(path);
        } catch (const Error&) {
        } catch (const std::exception& e) {
          FAIL() << "byte " << i << " = " << int(value) << ": " << e.what();
        }
      }
    }
  }
}

}  // namespace
}  // namespace coloc::io
