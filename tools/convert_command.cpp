// `coloc convert IN OUT`: rosbag2 sqlite3 <-> MCAP, payloads and log times preserved byte for byte.
#include <cstdio>

#include "coloc/io/bag_writer.hpp"
#include "commands.hpp"

namespace coloc::tools {

void addConvertCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert",
                                 "Convert a recording: IN (.mcap, .db3 or rosbag2 folder) to OUT (a rosbag2 sqlite3 folder, "
                                 "or an MCAP file if OUT ends in .mcap)");
  static std::string in, out;
  cmd->add_option("IN", in, "input recording")->required();
  cmd->add_option("OUT", out, "output: folder (sqlite3) or FILE.mcap")->required();
  cmd->callback([] {
    const io::ConvertSummary summary = io::convert(in, out);
    std::printf("converted %llu messages on %zu topics: %s -> %s\n", static_cast<unsigned long long>(summary.message_count),
                summary.topics.size(), in.c_str(), out.c_str());
  });
}

}  // namespace coloc::tools
