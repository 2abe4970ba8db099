// BagReader: decides what the path is (MCAP file, sqlite3 database, rosbag2 directory), opens each
// storage file and chains them.
#include "coloc/io/bag_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include <stdlib.h>
#include <unistd.h>

#include "bag_compression.hpp"
#include "bag_metadata.hpp"
#include "coloc/core/error.hpp"
#include "mcap_records.hpp"
#include "storage_reader.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;

enum class Storage { kMcap, kSqlite };

const char* storageName(Storage storage) { return storage == Storage::kMcap ? "mcap" : "sqlite3"; }

/// What a file's first bytes say it is; the extension decides only when they are inconclusive, so
/// that a truncated .mcap still gets the MCAP reader's precise error.
std::optional<Storage> sniffStorage(const fs::path& path) {
  char head[16] = {};
  std::ifstream file(path, std::ios::binary);
  file.read(head, sizeof head);
  const auto got = static_cast<std::size_t>(file.gcount());
  if (got >= sizeof detail::mcap::kMagic && std::memcmp(head, detail::mcap::kMagic, sizeof detail::mcap::kMagic) == 0) {
    return Storage::kMcap;
  }
  if (got == sizeof head && std::memcmp(head, "SQLite format 3\0", 16) == 0) return Storage::kSqlite;
  if (path.extension() == ".mcap") return Storage::kMcap;
  if (path.extension() == ".db3") return Storage::kSqlite;
  return std::nullopt;
}

std::unique_ptr<detail::StorageReader> openStorage(Storage storage, const std::string& path, const BagReadOptions& options) {
  return storage == Storage::kMcap ? detail::openMcapStorage(path, options.recover) : detail::openSqliteStorage(path);
}

/// Split files are "<bag>_<N>.<ext>" with N unpadded, so "bag_10" must sort after "bag_9": order by the
/// name before the trailing number, then by the number's value.
std::pair<std::string, unsigned long long> splitOrderKey(const std::string& path) {
  const std::string stem = fs::path(path).stem().string();
  const std::size_t digits_start = stem.find_last_not_of("0123456789") + 1;  // npos + 1 == 0: all digits
  const std::string digits = stem.substr(digits_start, 18);
  return {stem.substr(0, digits_start), digits.empty() ? 0ull : std::stoull(digits)};
}

bool splitOrderLess(const std::string& a, const std::string& b) {
  const auto ka = splitOrderKey(a), kb = splitOrderKey(b);
  return ka != kb ? ka < kb : a < b;
}

enum class Compression { kNone, kFile, kMessage };

struct BagLayout {
  Storage storage = Storage::kMcap;
  std::vector<std::string> files;
  std::vector<TopicInfo> metadata_topics;  // from metadata.yaml, to fill what old storage lacks
  Compression compression = Compression::kNone;
};

/// A private directory under the system's temporary directory, removed with everything in it.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::string pattern = (fs::temp_directory_path() / ("coloc-bag-" + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) throw Error(pattern + ": cannot create a directory to decompress the bag into");
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// MESSAGE mode: each message's bytes are a zstd frame, decompressed as they are read.
class MessageDecompressing final : public detail::StorageReader {
 public:
  MessageDecompressing(std::unique_ptr<detail::StorageReader> inner, std::string path) : inner_(std::move(inner)), path_(std::move(path)) {}
  const std::vector<TopicInfo>& topics() const override { return inner_->topics(); }
  std::optional<RecoveredFile> recovery() const override { return inner_->recovery(); }
  bool next(BagMessage& message) override {
    if (!inner_->next(message)) return false;
    message.data = detail::decompressZstdMessage(message.data.data(), message.data.size(),
                                                 path_ + ": message " + std::to_string(read_++) + " on " + message.topic);
    return true;
  }

 private:
  std::unique_ptr<detail::StorageReader> inner_;
  std::string path_;
  std::uint64_t read_ = 0;
};

