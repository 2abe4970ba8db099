// rosbag2's zstd compression, FILE and MESSAGE modes: written on request, read back message for message,
// and damaged compressed data refused with the file and the reason.
#include <gtest/gtest.h>

#include <algorithm>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;
using testing::errorMessage;
using testing::nav2Bag;
using testing::readAllMessages;
using testing::readBytes;
using testing::ScratchDir;
using testing::writeBytes;

std::string text(const std::string& path) {
  const std::vector<std::uint8_t> b = readBytes(path);
  return std::string(b.begin(), b.end());
}

// The temporary copies a FILE-mode bag is read through.
std::size_t decompressedCopies() {
  std::size_t n = 0;
  for (const auto& entry : fs::directory_iterator(fs::temp_directory_path()))
    n += entry.path().filename().string().rfind("coloc-bag-" + std::to_string(::getpid()) + "-", 0) == 0;
  return n;
}

void expectSameMessages(const std::vector<BagMessage>& a, const std::vector<BagMessage>& b) {
  ASSERT_EQ(a.size(), b.size());
  // sqlite3 returns messages by timestamp: compare as sets ordered the same way.
  auto key = [](const BagMessage& m) { return std::make_tuple(m.log_time, m.topic, m.data); };
  std::vector<std::tuple<Stamp, std::string, std::vector<std::uint8_t>>> ka, kb;
  for (const auto& m : a) ka.push_back(key(m));
  for (const auto& m : b) kb.push_back(key(m));
  std::sort(ka.begin(), ka.end());
  std::sort(kb.begin(), kb.end());
  EXPECT_TRUE(ka == kb);
}

// The real recording converted to a sqlite3 bag named `name` in `dir`, compressed as asked.
std::string convertedBag(const ScratchDir& dir, const std::string& name, BagCompression compression) {
  ConvertOptions options;
  options.sqlite_compression = compression;
  const std::string bag = dir / name;
  convert(nav2Bag(), bag, options);
  return bag;
}

TEST(BagCompression, FileModeBagHoldsOnlyTheCompressedDatabaseAndReadsBackEveryMessage) {
  ScratchDir dir;
  const std::string bag = convertedBag(dir, "filemode", BagCompression::kZstdFile);
  EXPECT_TRUE(fs::is_regular_file(fs::path(bag) / "filemode_0.db3.zstd"));
  EXPECT_FALSE(fs::exists(fs::path(bag) / "filemode_0.db3"));
  const std::string metadata = text((fs::path(bag) / "metadata.yaml").string());
  EXPECT_NE(metadata.find("compression_format: \"zstd\""), std::string::npos) << metadata;
  EXPECT_NE(metadata.find("compression_mode: \"FILE\""), std::string::npos) << metadata;
  EXPECT_NE(metadata.find("- filemode_0.db3.zstd"), std::string::npos) << metadata;
  const std::size_t before = decompressedCopies();
  {
    BagReader reader = BagReader::open(bag);
    EXPECT_EQ(decompressedCopies(), before + 1);
    EXPECT_EQ(reader.messageCount(), BagReader::open(nav2Bag()).messageCount());
  }
  EXPECT_EQ(decompressedCopies(), before) << "the decompressed copy outlived its reader";
  expectSameMessages(readAllMessages(bag), readAllMessages(nav2Bag()));
}

TEST(BagCompression, MessageModeStoresZstdFramesAndReadsBackEveryMessage) {
  ScratchDir dir;
  const std::string bag = convertedBag(dir, "messagemode", BagCompression::kZstdMessage);
  const std::string metadata = text((fs::path(bag) / "metadata.yaml").string());
  EXPECT_NE(metadata.find("compression_mode: \"MESSAGE\""), std::string::npos) << metadata;
  // The database alone, read without the metadata, gives the frames as stored: zstd's magic first.
  const std::vector<BagMessage> raw = readAllMessages((fs::path(bag) / "messagemode_0.db3").string());
  ASSERT_FALSE(raw.empty());
  for (const BagMessage& m : raw) {
    ASSERT_GE(m.data.size(), 4u);
    EXPECT_EQ(m.data[0], 0x28);
    EXPECT_EQ(m.data[3], 0xFD);
  }
  expectSameMessages(readAllMessages(bag), readAllMessages(nav2Bag()));
}

TEST(BagCompression, DamagedCompressedDataIsRefusedWithTheFileAndTheReason) {
  ScratchDir dir;
  const std::string bag = convertedBag(dir, "cut", BagCompression::kZstdFile);
  const std::string file = (fs::path(bag) / "cut_0.db3.zstd").string();
  std::vector<std::uint8_t> bytes = readBytes(file);
  bytes.resize(bytes.size() / 2);
  writeBytes(file, bytes);
  std::string error = errorMessage([&] { BagReader::open(bag); });
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
  bytes.assign(100, 0x55);
  writeBytes(file, bytes);
  error = errorMessage([&] { BagReader::open(bag); });
  EXPECT_NE(error.find("not a valid zstd file"), std::string::npos) << error;

  // MESSAGE mode: a message that is not a zstd frame names its position and topic.
  const std::string plain = convertedBag(dir, "plain", BagCompression::kNone);
  const std::string yaml = (fs::path(plain) / "metadata.yaml").string();
  std::string m = text(yaml);
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"compression_format: \"\"", "compression_format: \"zstd\""},
                                 {"compression_mode: \"\"", "compression_mode: \"MESSAGE\""}}) {
    ASSERT_NE(m.find(from), std::string::npos) << m;
    m.replace(m.find(from), from.size(), to);
  }
  testing::writeText(yaml, m);
  error = errorMessage([&] { readAllMessages(plain); });
  EXPECT_NE(error.find("message 0 on /"), std::string::npos) << error;
  EXPECT_NE(error.find("not a zstd frame"), std::string::npos) << error;
}

}  // namespace
}  // namespace coloc::io
