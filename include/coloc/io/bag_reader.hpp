#pragma once
// Reads ROS 2 recordings without ROS: a .mcap file, a .db3 file, or a rosbag2 directory (metadata.yaml
// naming one or several sqlite3 or mcap files). Messages come in file order (sqlite3: by timestamp,
// then row id; MCAP: as written), one file after the other, streamed: an MCAP file is read chunk by
// chunk, never whole.
//
// All failures throw coloc::Error naming the file (and byte offset or row where it applies) and the
// reason: bad magic, truncated records, CRC mismatch, unknown compression, a message on an unknown
// channel, a missing file, unreadable metadata.yaml, ...
//
// A recording stopped by a crash or a power cut leaves an MCAP file without its footer, cut inside a
// record. It is refused unless opened with `recover`: then its whole records before the cut are read,
// and recovered() says what was read and why reading stopped where it did. A closed file is read the
// same way with or without it. (A sqlite3 database needs no such option: SQLite itself rolls back or
// keeps what its journal or write-ahead log holds.)
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "coloc/io/bag_message.hpp"

namespace coloc::io {

struct BagReadOptions {
  /// Read MCAP files that were never closed (no footer) up to where their whole records end.
  bool recover = false;
};

/// An MCAP file read with BagReadOptions::recover that was not closed: what of it was read.
struct RecoveredFile {
  std::string file;
  std::uint64_t file_bytes = 0;  ///< its size
  std::uint64_t read_bytes = 0;  ///< from its start, the records read
  std::uint64_t messages = 0;    ///< messages read from it
  std::string reason;            ///< why reading stopped at read_bytes
};

class BagReader {
 public:
  /// Opens and indexes the bag (topics, message counts). Throws coloc::Error.
  static BagReader open(const std::string& path, const BagReadOptions& options = {});

  ~BagReader();
  BagReader(BagReader&&) noexcept;
  BagReader& operator=(BagReader&&) noexcept;

  /// The path given to open().
  const std::string& path() const;
  /// "mcap" or "sqlite3".
  const std::string& storageIdentifier() const;
  /// The storage files read, in order.
  const std::vector<std::string>& files() const;
  /// Topics in the order the bag lists them, counts summed over all files.
  const std::vector<TopicInfo>& topics() const;
  std::uint64_t messageCount() const;
  /// The files that were not closed, read with BagReadOptions::recover up to their cut (known on open;
  /// messageCount() counts what will be read).
  const std::vector<RecoveredFile>& recovered() const;

  /// Fills `message` with the next message and returns true, or returns false at the end.
  /// Reuses message.data's capacity. Throws coloc::Error on corrupt data.
  bool next(BagMessage& message);

  /// Collect MCAP attachments and metadata records while reading (off by default: they are skipped
  /// unread, as a replay has no use for them). Call before the first next().
  void keepAttachments(bool keep);
  /// MCAP attachments and metadata records of the files next() has finished (all of them once it
  /// returned false), when kept; rosbag2 sqlite3 storage has neither.
  const std::vector<BagAttachment>& attachments() const;
  const std::vector<BagMetadataRecord>& metadataRecords() const;

 private:
  struct Impl;
  explicit BagReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::io
