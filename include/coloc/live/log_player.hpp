#pragma once
// Plays a recorded log (MCAP or rosbag2 sqlite3) over DDS as `ros2 bag play` does, without ROS: every
// message of the chosen topics is published, as recorded (bytes unchanged), on its ROS 2 topic with
// its type, at its recorded pace scaled by the rate, and the log's time goes out on /clock so that
// nodes can run on it (use_sim_time).
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "coloc/io/bag_reader.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::live {

struct PlayOptions {
  double rate = 1.0;                 ///< 2 = twice as fast as recorded
  std::vector<std::string> topics;   ///< empty: every topic
  bool loop = false;                 ///< start again at the end, until stopped
  int passes = 0;                    ///< with loop: stop after this many passes (0: until stopped)
  bool publish_clock = true;         ///< the log's time on /clock (rosgraph_msgs/Clock)
  double clock_frequency = 100.0;    ///< Hz of /clock between messages (each message also sends its own time first)
  double delay = 0.0;                ///< s to wait after the writers are created (discovery) before the first message
  bool recover = false;              ///< play a log that was never closed up to where it stops (io::BagReadOptions)
  /// Topics published under another name (recorded name -> published name), as `ros2 bag play --remap`.
  std::map<std::string, std::string> remap;
  rsu_client::DdsConfig dds;
  std::function<bool()> stop_requested;            ///< polled between messages
  std::function<void(double fraction)> progress;   ///< share of the log played
};

struct PlayReport {
  std::map<std::string, std::uint64_t> published;  ///< per topic
  std::uint64_t failed = 0;                        ///< writes DDS refused
  std::uint64_t loops = 0;                         ///< passes over the log completed
  double log_seconds = 0.0, wall_seconds = 0.0;
  double max_lag_ms = 0.0;                         ///< latest a message went out after its due time
  bool stopped = false;                            ///< stop_requested ended it
  std::vector<io::RecoveredFile> recovered;        ///< the log's files that were never closed, played up to their cut
};

/// Throws coloc::Error if the log cannot be opened, a topic asked for is not in it, or DDS refuses.
PlayReport playLog(const std::string& log_path, const PlayOptions& options);

}  // namespace coloc::live
