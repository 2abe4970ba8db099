// A simulated drive kept in memory for its replays holds its scans decoded, without the message in
// between: they must be, bit for bit, what a replay decodes from the same drive written to disk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/replay/replay_cache.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/twin/twin_recording.hpp"
#include "temp_dir.hpp"

namespace coloc::twin {
namespace {

sim::Scenario smallSite() {
  std::ifstream in(COLOC_SOURCE_DIR "/test/tools/small_site.yaml");
  std::stringstream text;
  text << in.rdbuf();
  return sim::parseScenario(text.str(), "small_site.yaml");
}

TEST(TwinRecording, ScansKeptInMemoryAreWhatAReplayDecodesFromTheWrittenLog) {
  sim::Scenario scenario = smallSite();
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

std::vector<const io::BagMessage*> onTopic(const replay::RecordedLog& log, const std::string& topic) {
  std::vector<const io::BagMessage*> found;
  for (const io::BagMessage& m : log.messages())
    if (m.topic == topic) found.push_back(&m);
  return found;
}

TEST(TwinRecording, AnRsusPerfectTwinSendsWhatTheSameRsuPerfectlySurveyedAndSynchronisedSendsOnTheSameDrive) {
  testing::TempDir dir;
  TwinRecordingOptions options;
  options.perception_ablation = false;
  options.write_log = false;
  options.keep_log = true;
  // Past the RSU miscalibrated (15 cm, -10 cm, 0.5 deg, 10 ms), with its perfect twin.
  sim::Scenario off = smallSite();
  off.rsus[0].survey_error = Eigen::Vector3d(0.15, -0.10, 0.5 * M_PI / 180.0);
  off.rsus[0].clock_offset = 0.010;
  options.out_dir = (dir.path() / "miscalibrated").string();
  options.perfect_rsus = true;
  const TwinRecordingSummary with_twin = recordTwin(off, options);
  // The same drive past the RSU perfect, without a twin.
  sim::Scenario exact = smallSite();
  options.out_dir = (dir.path() / "perfect").string();
  options.perfect_rsus = false;
  const TwinRecordingSummary perfect = recordTwin(exact, options);
  const std::string id = exact.rsus[0].id;
  const auto twin = onTopic(*with_twin.log, rsu_client::addressedFixTopic(perfectRsuId(id)));
  const auto own = onTopic(*with_twin.log, rsu_client::addressedFixTopic(id));
  const auto expected = onTopic(*perfect.log, rsu_client::addressedFixTopic(id));
  ASSERT_GT(expected.size(), 20u);
  ASSERT_EQ(twin.size(), expected.size());
  ASSERT_EQ(own.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(twin[i]->log_time, expected[i]->log_time) << "fix " << i;
    EXPECT_EQ(twin[i]->data, expected[i]->data) << "fix " << i;  // the same position and stamp, to the bit
    // The RSU's own fix is where its survey says, 10 ms later on its clock.
    const io::Odometry a = std::get<io::Odometry>(io::decodeMessage(io::MessageKind::kOdometry, own[i]->data));
    const io::Odometry b = std::get<io::Odometry>(io::decodeMessage(io::MessageKind::kOdometry, twin[i]->data));
    EXPECT_EQ(a.child_frame_id, std::to_string(off.vehicle_station_id));  // addressed to the ego
    EXPECT_NEAR(a.header.stamp - b.header.stamp, 10'000'000, 1);
    const double shift = (a.pose.pose.position - b.pose.pose.position).head<2>().norm();
    EXPECT_GT(shift, 0.10) << "fix " << i;
    EXPECT_LT(shift, 0.18 + 0.5 * M_PI / 180.0 * 60.0) << "fix " << i;  // 18 cm and 0.5 deg at up to 60 m
  }
  // Everything else on the drive is the same.
  for (const std::string topic : {"/points", "/vehicle/twist", "/ground_truth/odom"}) {
    const auto a = onTopic(*with_twin.log, topic), b = onTopic(*perfect.log, topic);
    ASSERT_EQ(a.size(), b.size()) << topic;
    if (topic != "/points") {
      for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i]->data, b[i]->data) << topic << " message " << i;
    }
  }
}

// A real RSU never sees the street empty: the twin's learn their background from frames of it with its
// traffic and parked cars (TwinRecordingOptions::rsu_commissioning_frames), as roadside::BackgroundLearner
// does on site. A car parked since the survey half a metre beside the lane then is background: the
// vehicle passing it is found alone, where against the surveyed empty street the two merge into one
// object larger than the vehicle. The rest of the drive is drawn the same either way.
TEST(TwinRecording, AnRsuThatLearnedTheBusyStreetTakesACarParkedSinceTheSurveyForBackground) {
  std::ifstream in(COLOC_SOURCE_DIR "/test/tools/small_site.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string parked = "  - {type: parked_car, at: [25, 7.5], yaw: 0.0}\n";
  ASSERT_NE(yaml.find(parked), std::string::npos);
  // The vehicle's body spans y = -2.67 .. -0.83 in its lane; this one -0.32 .. 1.52, across the line.
  yaml.replace(yaml.find(parked), parked.size(), parked + "  - {type: parked_car, at: [36, 0.6], yaw: 0.0, in_map: false}\n");
  const sim::Scenario scenario = sim::parseScenario(yaml, "small_site.yaml");
  testing::TempDir dir;
  TwinRecordingOptions options;
  options.perception_ablation = false;
  options.write_log = false;
  options.keep_log = true;
  const auto run = [&](int frames, const std::string& name) {
    options.rsu_commissioning_frames = frames;
    options.out_dir = (dir.path() / name).string();
    return recordTwin(scenario, options);
  };
  const TwinRecordingSummary learned = run(20, "learned"), surveyed = run(0, "surveyed");
  const std::string id = scenario.rsus[0].id;
  const auto count = [&](const TwinRecordingSummary& s, roadside::Refusal why) {
    std::size_t n = 0;
    for (const RsuFrameRecord& f : s.rsu_frames.at(id)) n += f.refusal == why ? 1 : 0;
    return n;
  };
  const std::size_t merged = count(surveyed, roadside::Refusal::kTooLarge);
  std::printf("against the surveyed street: %zu fixes, %zu frames merged with the parked car; learned: %zu fixes\n",
              surveyed.fix_errors.at(id).size(), merged, learned.fix_errors.at(id).size());
  EXPECT_GE(merged, 3u) << "the parked car should merge with the passing vehicle against the empty street";
  EXPECT_EQ(count(learned, roadside::Refusal::kTooLarge), 0u);
  EXPECT_GE(learned.fix_errors.at(id).size(), surveyed.fix_errors.at(id).size() + merged - 1);
  std::vector<double> errors;
  for (const Eigen::Vector2d& e : learned.fix_errors.at(id)) errors.push_back(e.norm());
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);  // a VLP-32C 2 m up at 5-40 m: a few cm, as on the empty street
  EXPECT_LT(errors.back(), 0.3);
  for (const std::string topic : {"/points", "/vehicle/twist", "/ground_truth/odom"}) {
    const auto a = onTopic(*learned.log, topic), b = onTopic(*surveyed.log, topic);
    ASSERT_EQ(a.size(), b.size()) << topic;
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i]->data, b[i]->data) << topic << " message " << i;
  }
}

