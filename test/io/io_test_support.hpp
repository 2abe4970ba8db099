#pragma once
// Helpers shared by the io tests: the real recording, scratch directories, whole-file access and
// checks on coloc::Error messages.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/mcap_writer.hpp"

namespace coloc::io::testing {

namespace fs = std::filesystem;

/// The real recording in data/; a missing file throws, naming it, so that its tests fail with that message.
inline std::string nav2Bag() {
  const std::string path = COLOC_DATA_DIR "/rosbag2/nav2_turtlebot.mcap";
  if (!fs::is_regular_file(path)) throw std::runtime_error("real data file missing: " + path + " (see data/README.md)");
  return path;
}

/// The first `messages` of the real recording, written to `path` by coloc's MCAP writer with `options`.
inline std::string rewriteNav2(const std::string& path, const McapWriterOptions& options, std::size_t messages) {
  BagReader reader = BagReader::open(nav2Bag());
  McapWriter writer = McapWriter::create(path, options);
  for (const auto& topic : reader.topics()) writer.addTopic(topic);
  BagMessage message;
  for (std::size_t i = 0; i < messages && reader.next(message); ++i) writer.write(message);
  writer.close();
  return path;
}

/// A fresh directory under the system temp directory, removed with everything in it.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "coloc_io_test_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const fs::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

inline std::vector<std::uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

inline std::vector<BagMessage> readAllMessages(const std::string& path) {
  BagReader reader = BagReader::open(path);
  std::vector<BagMessage> messages;
  BagMessage message;
  while (reader.next(message)) messages.push_back(message);
  return messages;
}

/// Opens the bag and reads every message.
inline void openAndReadAll(const std::string& path) { readAllMessages(path); }

/// The message of the coloc::Error `action` throws; fails the test if it throws nothing or anything else.
inline std::string errorMessage(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected coloc::Error, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected coloc::Error, nothing was thrown";
  return {};
}

}  // namespace coloc::io::testing