/// rosbag2 resolves relative_file_paths against the bag directory since metadata version 4, against
/// its parent before; both are tried.
std::string resolveListedFile(const fs::path& directory, const std::string& listed, const std::string& metadata_path) {
  for (const fs::path& base : {directory, directory.parent_path()}) {
    const fs::path candidate = base / listed;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  throw Error(metadata_path + ": lists storage file '" + listed + "', which does not exist in " + directory.string());
}

BagLayout layoutFromMetadata(const fs::path& directory, const std::string& metadata_path) {
  const detail::BagMetadata metadata = detail::readBagMetadata(metadata_path);
  BagLayout layout;
  if (metadata.storage_identifier == "mcap") {
    layout.storage = Storage::kMcap;
  } else if (metadata.storage_identifier == "sqlite3") {
    layout.storage = Storage::kSqlite;
  } else {
    throw Error(metadata_path + ": storage_identifier '" + metadata.storage_identifier +
                "' is not supported (sqlite3, mcap)");
  }
  if (!metadata.compression_format.empty()) {
    if (metadata.compression_format != "zstd")
      throw Error(metadata_path + ": compression_format '" + metadata.compression_format + "' is not supported (zstd)");
    std::string mode = metadata.compression_mode;
    for (char& c : mode) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (mode == "FILE") layout.compression = Compression::kFile;
    else if (mode == "MESSAGE") layout.compression = Compression::kMessage;
    else throw Error(metadata_path + ": compression_mode '" + metadata.compression_mode + "' is not supported (FILE, MESSAGE)");
  }
  if (metadata.relative_file_paths.empty()) throw Error(metadata_path + ": relative_file_paths lists no storage file");
  for (const auto& listed : metadata.relative_file_paths) {
    layout.files.push_back(resolveListedFile(directory, listed, metadata_path));
  }
  layout.metadata_topics = metadata.topics;
  return layout;
}

/// A directory without metadata.yaml (a recording that was never closed): its storage files in split order.
BagLayout layoutFromListing(const fs::path& directory) {
  std::vector<std::string> mcap, sqlite;
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (!entry.is_regular_file()) continue;
    if (entry.path().extension() == ".mcap") mcap.push_back(entry.path().string());
    if (entry.path().extension() == ".db3") sqlite.push_back(entry.path().string());
  }
  if (mcap.empty() == sqlite.empty()) {
    throw Error(directory.string() + ": no metadata.yaml, and " +
                (mcap.empty() ? "no .db3 or .mcap file" : "both .db3 and .mcap files") + ": not a rosbag2 directory");
  }
  BagLayout layout;
  layout.storage = mcap.empty() ? Storage::kSqlite : Storage::kMcap;
  layout.files = mcap.empty() ? sqlite : mcap;
  std::sort(layout.files.begin(), layout.files.end(), splitOrderLess);
  return layout;
}

BagLayout layoutOf(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw Error(path + ": no such file or directory");
  if (fs::is_directory(status)) {
    const fs::path metadata = fs::path(path) / "metadata.yaml";
    if (fs::exists(metadata, ec)) return layoutFromMetadata(path, metadata.string());
    return layoutFromListing(path);
  }
  if (fs::path(path).filename() == "metadata.yaml") {
    return layoutFromMetadata(fs::path(path).parent_path(), path);
  }
  const auto storage = sniffStorage(path);
  if (!storage) throw Error(path + ": neither an MCAP file, a rosbag2 .db3 database nor a rosbag2 directory");
  return {*storage, {path}, {}};
}

void mergeTopics(std::vector<TopicInfo>& merged, const std::vector<TopicInfo>& more) {
  for (const auto& topic : more) {
    const auto same = std::find_if(merged.begin(), merged.end(), [&](const TopicInfo& t) { return t.name == topic.name; });
    if (same == merged.end()) {
      merged.push_back(topic);
    } else {
      same->message_count += topic.message_count;
    }
  }
}

}  // namespace

