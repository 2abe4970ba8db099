// A simulated drive kept in memory for its replays holds its scans decoded, without the message in
// between: they must be, bit for bit, what a replay decodes from the same drive written to disk.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/replay/replay_cache.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/twin/twin_recording.hpp"
#include "temp_dir.hpp"

namespace coloc::twin {
namespace {

TEST(TwinRecording, ScansKeptInMemoryAreWhatAReplayDecodesFromTheWrittenLog) {
  std::ifstream in(COLOC_SOURCE_DIR "/test/tools/small_site.yaml");
  std::stringstream text;
  text << in.rdbuf();
  sim::Scenario scenario = sim::parseScenario(text.str(), "small_site.yaml");
  testing::TempDir dir;
  TwinRecordingOptions options;
  options.out_dir = (dir.path() / "drive").string();
  options.perception_ablation = false;
  options.write_log = true;
  options.keep_log = true;
  const TwinRecordingSummary summary = recordTwin(scenario, options);
  ASSERT_TRUE(summary.log);
  const replay::RecordedLog& kept = *summary.log;
  const replay::RecordedLog written(options.out_dir + "/log");
  ASSERT_EQ(kept.messages().size(), written.messages().size());
  int scans = 0;
  for (std::size_t i = 0; i < written.messages().size(); ++i) {
    const io::BagMessage& m = written.messages()[i];
    ASSERT_EQ(kept.messages()[i].topic, m.topic) << "message " << i;
    ASSERT_EQ(kept.messages()[i].log_time, m.log_time) << "message " << i;
    if (m.topic != "/points") {
      EXPECT_EQ(kept.messages()[i].data, m.data) << "message " << i;
      continue;
    }
    const replay::RecordedLog::Scan a = kept.scan(i, io::MessageKind::kPointCloud2), b = written.scan(i, io::MessageKind::kPointCloud2);
    EXPECT_EQ(a.stamp, b.stamp) << "message " << i;
    EXPECT_EQ(a.cloud->points, b.cloud->points) << "message " << i;
    EXPECT_EQ(a.cloud->times, b.cloud->times) << "message " << i;
    ++scans;
  }
  EXPECT_GT(scans, 40);  // 60 m at 8 m/s, 10 Hz
}

// A link or processing time out of range is refused before the drive is surveyed and simulated,
// naming what is wrong, and nothing is written.
TEST(TwinRecording, RefusesALinkOrProcessingTimeOutOfRangeBeforeSimulating) {
  const sim::Scenario scenario = sim::parseScenario("route: {start: [0, 0], pieces: [{length: 50}]}\n", "s.yaml");
  testing::TempDir dir;
  const auto message = [&](TwinRecordingOptions options) {
    options.out_dir = (dir.path() / "drive").string();
    try {
      recordTwin(scenario, options);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  TwinRecordingOptions bad_loss;
  bad_loss.link.loss = 2.0;
  EXPECT_NE(message(bad_loss).find("link: loss must be a probability in [0, 1]"), std::string::npos);
  TwinRecordingOptions bad_delay;
  bad_delay.link.delay = -0.03;
  EXPECT_NE(message(bad_delay).find("link: delay must be a finite number of seconds >= 0"), std::string::npos);
  TwinRecordingOptions bad_processing;
  bad_processing.rsu_processing = std::nan("");
  EXPECT_NE(message(bad_processing).find("processing time must be a finite number"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "drive" / "map"));  // refused before the survey
}

}  // namespace
}  // namespace coloc::twin
