// `coloc convert IN OUT`: rosbag2 sqlite3 <-> MCAP, payloads and log times preserved byte for byte;
// with --recover, a recording that was never closed becomes a closed one of what it held.
#include <cstdio>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_writer.hpp"
#include "commands.hpp"
#include "log_options.hpp"

namespace coloc::tools {

void addConvertCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert",
                                 "Convert a recording: IN (.mcap, .db3 or rosbag2 folder) to OUT (a rosbag2 sqlite3 folder, "
                                 "or an MCAP file if OUT ends in .mcap)");
  static std::string in, out, compression = "none";
  cmd->add_option("IN", in, "input recording")->required();
  cmd->add_option("OUT", out, "output: folder (sqlite3) or FILE.mcap")->required();
  cmd->add_option("--compress", compression, "sqlite3 output: none, zstd-file or zstd-message (rosbag2's FILE and MESSAGE modes)")
      ->check(CLI::IsMember({"none", "zstd-file", "zstd-message"}));
  static bool recover = false;
  addRecoverFlag(cmd, recover);
  cmd->callback([] {
    const bool to_mcap = out.size() >= 5 && out.compare(out.size() - 5, 5, ".mcap") == 0;
    if (to_mcap && compression != "none")
      throw Error("--compress " + compression + ": applies to sqlite3 output; MCAP output compresses its chunks (zstd) already");
    io::ConvertOptions options;
    options.sqlite_compression = compression == "zstd-file"      ? io::BagCompression::kZstdFile
                                 : compression == "zstd-message" ? io::BagCompression::kZstdMessage
                                                                 : io::BagCompression::kNone;
    options.read.recover = recover;
    const io::ConvertSummary summary = io::convert(in, out, options);
    std::printf("%s", describeRecovered(summary.recovered).c_str());
    std::printf("converted %llu messages on %zu topics: %s -> %s\n", static_cast<unsigned long long>(summary.message_count),
                summary.topics.size(), in.c_str(), out.c_str());
    if (summary.attachments + summary.metadata_records > 0)
      std::printf("%s %llu attachments and %llu metadata records%s\n", to_mcap ? "copied" : "left out", (unsigned long long)summary.attachments,
                  (unsigned long long)summary.metadata_records, to_mcap ? "" : " (rosbag2 sqlite3 cannot hold them)");
  });
}

}  // namespace coloc::tools
