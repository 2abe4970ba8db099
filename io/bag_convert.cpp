// convert(): any readable bag to a rosbag2 sqlite3 directory or an MCAP file, message by message.
#include <filesystem>
#include <optional>
#include <type_traits>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/mcap_writer.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

template <class Writer>
std::uint64_t copyMessages(BagReader& reader, Writer& writer) {
  for (const auto& topic : reader.topics()) writer.addTopic(topic);
  std::uint64_t count = 0;
  BagMessage message;
  while (reader.next(message)) {
    writer.write(message);
    ++count;
  }
  if constexpr (std::is_same_v<Writer, McapWriter>) {
    for (const BagAttachment& a : reader.attachments()) writer.writeAttachment(a);
    for (const BagMetadataRecord& m : reader.metadataRecords()) writer.writeMetadata(m);
  }
  writer.close();
  return count;
}

/// Removes what a failed conversion wrote, so that a rerun is not refused for existing output.
void removePartialOutput(const std::string& output, bool is_mcap, bool directory_existed) {
  std::error_code ec;
  if (is_mcap) {
    fs::remove(output, ec);
    return;
  }
  if (directory_existed) {
    for (const auto& entry : fs::directory_iterator(output, ec)) fs::remove_all(entry.path(), ec);
  } else {
    fs::remove_all(output, ec);
  }
}

}  // namespace

ConvertSummary convert(const std::string& input, const std::string& output, const ConvertOptions& options) {
  BagReader reader = BagReader::open(input, options.read);
  reader.keepAttachments(true);  // copied to an MCAP output, counted for a sqlite3 one
  ConvertSummary summary;
  summary.topics = reader.topics();
  summary.recovered = reader.recovered();
  const bool is_mcap = endsWith(output, ".mcap");
  std::error_code ec;
  const bool directory_existed = !is_mcap && fs::is_directory(output, ec);
  std::optional<McapWriter> mcap;
  std::optional<BagWriter> sqlite;
  if (is_mcap) {
    mcap.emplace(McapWriter::create(output, options.mcap));
  } else {
    sqlite.emplace(BagWriter::create(output, options.sqlite_compression));
  }
  try {
    summary.message_count = is_mcap ? copyMessages(reader, *mcap) : copyMessages(reader, *sqlite);
    summary.attachments = reader.attachments().size();
    summary.metadata_records = reader.metadataRecords().size();
  } catch (const Error& e) {
    mcap.reset();
    sqlite.reset();
    removePartialOutput(output, is_mcap, directory_existed);
    throw Error("converting " + input + " to " + output + " failed (output removed): " + e.what());
  }
  return summary;
}

}  // namespace coloc::io