struct BagReader::Impl {
  std::optional<TemporaryDirectory> decompressed;  // FILE mode: the storage files, decompressed
  std::string path;
  std::string storage;
  std::vector<std::string> files;
  std::vector<std::unique_ptr<detail::StorageReader>> readers;
  std::vector<TopicInfo> topics;
  std::uint64_t message_count = 0;
  std::size_t current = 0;
  std::uint64_t next_index = 0;
  std::vector<BagAttachment> attachments;
  std::vector<BagMetadataRecord> metadata;
  std::vector<RecoveredFile> recovered;
};

BagReader BagReader::open(const std::string& path, const BagReadOptions& options) {
  BagLayout layout = layoutOf(path);
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->storage = storageName(layout.storage);
  impl->files = layout.files;
  for (const auto& file : layout.files) {
    if (layout.compression == Compression::kFile) {
      // A storage file must be seekable (sqlite3, MCAP's footer): each is decompressed to a temporary
      // file that lives as long as the reader.
      if (!impl->decompressed) impl->decompressed.emplace();
      std::string name = fs::path(file).filename().string();
      if (name.size() > 5 && name.compare(name.size() - 5, 5, ".zstd") == 0) name.resize(name.size() - 5);
      const std::string plain = (impl->decompressed->path() / (std::to_string(impl->readers.size()) + "_" + name)).string();
      detail::decompressZstdFile(file, plain);
      impl->readers.push_back(openStorage(layout.storage, plain, options));
    } else if (layout.compression == Compression::kMessage) {
      impl->readers.push_back(std::make_unique<MessageDecompressing>(openStorage(layout.storage, file, options), file));
    } else {
      impl->readers.push_back(openStorage(layout.storage, file, options));
    }
    mergeTopics(impl->topics, impl->readers.back()->topics());
    if (std::optional<RecoveredFile> recovered = impl->readers.back()->recovery()) {
      recovered->file = file;  // the bag's file, not a decompressed copy's
      impl->recovered.push_back(std::move(*recovered));
    }
  }
  for (auto& topic : impl->topics) {
    impl->message_count += topic.message_count;
    if (!topic.offered_qos_profiles.empty()) continue;
    for (const auto& listed : layout.metadata_topics) {
      if (listed.name == topic.name) topic.offered_qos_profiles = listed.offered_qos_profiles;
    }
  }
  return BagReader(std::move(impl));
}

BagReader::BagReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagReader::~BagReader() = default;
BagReader::BagReader(BagReader&&) noexcept = default;
BagReader& BagReader::operator=(BagReader&&) noexcept = default;

const std::string& BagReader::path() const { return impl_->path; }
const std::string& BagReader::storageIdentifier() const { return impl_->storage; }
const std::vector<std::string>& BagReader::files() const { return impl_->files; }
const std::vector<TopicInfo>& BagReader::topics() const { return impl_->topics; }
std::uint64_t BagReader::messageCount() const { return impl_->message_count; }
const std::vector<RecoveredFile>& BagReader::recovered() const { return impl_->recovered; }
void BagReader::keepAttachments(bool keep) {
  for (auto& reader : impl_->readers)
    if (reader) reader->keepAttachments(keep);
}
const std::vector<BagAttachment>& BagReader::attachments() const { return impl_->attachments; }
const std::vector<BagMetadataRecord>& BagReader::metadataRecords() const { return impl_->metadata; }

bool BagReader::next(BagMessage& message) {
  while (impl_->current < impl_->readers.size()) {
    if (impl_->readers[impl_->current]->next(message)) {
      message.index = impl_->next_index++;
      return true;
    }
    for (BagAttachment& a : impl_->readers[impl_->current]->takeAttachments()) impl_->attachments.push_back(std::move(a));
    for (BagMetadataRecord& m : impl_->readers[impl_->current]->takeMetadata()) impl_->metadata.push_back(std::move(m));
    impl_->readers[impl_->current++].reset();  // release the finished file's handle and buffers
  }
  return false;
}

}  // namespace coloc::io