// The oracle bound withholds exactly the fixes farther than its limit from the truth, counts each as
// refused with its reason, and leaves every other fix of the drive as it was, to the bit.
TEST(TwinRecording, TheOracleLimitWithholdsExactlyTheFixesFartherThanItFromTheTruthAndNothingElse) {
  const sim::Scenario scenario = smallSite();  // its RSU surveyed exactly: a fix's error is the perception's
  testing::TempDir dir;
  TwinRecordingOptions options;
  options.perception_ablation = false;
  options.write_log = false;
  options.keep_log = true;
  options.out_dir = (dir.path() / "all").string();
  const TwinRecordingSummary all = recordTwin(scenario, options);
  const std::string id = scenario.rsus[0].id;
  const std::vector<Eigen::Vector2d>& errors = all.fix_errors.at(id);
  ASSERT_GT(errors.size(), 20u);
  std::vector<double> sizes;
  for (const Eigen::Vector2d& e : errors) sizes.push_back(e.norm());
  std::sort(sizes.begin(), sizes.end());
  // About half the fixes beyond it, halfway between two of them: a fix exactly at the limit would be
  // decided by the last bit of its survey transform, which the oracle reads before and this test after.
  const double limit = 0.5 * (sizes[sizes.size() / 2 - 1] + sizes[sizes.size() / 2]);
  options.out_dir = (dir.path() / "oracle").string();
  options.oracle_fix_limit = limit;
  const TwinRecordingSummary bounded = recordTwin(scenario, options);

  const auto sent = onTopic(*all.log, rsu_client::addressedFixTopic(id)), kept = onTopic(*bounded.log, rsu_client::addressedFixTopic(id));
  ASSERT_EQ(sent.size(), errors.size());  // no link loss: every fix is on the log
  std::size_t k = 0, beyond = 0;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    if (errors[i].norm() > limit) {
      ++beyond;
      continue;
    }
    ASSERT_LT(k, kept.size()) << "fix " << i << " within the limit was withheld";
    EXPECT_EQ(kept[k]->log_time, sent[i]->log_time) << "fix " << i;
    EXPECT_EQ(kept[k]->data, sent[i]->data) << "fix " << i;
    ++k;
  }
  EXPECT_EQ(k, kept.size());
  EXPECT_GT(beyond, 5u);
  for (const Eigen::Vector2d& e : bounded.fix_errors.at(id)) EXPECT_LE(e.norm(), limit);
  std::size_t refused = 0;
  for (const RsuFrameRecord& f : bounded.rsu_frames.at(id)) refused += f.refusal == roadside::Refusal::kBeyondOracleLimit ? 1 : 0;
  EXPECT_EQ(refused, beyond);
  EXPECT_EQ(bounded.rsu_frames.at(id).size(), all.rsu_frames.at(id).size());  // every frame accounted for

  options.oracle_fix_limit = -0.1;
  options.out_dir = (dir.path() / "negative").string();
  try {
    recordTwin(scenario, options);
    FAIL() << "a negative oracle limit was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("oracle fix limit must be a finite number of metres >= 0"), std::string::npos) << e.what();
  }
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
  TwinRecordingOptions bad_commissioning;
  bad_commissioning.rsu_commissioning_frames = -5;
  EXPECT_NE(message(bad_commissioning).find("commissioning frames must be 0-10000 (0: the surveyed empty street), not -5"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "drive" / "map"));  // refused before the survey
}

TEST(TwinRecording, RefusesPerfectTwinsWhoseTopicAnotherRsuUsesBeforeSimulating) {
  sim::Scenario scenario = smallSite();
  sim::ScenarioRsu other = scenario.rsus[0];
  other.id = perfectRsuId(scenario.rsus[0].id);
  other.position.x() += 20.0;
  scenario.rsus.push_back(other);
  testing::TempDir dir;
  TwinRecordingOptions options;
  options.out_dir = (dir.path() / "drive").string();
  options.perfect_rsus = true;
  try {
    recordTwin(scenario, options);
    FAIL() << "two RSUs on one topic were recorded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("RSU rsu_a's perfect twin would send on RSU rsu_a_perfect's topic"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "drive" / "map"));
}

}  // namespace
}  // namespace coloc::twin
