#pragma once
// One storage file of a bag (an MCAP file or a sqlite3 database), as BagReader composes them.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coloc/io/bag_message.hpp"
#include "coloc/io/bag_reader.hpp"

namespace coloc::io::detail {

class StorageReader {
 public:
  virtual ~StorageReader() = default;
  /// Topics with their message counts in this file.
  virtual const std::vector<TopicInfo>& topics() const = 0;
  /// Next message in file order; false at the end. message.index is left to the caller.
  virtual bool next(BagMessage& message) = 0;
  /// Whether next() collects attachments and metadata records (off: skipped unread).
  virtual void keepAttachments(bool) {}
  /// Attachments and metadata records met by next() so far (all of them once it returned false).
  virtual std::vector<BagAttachment> takeAttachments() { return {}; }
  virtual std::vector<BagMetadataRecord> takeMetadata() { return {}; }
  /// Set when the file was not closed and was opened to be recovered: what is read of it.
  virtual std::optional<RecoveredFile> recovery() const { return std::nullopt; }
};

/// Throw coloc::Error naming the file and the reason.
/// `recover`: a file that was not closed is read up to its cut instead of refused.
std::unique_ptr<StorageReader> openMcapStorage(const std::string& path, bool recover = false);
std::unique_ptr<StorageReader> openSqliteStorage(const std::string& path);

}  // namespace coloc::io::detail
