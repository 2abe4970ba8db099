#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <thread>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/mcap_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/pipeline/message_inputs.hpp"
#include "coloc/pipeline/ndt_quality_map.hpp"
#include "coloc/pipeline/static_transforms.hpp"
#include "coloc/replay/log_replay.hpp"
#include "real_data.hpp"
#include "temp_dir.hpp"
#include "transform_stamped.hpp"

namespace coloc::replay {
namespace {

std::string nav2() { return testing::realData("rosbag2/nav2_turtlebot.mcap"); }

io::TopicInfo topicOf(const std::string& name, const std::string& type) {
  io::TopicInfo info;
  info.name = name;
  info.type = type;
  return info;
}

const TopicUse& topic(const ReplayResult& r, const std::string& name) {
  for (const TopicUse& t : r.topics)
    if (t.topic == name) return t;
  throw Error("no topic " + name);
}

const fusion::SourceCounters& counters(const ReplayResult& r, const std::string& name) {
  for (const auto& s : r.sources)
    if (s.name == name) return s.counters;
  throw Error("no source " + name);
}

TEST(LogReplay, RealNav2RecordingIsFusedFromAmclPosesAndOdometryTwist) {
  const ReplayResult r = replayLog(nav2(), ReplayOptions());
  EXPECT_EQ(topic(r, "/amcl_pose").role, InputRole::kPose);
  EXPECT_EQ(topic(r, "/odom").role, InputRole::kTwist);
  EXPECT_EQ(topic(r, "/tf").role, InputRole::kIgnore);
  EXPECT_EQ(topic(r, "/tf").note, "moving frames are not used; the LiDAR's mounting is read from /tf_static");
  EXPECT_EQ(topic(r, "/tf_static").role, InputRole::kStaticTransforms);  // the real recording's transforms decode
  EXPECT_EQ(topic(r, "/tf_static").messages, 1u);
  EXPECT_EQ(topic(r, "/tf_static").decode_errors, 0u) << topic(r, "/tf_static").first_error;
  EXPECT_TRUE(r.lidar_pose_from.empty());  // no scans: no LiDAR to place
  EXPECT_EQ(topic(r, "/odom").fallback_covariance, 2639u);  // the TurtleBot's odometry carries no covariance
  // Header stamps are simulation time, log times wall clock: the replay must relate them, not mix them.
  EXPECT_EQ(r.clock, ClockMode::kSeparate);
  EXPECT_NEAR(r.clock_fit.rate, 0.9933, 0.002);
  EXPECT_LT(topic(r, "/odom").delay_median, 0.02);
  EXPECT_LT(topic(r, "/amcl_pose").delay_median, 0.1);
  const auto& amcl = counters(r, "/amcl_pose");
  EXPECT_EQ(amcl.received, 135u);
  EXPECT_GE(amcl.applied, 130u);
  EXPECT_EQ(amcl.gated + amcl.invalid + amcl.from_future, 0u);
  EXPECT_GT(counters(r, "/odom").applied, 2400u);
  // The fused path follows AMCL: on average within 10 cm of each AMCL pose at its stamp.
  ASSERT_GT(r.fused.size(), 4000u);
  double sum = 0.0;
  int n = 0;
  for (const io::TrajectoryPoint& p : r.pose_inputs) {
    const auto it = std::lower_bound(r.fused.begin(), r.fused.end(), p.stamp,
                                     [](const io::TrajectoryPoint& f, Stamp s) { return f.stamp < s; });
    if (it == r.fused.end()) continue;
    sum += (it->pose.position.head<2>() - p.pose.position.head<2>()).norm();
    ++n;
  }
  ASSERT_GT(n, 100);
  EXPECT_LT(sum / n, 0.10);
}

TEST(LogReplay, Sqlite3ConversionOfTheRecordingGivesTheSameFusedOutput) {
  testing::TempDir dir;
  io::convert(nav2(), dir / "nav2");
  const ReplayResult from_mcap = replayLog(nav2(), ReplayOptions());
  const ReplayResult from_db3 = replayLog(dir / "nav2", ReplayOptions());
  ASSERT_EQ(from_mcap.fused.size(), from_db3.fused.size());
  for (std::size_t i = 0; i < from_mcap.fused.size(); ++i) {
    ASSERT_EQ(from_mcap.fused[i].stamp, from_db3.fused[i].stamp);
    ASSERT_EQ(from_mcap.fused[i].pose.position, from_db3.fused[i].pose.position) << "tick " << i;
    ASSERT_EQ(from_mcap.fused[i].pose.orientation.coeffs(), from_db3.fused[i].pose.orientation.coeffs());
  }
}

// A straight drive at 5 m/s: ground truth at 100 Hz, odometry at 50 Hz (5 ms late), noisy NDT-like poses
// at 10 Hz (100 ms late), one truncated pose, and a topic of a type coloc does not read.
std::string writeSyntheticLog(const testing::TempDir& dir) {
  const std::string path = dir / "drive";
  io::BagWriter bag = io::BagWriter::create(path);
  bag.addTopic(topicOf("/ground_truth/odom", "nav_msgs/msg/Odometry"));
  bag.addTopic(topicOf("/vehicle/twist", "geometry_msgs/msg/TwistWithCovarianceStamped"));
  bag.addTopic(topicOf("/ndt_pose", "geometry_msgs/msg/PoseWithCovarianceStamped"));
  bag.addTopic(topicOf("/chatter", "std_msgs/msg/String"));
  const Stamp t0 = 1'700'000'000'000'000'000LL;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  auto truthAt = [](double t) { return Eigen::Vector3d(5.0 * t, 2.0, 0.0); };
  for (int i = 0; i <= 1000; ++i) {  // 10 s
    const Stamp t = t0 + i * 10'000'000LL;
    const double s = i * 0.01;
    io::Odometry gt;
    gt.header = {t, "map"};
    gt.child_frame_id = "base_link";
    gt.pose.pose.position = truthAt(s);
    const io::Bytes gt_bytes = io::encodeOdometry(gt);
    bag.write("/ground_truth/odom", t, gt_bytes.data(), gt_bytes.size());
    if (i % 2 == 0) {
      io::StampedTwist tw;
      tw.header = {t, "base_link"};
      tw.measurement.linear = {5.0, 0.0, 0.0};
      tw.measurement.covariance = Matrix6d::Zero();
      tw.measurement.covariance.diagonal() << 0.01, 0.01, 0.01, 0.01, 0.01, 0.001;
      const io::Bytes b = io::encodeTwistWithCovarianceStamped(tw);
      bag.write("/vehicle/twist", t + 5'000'000, b.data(), b.size());
    }
    if (i % 10 == 0) {
      io::StampedPose p;
      p.header = {t, "map"};
      p.measurement.pose.position = truthAt(s) + Eigen::Vector3d(noise(rng), noise(rng), 0.0);
      p.measurement.covariance = Matrix6d::Zero();  // z, roll, pitch 0: "not estimated", as AMCL writes
      p.measurement.covariance.diagonal() << 0.01, 0.01, 0.0, 0.0, 0.0, 0.0004;
      io::Bytes b = io::encodePoseWithCovarianceStamped(p);
      if (i == 500) b.resize(b.size() / 2);  // one message cut short
      bag.write("/ndt_pose", t + 100'000'000, b.data(), b.size());
    }
    if (i % 100 == 0) {
      const std::uint8_t text[] = {0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0, 0};
      bag.write("/chatter", t, text, sizeof text);
    }
  }
  bag.close();
  return path;
}

TEST(LogReplay, SyntheticDriveIsFusedAndScoredAgainstItsGroundTruth) {
  testing::TempDir dir;
  const ReplayResult r = replayLog(writeSyntheticLog(dir), ReplayOptions());
  EXPECT_EQ(r.clock, ClockMode::kSame);
  EXPECT_EQ(topic(r, "/ground_truth/odom").role, InputRole::kGroundTruth);
  EXPECT_EQ(topic(r, "/chatter").role, InputRole::kIgnore);
  EXPECT_NEAR(topic(r, "/ndt_pose").delay_median, 0.100, 1e-6);
  EXPECT_NEAR(topic(r, "/vehicle/twist").delay_median, 0.005, 1e-6);
  // The truncated message is counted and named, and the replay goes on.
  EXPECT_EQ(topic(r, "/ndt_pose").decode_errors, 1u);
  EXPECT_NE(topic(r, "/ndt_pose").first_error.find("topic /ndt_pose message #"), std::string::npos)
      << topic(r, "/ndt_pose").first_error;
  EXPECT_EQ(counters(r, "/ndt_pose").applied, 100u);
  ASSERT_GT(r.errors.size(), 400u);
  double mean = 0.0;
  for (const ErrorSample& e : r.errors) mean += e.error;
  mean /= r.errors.size();
  // Poses alone err by 0.125 m on average (2-D, sigma 0.1 m); fused with odometry clearly less.
  EXPECT_LT(mean, 0.08);
}

// The synthetic log's poses through a link that delays them 50 ms and loses 30 %.
ReplayOptions poseLinkOptions() {
  ReplayOptions options;
  options.config = pipeline::parseConfig(
      "inputs:\n  /ndt_pose: {role: pose, link: {delay: 0.05, jitter: 0.0, loss: 0.3, seed: 5}}\n", "test.yaml");
  return options;
}

TEST(LogReplay, TopicReplayedThroughAnEmulatedLinkIsDelayedAndThinnedRepeatably) {
  testing::TempDir dir;
  const std::string log = writeSyntheticLog(dir);
  ReplayOptions options = poseLinkOptions();
  const ReplayResult a = replayLog(log, options), b = replayLog(log, options);
  const TopicUse& pose = topic(a, "/ndt_pose");
  EXPECT_GT(pose.link_dropped, 10u);
  EXPECT_LT(pose.link_dropped, 50u);
  EXPECT_NEAR(pose.delay_median, 0.150, 1e-6);  // 100 ms recorded + 50 ms emulated
  EXPECT_EQ(counters(a, "/ndt_pose").applied + pose.link_dropped, 100u);  // 101 written, one undecodable
  EXPECT_EQ(topic(b, "/ndt_pose").link_dropped, pose.link_dropped);
  ASSERT_EQ(a.fused.size(), b.fused.size());
  EXPECT_EQ(a.fused.back().pose.position, b.fused.back().pose.position);
}

TEST(LogReplay, AReplayEndedEarlyGivesOutWhatTheWholeReplayGaveUpToItsEnd) {
  testing::TempDir dir;
  const std::string log = writeSyntheticLog(dir);
  ReplayOptions options = poseLinkOptions();
  const ReplayResult whole = replayLog(log, options);
  ASSERT_GT(whole.fused.size(), 100u);
  options.until = whole.fused[whole.fused.size() / 2].stamp;
  const ReplayResult part = replayLog(log, options);
  // Every estimate up to the end is the whole replay's, to the bit; none after it.
  ASSERT_FALSE(part.fused.empty());
  EXPECT_LE(part.fused.back().stamp, options.until);
  ASSERT_LE(part.fused.size(), whole.fused.size());
  EXPECT_GE(part.fused.size(), whole.fused.size() / 2 - 1);
  for (std::size_t k = 0; k < part.fused.size(); ++k) {
    EXPECT_EQ(part.fused[k].stamp, whole.fused[k].stamp);
    EXPECT_EQ(part.fused[k].pose.position, whole.fused[k].pose.position) << "tick " << k;
  }
  // What the log counts covers all of it; the filter saw only the inputs that arrived by the end.
  EXPECT_EQ(part.messages_read, whole.messages_read);
  EXPECT_EQ(topic(part, "/ndt_pose").link_dropped, topic(whole, "/ndt_pose").link_dropped);
  EXPECT_GT(part.inputs_after_until, 100u);
  EXPECT_EQ(whole.inputs_after_until, 0u);
  EXPECT_LT(counters(part, "/ndt_pose").applied, counters(whole, "/ndt_pose").applied);
  // Ended before any input, nothing is fused: the error says where the replay ended.
  options.until = whole.fused.front().stamp - 10 * kNanosPerSecond;
  try {
    replayLog(log, options);
    FAIL() << "a replay ended before its first input fused something";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nothing fused"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the replay ended at stamp " + formatSeconds(options.until) + " (until)"), std::string::npos) << e.what();
  }
}

TEST(LogReplay, ConfiguredRoleOnAnIncompatibleTypeIsAnErrorNamingTheTopic) {
  testing::TempDir dir;
  ReplayOptions options;
  options.config = pipeline::parseConfig("inputs:\n  /vehicle/twist: {role: pose}\n", "test.yaml");
  try {
    replayLog(writeSyntheticLog(dir), options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("inputs./vehicle/twist.role"), std::string::npos) << e.what();
  }
}

TEST(LogReplay, MissingLogIsAnErrorNamingIt) {
  EXPECT_THROW(replayLog("/nonexistent/log.mcap", ReplayOptions()), Error);
}

}  // namespace
}  // namespace coloc::replay

namespace coloc::replay {
namespace {

io::PointCloud2 toMessage(const ndt::PointCloud& cloud, Stamp stamp) {
  io::PointCloud2 m;
  m.header = {stamp, "lidar"};
  m.height = 1;
  m.width = static_cast<std::uint32_t>(cloud.size());
  m.fields = {{"x", 0, io::PointField::kFloat32, 1}, {"y", 4, io::PointField::kFloat32, 1}, {"z", 8, io::PointField::kFloat32, 1}};
  m.point_step = 12;
  m.row_step = 12 * m.width;
  m.is_dense = true;
  m.data.resize(m.row_step);
  std::memcpy(m.data.data(), cloud.points.data(), m.data.size());
  return m;
}

// The real HDL-32E pair's source scan `count` times, 0.1 s apart, as a standing vehicle would see it;
// the message at `truncated` (if any) cut to a third; with `twist_speed` >= 0, twists at 50 Hz that
// read that speed (m/s, variance 0.0025).
void writeScanLog(const std::string& path, int count, int truncated = -1, double twist_speed = -1.0) {
  const ndt::PointCloud scan = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const Stamp t0 = 1'700'000'000'000'000'000LL;
  io::BagWriter bag = io::BagWriter::create(path);
  bag.addTopic(topicOf("/points", "sensor_msgs/msg/PointCloud2"));
  for (int i = 0; i < count; ++i) {
    io::Bytes b = io::encodePointCloud2(toMessage(scan, t0 + i * 100'000'000LL));
    if (i == truncated) b.resize(b.size() / 3);
    bag.write("/points", t0 + i * 100'000'000LL + 30'000'000LL, b.data(), b.size());
  }
  if (twist_speed >= 0.0) {
    bag.addTopic(topicOf("/vehicle/twist", "geometry_msgs/msg/TwistWithCovarianceStamped"));
    for (int k = 0; k < 5 * count; ++k) {
      io::StampedTwist tw;
      tw.header = {t0 + k * 20'000'000LL, "base_link"};
      tw.measurement.linear = {twist_speed, 0.0, 0.0};
      tw.measurement.covariance = Matrix6d::Zero();
      tw.measurement.covariance.diagonal() << 0.0025, 0.0, 0.0, 0.0, 0.0, 2.5e-5;
      const io::Bytes b = io::encodeTwistWithCovarianceStamped(tw);
      bag.write("/vehicle/twist", t0 + k * 20'000'000LL + 1'000'000LL, b.data(), b.size());
    }
  }
  bag.close();
}

TEST(LogReplay, ScansInTheLogAreMatchedAgainstTheMapAndFused) {
  // The real HDL-32E pair: the target scan is the map, the source scan is in the log.
  testing::TempDir dir;
  const std::string map = testing::realData("hdl32e_pair/target.pcd");
  writeScanLog(dir / "scans", 3);
  ReplayOptions options;
  options.map = map;
  options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\nndt:\n  voxel_size: 1.0\n", "test.yaml");
  const ReplayResult r = replayLog(dir / "scans", options);
  EXPECT_TRUE(r.ndt_used);
  EXPECT_EQ(topic(r, "/points").role, InputRole::kScan);
  EXPECT_EQ(r.ndt.scans, 3u);
  EXPECT_EQ(r.ndt.poses, 3u);
  const Eigen::Matrix4d gt1 = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
  ASSERT_FALSE(r.pose_inputs.empty());
  EXPECT_NEAR(r.pose_inputs.back().pose.position.x(), gt1(0, 3), 0.03);
  EXPECT_NEAR(r.pose_inputs.back().pose.position.y(), gt1(1, 3), 0.03);
  EXPECT_GE(counters(r, "ndt").applied, 3u);
}

// The real pair's source scan as a LiDAR mounted at `mount` on the vehicle records it (points in the
// LiDAR's frame "velodyne_top"), with the log's /tf_static placing that frame through a sensor kit, and
// `extra` transforms after them.
void writeMountedScanLog(const std::string& path, const Eigen::Isometry3d& mount, const std::vector<io::TransformStamped>& extra = {}) {
  const ndt::PointCloud scan = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  ndt::PointCloud in_lidar;
  for (const auto& p : scan.points) in_lidar.points.push_back((mount.inverse() * p.cast<double>()).cast<float>());
  const Stamp t0 = 1'700'000'000'000'000'000LL;
  // base_link -> sensor_kit (0.5 m up, 0.1 rad of yaw) -> velodyne_top (the rest of the mount).
  Eigen::Isometry3d kit = Eigen::Isometry3d::Identity();
  kit.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  kit.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Isometry3d rest = kit.inverse() * mount;
  io::TFMessage tf;
  tf.transforms.push_back(coloc::testing::transformStamped(t0, "base_link", "sensor_kit", kit.translation(), Eigen::Quaterniond(kit.linear())));
  tf.transforms.push_back(coloc::testing::transformStamped(t0, "sensor_kit", "velodyne_top", rest.translation(), Eigen::Quaterniond(rest.linear())));
  tf.transforms.insert(tf.transforms.end(), extra.begin(), extra.end());
  io::BagWriter bag = io::BagWriter::create(path);
  bag.addTopic(topicOf("/tf_static", "tf2_msgs/msg/TFMessage"));
  bag.addTopic(topicOf("/points", "sensor_msgs/msg/PointCloud2"));
  const io::Bytes tf_bytes = io::encodeTFMessage(tf);
  bag.write("/tf_static", t0, tf_bytes.data(), tf_bytes.size());
  for (int i = 0; i < 3; ++i) {
    io::PointCloud2 m = toMessage(in_lidar, t0 + i * 100'000'000LL);
    m.header.frame_id = "velodyne_top";
    const io::Bytes b = io::encodePointCloud2(m);
    bag.write("/points", t0 + i * 100'000'000LL + 30'000'000LL, b.data(), b.size());
  }
  bag.close();
}

Eigen::Isometry3d testMount() {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.translation() = Eigen::Vector3d(1.2, -0.3, 1.8);
  mount.linear() = quaternionFromRollPitchYaw(0.01, -0.02, 0.25).toRotationMatrix();
  return mount;
}

ReplayResult replayAgainstThePairsMap(const std::string& log, const std::string& extra_config = "") {
  ReplayOptions options;
  options.map = testing::realData("hdl32e_pair/target.pcd");
  options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\nndt:\n  voxel_size: 1.0\n" + extra_config, "test.yaml");
  return replayLog(log, options);
}

// NDT's error by place (ndt.quality_map): where a drive with a reference found NDT poor, its poses are
// worth no more than that, whatever their fit says; elsewhere they are as NDT gives them. A map that
// cannot be read stops the replay before anything is fused, naming the file.
TEST(LogReplay, NdtPosesWhereTheQualityMapFoundNdtPoorAreTakenAtItsVariance) {
  testing::TempDir dir;
  writeScanLog(dir / "scans", 3);
  const Eigen::Vector2d here = testing::wherePairsScansMatch();
  // One cell (10 m) around where the scans are matched, NDT 0.5 m off there on the reference drive;
  // another far away.
  std::vector<pipeline::NdtQualitySample> samples;
  for (int i = 0; i < 5; ++i) samples.push_back({here, Eigen::Vector2d(0.5, 0.5)});
  for (int i = 0; i < 5; ++i) samples.push_back({here + Eigen::Vector2d(100.0, 0.0), Eigen::Vector2d(0.01, 0.0)});
  const pipeline::NdtQualityMap poor = pipeline::NdtQualityMap::fromErrors(samples, 10.0, 5, 0.0);
  ASSERT_NEAR(poor.varianceAt(here), 0.25, 1e-12);
  std::ofstream(dir / "poor.yaml") << poor.toYaml();
  const ReplayResult plain = replayAgainstThePairsMap(dir / "scans");
  const ReplayResult floored = replayAgainstThePairsMap(dir / "scans", "  quality_map: " + (dir / "poor.yaml") + "\n");
  EXPECT_EQ(plain.pipeline_report.ndt_quality_raised, 0u);
  EXPECT_EQ(floored.pipeline_report.ndt_quality_raised, floored.ndt.poses);
  ASSERT_EQ(floored.ndt.poses, 3u);
  int claimed = 0;
  for (const auto& [key, covariance] : floored.claimedCovariances()) {
    if (key.first != pipeline::kNdtSource) continue;
    ++claimed;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> e(covariance);
    EXPECT_GE(e.eigenvalues().minCoeff(), 0.25 * (1.0 - 1e-9));
  }
  EXPECT_EQ(claimed, 3);
  // With the filter's map-matching bias but no roadside fix to tell it apart, the bias is held and
  // the filter takes the poses floored at their place's whole error all the same (raised: near a fix
  // they would be floored at the map's noise, 0 here); reported on their own, they always are.
  const ReplayResult held = replayAgainstThePairsMap(dir / "scans", "  quality_map: " + (dir / "poor.yaml") + "\nfusion:\n  map_match_bias_sd: 0.1\n");
  EXPECT_EQ(held.pipeline_report.ndt_quality_raised, 3u);
  for (const auto& [key, covariance] : held.claimedCovariances()) {
    if (key.first == pipeline::kNdtSource) {
      EXPECT_GE(covariance.trace(), 0.5 * (1.0 - 1e-9));
    }
  }
  for (const auto& [key, covariance] : plain.claimedCovariances()) {
    if (key.first != pipeline::kNdtSource) continue;
    EXPECT_LT(covariance.trace(), 0.1) << "the fit's own covariance, as before";
  }
  // With the odometry's slow errors modelled as well, nothing is left that held the bias: it is loose
  // everywhere, the poses floored at the map's noise (0 here), and the report gives the states.
  const ReplayResult loose =
      replayAgainstThePairsMap(dir / "scans", "  quality_map: " + (dir / "poor.yaml") + "\nfusion:\n  map_match_bias_sd: 0.1\n  odometry_scale_sd: 0.02\n");
  EXPECT_EQ(loose.pipeline_report.ndt_quality_raised, 0u);
  EXPECT_TRUE(loose.pipeline_report.filter_odometry_modelled);
  EXPECT_FALSE(held.pipeline_report.filter_odometry_modelled);
  EXPECT_NE(loose.summaryJson("scans").find("\"filter_odometry_states\""), std::string::npos);
  EXPECT_EQ(held.summaryJson("scans").find("\"filter_odometry_states\""), std::string::npos);
  // NDT's noise measured along the vehicle and across it (ndt.quality_noise_by_direction): where the
  // bias is loose, each pose floored at each in its own direction (NdtQualityMap::noiseAt,
  // coveringAtLeast); the poses the filter takes are not reported on their own, which stay at their
  // place's whole error.
  std::vector<pipeline::NdtQualitySample> shaking;
  for (int i = 0; i < 6; ++i) shaking.push_back({here, Eigen::Vector2d(i % 2 ? 0.2 : -0.2, 0.0), 0.0});
  const pipeline::NdtQualityMap along = pipeline::NdtQualityMap::fromErrors(shaking, 10.0, 5, 0.0);
  ASSERT_TRUE(along.noiseAlongAcross());
  std::ofstream(dir / "along.yaml") << along.toYaml();
  const ReplayResult by_direction = replayAgainstThePairsMap(
      dir / "scans", "  quality_map: " + (dir / "along.yaml") + "\n  quality_noise_by_direction: true\nfusion:\n  map_match_bias_sd: 0.1\n  odometry_scale_sd: 0.02\n");
  EXPECT_EQ(by_direction.pipeline_report.ndt_quality_raised, 3u) << "the fit's 1 cm along raised to the noise's 28 cm";
  for (const auto& [key, covariance] : by_direction.claimedCovariances()) {
    if (key.first != pipeline::kNdtSource) continue;
    EXPECT_GE(std::min(covariance(0, 0), covariance(1, 1)), along.varianceAt(here) * (1.0 - 1e-9));
  }
  // The same poses where the map's only cell lies elsewhere and its default is nothing: as NDT gave them.
  std::ofstream(dir / "elsewhere.yaml") << pipeline::NdtQualityMap::fromErrors({samples.begin() + 5, samples.end()}, 10.0, 5, 0.0).toYaml();
  EXPECT_EQ(replayAgainstThePairsMap(dir / "scans", "  quality_map: " + (dir / "elsewhere.yaml") + "\n").pipeline_report.ndt_quality_raised, 0u);
  try {
    replayAgainstThePairsMap(dir / "scans", "  quality_map: " + (dir / "absent.yaml") + "\n");
    FAIL() << "a quality map that is not there was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("absent.yaml"), std::string::npos) << e.what();
  }
}

// ndt.quality_floor: noise. Where nothing tells NDT's bias apart it is followed, and each pose is
// worth its own part alone: at least its place's scan-to-scan noise in every direction and in yaw,
// and at most what NDT was there on the reference drive (its score's probes, half a metre apart,
// cannot tell a millimetre from a centimetre).
TEST(LogReplay, NdtAtItsNoiseTakesEachPoseBetweenItsPlacesNoiseAndItsErrorInEachDirection) {
  testing::TempDir dir;
  writeScanLog(dir / "scans", 3);
  const Eigen::Vector2d here = testing::wherePairsScansMatch();
  // The reference drive, eastward through the cell: NDT 5 cm ahead with 1 cm of noise along, 1 mm to
  // the left with 0.5 mm across, its yaw 1 mrad off with 1 mrad of noise.
  std::vector<pipeline::NdtQualitySample> samples;
  for (int i = 0; i < 10; ++i) {
    const double sign = i % 2 ? 1.0 : -1.0;
    samples.push_back({here + Eigen::Vector2d(0.3 * i - 1.5, 0.0), Eigen::Vector2d(0.05 + 0.005 * sign, 0.001 + 0.00025 * sign), 0.0, 0.001 + 0.0005 * sign});
  }
  const pipeline::NdtQualityMap map = pipeline::NdtQualityMap::fromErrors(samples, 10.0, 5, 0.0);
  std::ofstream(dir / "noise.yaml") << map.toYaml();
  const auto replay = [&](const std::string& floor) {
    ReplayOptions options;
    options.map = testing::realData("hdl32e_pair/target.pcd");
    options.keep_filter_inputs = true;
    options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\n  travel_check_window: 0\nndt:\n  voxel_size: 1.0\n"
                                           "  covariance_floor: [1e-9, 1e-9, 0.0225, 0.000625, 0.000625, 1e-9]\n  quality_map: " + (dir / "noise.yaml") +
                                               "\n  quality_floor: " + floor + "\n",
                                           "test.yaml");
    return replayLog(dir / "scans", options);
  };
  const ReplayResult error = replay("error"), noise = replay("noise");
  ASSERT_EQ(noise.ndt.poses, 3u);
  EXPECT_EQ(error.pipeline_report.ndt_quality_lowered, 0u);
  int seen = 0;
  for (const auto& [name, pose] : noise.weighed_poses) {
    if (name != pipeline::kNdtSource) continue;
    ++seen;
    const double yaw = std::atan2(pose.pose.orientation.toRotationMatrix()(1, 0), pose.pose.orientation.toRotationMatrix()(0, 0));
    const Eigen::Matrix2d floor = *map.noiseAt(pose.pose.position.head<2>(), yaw), cap = *map.errorAt(pose.pose.position.head<2>(), yaw);
    const Eigen::Matrix2d xy = pose.covariance.topLeftCorner<2, 2>();
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(xy - floor).eigenvalues().minCoeff(), -1e-15) << "at least the noise";
    // In the vehicle's frame: across, at most the place's error (1e-6 + 6e-8 m^2), where NDT's fit
    // claimed more; along, the fit's own where it lies between the two.
    const Eigen::Matrix2d turn = Eigen::Rotation2Dd(-yaw).toRotationMatrix();
    const Eigen::Matrix2d body = turn * xy * turn.transpose(), body_cap = turn * cap * turn.transpose();
    EXPECT_LE(body(1, 1), body_cap(1, 1) * (1.0 + 1e-6));
    EXPECT_LE(body(0, 0), body_cap(0, 0) * (1.0 + 1e-6));
    EXPECT_NEAR(pose.covariance(5, 5), *map.yawNoiseAt(pose.pose.position.head<2>()), 1e-12) << "NDT's yaw, its floor 1e-9, raised to the place's noise";
  }
  EXPECT_EQ(seen, 3);
  EXPECT_GE(noise.pipeline_report.ndt_quality_lowered, 1u) << "where NDT's fit claimed more across than NDT was there";
  // On their own (for the smoother, NDT's topic) the poses stay at their place's whole error, in yaw
  // too (1 mrad off, its square and its noise's), and so does the filter's in the default mode.
  for (const auto& [name, pose] : noise.filter_poses) {
    if (name != pipeline::kNdtSource) continue;
    const double trace = pose.covariance.topLeftCorner<2, 2>().trace();
    EXPECT_GE(trace, 2.0 * map.varianceAt(here) * (1.0 - 1e-9));
    EXPECT_NEAR(pose.covariance(5, 5), *map.yawErrorAt(pose.pose.position.head<2>()), 1e-12) << "its yaw at its place's whole yaw error";
  }
  for (const auto& [name, pose] : error.weighed_poses) {
    if (name != pipeline::kNdtSource) continue;
    const double trace = pose.covariance.topLeftCorner<2, 2>().trace();
    EXPECT_GE(trace, 2.0 * map.varianceAt(here) * (1.0 - 1e-9)) << "at its place's whole error";
  }
  // A key that is neither is refused naming it.
  try {
    pipeline::parseConfig("ndt:\n  quality_floor: bias\n", "test.yaml");
    FAIL() << "quality_floor: bias taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("quality_floor"), std::string::npos) << e.what();
  }
}

// pipeline.speed_scale_uncertainty: the odometry's stated covariance says nothing of its wheel's
// scale, which NDT's chords teach only after the first 5 m; until then each twist's speed variance
// holds a wheel's 2 % of its speed as well. Off, the twists go in as the log has them.
TEST(LogReplay, BeforeTheScaleIsLearnedEachTwistsSpeedVarianceHoldsAWheelsTwoPercent) {
  testing::TempDir dir;
  writeScanLog(dir / "scans", 3, -1, 2.0);
  const auto replay = [&](const std::string& on) {
    ReplayOptions options;
    options.map = testing::realData("hdl32e_pair/target.pcd");
    options.keep_filter_inputs = true;
    options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\n  speed_scale_uncertainty: " + on + "\nndt:\n  voxel_size: 1.0\n", "test.yaml");
    return replayLog(dir / "scans", options);
  };
  const ReplayResult with = replay("true"), without = replay("false");
  ASSERT_EQ(with.filter_twists.size(), 15u);
  ASSERT_EQ(with.received_twists.size(), 15u);
  for (std::size_t i = 0; i < with.filter_twists.size(); ++i) {
    EXPECT_NEAR(with.filter_twists[i].second.covariance(0, 0), 0.0025 + (0.02 * 2.0) * (0.02 * 2.0), 1e-12) << i;
    EXPECT_NEAR(without.filter_twists[i].second.covariance(0, 0), 0.0025, 1e-15) << i;
    EXPECT_EQ(with.received_twists[i].second.covariance(0, 0), 0.0025) << "as the log has it";
  }
}

TEST(LogReplay, ALogsTfStaticPlacesTheLidarWhereTheConfigDoesNot) {
  testing::TempDir dir;
  writeScanLog(dir / "plain", 3);
  writeMountedScanLog(dir / "mounted", testMount());
  const ReplayResult plain = replayAgainstThePairsMap(dir / "plain");
  const ReplayResult mounted = replayAgainstThePairsMap(dir / "mounted");
  EXPECT_EQ(topic(mounted, "/tf_static").role, InputRole::kStaticTransforms);
  EXPECT_EQ(topic(mounted, "/points").frame_id, "velodyne_top");
  EXPECT_EQ(mounted.lidar_pose_from, "/tf_static: velodyne_top in base_link");
  const Vector6d expected = pipeline::poseVector(testMount());
  EXPECT_LT((mounted.lidar_pose - expected).norm(), 1e-9);
  // Matched as the scan taken at the vehicle's origin is: both within 3 cm of the pair's reference (the
  // range crop and the voxel grid work in the LiDAR's frame, so the points NDT gets differ a little).
  const Eigen::Matrix4d gt1 = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
  ASSERT_EQ(mounted.ndt.poses, 3u);
  for (const ReplayResult* r : {&plain, &mounted}) {
    ASSERT_FALSE(r->pose_inputs.empty());
    EXPECT_LT((r->pose_inputs.back().pose.position.head<2>() - gt1.block<2, 1>(0, 3)).norm(), 0.03);
  }
  // Taken at the origin instead, the same scans are 1.2 m off: NDT does not find the reference.
  const ReplayResult at_origin = replayAgainstThePairsMap(dir / "mounted", "  base_frame: base_footprint\n");
  EXPECT_TRUE(at_origin.pose_inputs.empty() || (at_origin.pose_inputs.back().pose.position.head<2>() - gt1.block<2, 1>(0, 3)).norm() > 0.3);
  EXPECT_NE(mounted.summaryJson("log").find("\"from\": \"/tf_static: velodyne_top in base_link\""), std::string::npos);
}

TEST(LogReplay, AConfiguredLidarPoseWinsAndAnUnconnectedBaseFrameLeavesTheLidarAtTheOriginSayingWhy) {
  testing::TempDir dir;
  writeMountedScanLog(dir / "mounted", testMount());
  const Vector6d m = pipeline::poseVector(testMount());
  char configured[200];
  std::snprintf(configured, sizeof configured, "  lidar_pose: [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]\n", m[0], m[1], m[2], m[3], m[4], m[5]);
  const ReplayResult given = replayAgainstThePairsMap(dir / "mounted", configured);
  EXPECT_EQ(given.lidar_pose_from, "ndt.lidar_pose (configured)");
  EXPECT_EQ(given.lidar_pose, m);
  const ReplayResult unconnected = replayAgainstThePairsMap(dir / "mounted", "  base_frame: base_footprint\n");
  EXPECT_EQ(unconnected.lidar_pose, Vector6d::Zero());
  EXPECT_NE(unconnected.lidar_pose_from.find("does not connect 'base_footprint' (ndt.base_frame) to the scans' frame 'velodyne_top'"),
            std::string::npos)
      << unconnected.lidar_pose_from;
}

TEST(LogReplay, ABadTransformInTfStaticIsCountedNamingItsFramesAndTheOthersAreKept) {
  testing::TempDir dir;
  io::TransformStamped bad;
  bad.header.frame_id = "base_link";
  bad.child_frame_id = "camera";
  bad.rotation = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  writeMountedScanLog(dir / "mounted", testMount(), {bad});
  const ReplayResult r = replayAgainstThePairsMap(dir / "mounted");
  EXPECT_EQ(topic(r, "/tf_static").decode_errors, 1u);
  EXPECT_NE(topic(r, "/tf_static").first_error.find("static transform 'base_link' -> 'camera': rotation is not a unit quaternion"),
            std::string::npos)
      << topic(r, "/tf_static").first_error;
  EXPECT_EQ(r.lidar_pose_from, "/tf_static: velodyne_top in base_link");
}

TEST(LogReplay, ReplaysSharingACacheGiveTheSameResultsAsReplaysApart) {
  // Scans (one of them truncated), replayed from two starting poses side by side through one cache and
  // each alone: the same fused output, NDT counters and decode errors; the log is read once.
  testing::TempDir dir;
  const std::string map = testing::realData("hdl32e_pair/target.pcd");
  writeScanLog(dir / "scans", 4, 2);
  auto optionsFrom = [&](const std::string& start) {
    ReplayOptions options;
    options.map = map;
    options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [" + start + ", 0.0, 0.0]\nndt:\n  voxel_size: 1.0\n", "test.yaml");
    return options;
  };
  const std::vector<std::string> starts = {"0.3, 0.3", "-0.2, 0.4"};
  auto cache = std::make_shared<ReplayCache>();
  std::vector<ReplayResult> shared(starts.size()), apart(starts.size());
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < starts.size(); ++i)
    threads.emplace_back([&, i] {
      ReplayOptions options = optionsFrom(starts[i]);
      options.cache = cache;
      shared[i] = replayLog(dir / "scans", options);
    });
  for (std::thread& t : threads) t.join();
  for (std::size_t i = 0; i < starts.size(); ++i) {
    apart[i] = replayLog(dir / "scans", optionsFrom(starts[i]));
    ASSERT_EQ(shared[i].fused.size(), apart[i].fused.size());
    for (std::size_t k = 0; k < apart[i].fused.size(); ++k) {
      EXPECT_EQ(shared[i].fused[k].stamp, apart[i].fused[k].stamp);
      EXPECT_EQ(shared[i].fused[k].pose.position, apart[i].fused[k].pose.position) << "start " << starts[i] << ", tick " << k;
    }
    EXPECT_EQ(shared[i].ndt.poses, apart[i].ndt.poses);
    EXPECT_EQ(topic(shared[i], "/points").decode_errors, 1u);
    EXPECT_EQ(topic(shared[i], "/points").first_error, topic(apart[i], "/points").first_error);
    EXPECT_EQ(shared[i].summaryJson("log"), apart[i].summaryJson("log"));
  }
  EXPECT_EQ(apart[0].ndt.scans, 3u);
  EXPECT_EQ(cache->log(dir / "scans").use_count(), 2);  // the cache's copy and this one: read once
  EXPECT_EQ(cache->targets()->stats().builds, 1u);
}

// The log at `file` and `in_memory` replayed against the real pair's map: the same fused poses and summary.
void expectTheSameReplay(const std::string& file, const std::shared_ptr<const RecordedLog>& in_memory) {
  ReplayOptions options;
  options.map = testing::realData("hdl32e_pair/target.pcd");
  options.config = pipeline::parseConfig("pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\nndt:\n  voxel_size: 1.0\n", "test.yaml");
  const ReplayResult read = replayLog(file, options);
  options.cache = std::make_shared<ReplayCache>();
  options.cache->add("drive in memory", in_memory);
  const ReplayResult kept = replayLog("drive in memory", options);
  ASSERT_EQ(kept.fused.size(), read.fused.size());
  for (std::size_t k = 0; k < read.fused.size(); ++k) EXPECT_EQ(kept.fused[k].pose.position, read.fused[k].pose.position) << "tick " << k;
  EXPECT_EQ(kept.summaryJson("log"), read.summaryJson("log"));
}

TEST(LogReplay, ALogMadeInMemoryIsTheLogAReaderGivesFromItsFileAndReplaysTheSame) {
  // Messages written out of time order (an RSU's fix arrives late): the log in memory puts them in the
  // order and numbering the rosbag2 reader gives, counts each topic, and replays as the file does.
  testing::TempDir dir;
  const ndt::PointCloud scan = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const Stamp t0 = 1'700'000'000'000'000'000LL;
  std::vector<io::TopicInfo> topics = {topicOf("/points", "sensor_msgs/msg/PointCloud2"), topicOf("/late", "sensor_msgs/msg/PointCloud2")};
  std::vector<io::BagMessage> messages;
  {
    io::BagWriter bag = io::BagWriter::create(dir / "scans");
    for (const io::TopicInfo& t : topics) bag.addTopic(t);
    for (int i = 0; i < 3; ++i) {
      io::BagMessage m;
      m.topic = i == 1 ? "/late" : "/points";
      m.log_time = t0 + (i == 1 ? 250'000'000LL : i * 100'000'000LL);  // the second written is logged last
      m.data = io::encodePointCloud2(toMessage(scan, t0 + i * 100'000'000LL));
      bag.write(m.topic, m.log_time, m.data.data(), m.data.size());
      messages.push_back(m);
    }
    bag.close();
  }
  const RecordedLog from_file(dir / "scans");
  auto in_memory = std::make_shared<const RecordedLog>(topics, messages);
  ASSERT_EQ(in_memory->messages().size(), from_file.messages().size());
  for (std::size_t i = 0; i < from_file.messages().size(); ++i) {
    EXPECT_EQ(in_memory->messages()[i].topic, from_file.messages()[i].topic) << "message " << i;
    EXPECT_EQ(in_memory->messages()[i].log_time, from_file.messages()[i].log_time) << "message " << i;
    EXPECT_EQ(in_memory->messages()[i].index, from_file.messages()[i].index) << "message " << i;
    EXPECT_EQ(in_memory->messages()[i].data, from_file.messages()[i].data) << "message " << i;
  }
  EXPECT_EQ(in_memory->messages().back().topic, "/late");
  ASSERT_EQ(in_memory->topics().size(), from_file.topics().size());
  for (std::size_t i = 0; i < from_file.topics().size(); ++i) {
    EXPECT_EQ(in_memory->topics()[i].name, from_file.topics()[i].name);
    EXPECT_EQ(in_memory->topics()[i].type, from_file.topics()[i].type);
    EXPECT_EQ(in_memory->topics()[i].message_count, from_file.topics()[i].message_count);
  }
  expectTheSameReplay(dir / "scans", in_memory);

  messages.front().topic = "/unlisted";
  try {
    RecordedLog bad(topics, messages);
    FAIL() << "a message on a topic the log does not list was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/unlisted"), std::string::npos) << e.what();
  }
}

TEST(LogReplay, ALogGivenItsScansDecodedGivesEachToItsMessageAndReplaysAsItsFile) {
  // A simulated drive keeps its scans decoded and their bytes empty: after the messages are put in log
  // time order, each message must still have its own scan, and the replay must be the file's.
  testing::TempDir dir;
  const ndt::PointCloud scan = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const Stamp t0 = 1'700'000'000'000'000'000LL;
  const std::vector<io::TopicInfo> topics = {topicOf("/points", "sensor_msgs/msg/PointCloud2")};
  std::vector<io::BagMessage> messages;
  std::vector<RecordedLog::Scan> decoded;
  {
    io::BagWriter bag = io::BagWriter::create(dir / "scans");
    bag.addTopic(topics[0]);
    for (int i = 0; i < 3; ++i) {
      const io::PointCloud2 cloud = toMessage(scan, t0 + i * 100'000'000LL);
      io::BagMessage m;
      m.topic = "/points";
      m.log_time = t0 + (i == 1 ? 250'000'000LL : i * 100'000'000LL);  // the second written is logged last
      const io::Bytes data = io::encodePointCloud2(cloud);
      bag.write(m.topic, m.log_time, data.data(), data.size());
      messages.push_back(m);
      decoded.push_back({cloud.header.stamp, std::make_shared<const ndt::PointCloud>(pipeline::toPointCloud(cloud)), std::string()});
    }
    bag.close();
  }
  const RecordedLog from_file(dir / "scans");
  auto given = std::make_shared<const RecordedLog>(topics, messages, decoded);
  for (std::size_t i = 0; i < 3; ++i) {
    const RecordedLog::Scan a = given->scan(i, io::MessageKind::kPointCloud2), b = from_file.scan(i, io::MessageKind::kPointCloud2);
    EXPECT_EQ(a.stamp, b.stamp) << "message " << i;
    EXPECT_EQ(a.cloud->points, b.cloud->points) << "message " << i;
    EXPECT_TRUE(given->messages()[i].data.empty());
  }
  expectTheSameReplay(dir / "scans", given);

  decoded.pop_back();
  EXPECT_THROW(RecordedLog(topics, messages, decoded), Error);  // not one per message
}

TEST(LogReplay, ScanTopicWithoutAMapIsListedAndSkipped) {
  testing::TempDir dir;
  {
    io::BagWriter bag = io::BagWriter::create(dir / "scans");
    bag.addTopic(topicOf("/points", "sensor_msgs/msg/PointCloud2"));
    ndt::PointCloud cloud;
    cloud.points = {{1, 2, 3}};
    const io::Bytes b = io::encodePointCloud2(toMessage(cloud, 1'000'000'000));
    bag.write("/points", 1'000'000'000, b.data(), b.size());
    bag.close();
  }
  // Nothing else in the log: there is nothing to fuse, and the error lists what the log holds and why.
  try {
    replayLog(dir / "scans", ReplayOptions());
    ADD_FAILURE() << "a log with nothing to fuse was replayed";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("nothing to fuse"), std::string::npos) << what;
    EXPECT_NE(what.find("/points (sensor_msgs/msg/PointCloud2), 1 messages: not used"), std::string::npos) << what;
    EXPECT_NE(what.find("--map"), std::string::npos) << what;
  }
}

TEST(LogReplay, ALogWhosePosesCannotStartTheFilterIsAnErrorListingItsTopics) {
  testing::TempDir dir;
  {
    io::BagWriter bag = io::BagWriter::create(dir / "zero");
    bag.addTopic(topicOf("/ndt_pose", "geometry_msgs/msg/PoseWithCovarianceStamped"));
    bag.addTopic(topicOf("/chatter", "std_msgs/msg/String"));
    io::StampedPose p;
    p.header = {0, "map"};
    p.measurement.covariance = Matrix6d::Identity() * std::nan("");  // every pose unusable
    const io::Bytes b = io::encodePoseWithCovarianceStamped(p);
    for (int i = 0; i < 3; ++i) bag.write("/ndt_pose", 0, b.data(), b.size());
    const std::uint8_t text[] = {0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0, 0};
    bag.write("/chatter", 0, text, sizeof text);
    bag.close();
  }
  try {
    replayLog(dir / "zero", ReplayOptions());
    ADD_FAILURE() << "a log that fused nothing was reported as fused";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("nothing fused"), std::string::npos) << what;
    EXPECT_NE(what.find("/ndt_pose (geometry_msgs/msg/PoseWithCovarianceStamped), 3 messages: role pose"), std::string::npos) << what;
    EXPECT_NE(what.find("/chatter (std_msgs/msg/String), 1 messages: not used"), std::string::npos) << what;
  }
}

TEST(LogReplay, TheLogsDurationRunsFromItsEarliestToItsLatestTimeWhateverTheFileOrder) {
  testing::TempDir dir;
  const std::string path = dir / "shuffled.mcap";
  {
    // MCAP keeps the order of writing: the latest message first, the earliest last.
    io::McapWriter bag = io::McapWriter::create(path);
    bag.addTopic(topicOf("/ndt_pose", "geometry_msgs/msg/PoseWithCovarianceStamped"));
    const Stamp t0 = 1'700'000'000'000'000'000LL;
    for (const int k : {4, 1, 2, 3, 0}) {
      io::StampedPose p;
      p.header = {t0 + k * 100'000'000LL, "map"};
      p.measurement.pose.position = {0.5 * k, 0.0, 0.0};
      p.measurement.covariance = Matrix6d::Identity() * 0.01;
      const io::Bytes b = io::encodePoseWithCovarianceStamped(p);
      bag.write("/ndt_pose", t0 + k * 100'000'000LL, t0 + k * 100'000'000LL, b.data(), b.size());
    }
    bag.close();
  }
  const ReplayResult r = replayLog(path, ReplayOptions());
  EXPECT_NEAR(r.log_duration, 0.4, 1e-9);
}

}  // namespace
}  // namespace coloc::replay

#include "coloc/replay/log_smoother.hpp"

namespace coloc::replay {
namespace {

// The configuration file's smoother section and the library's SmootherOptions start from the same
// values: a user of either gets the same smoother.
TEST(SmootherConfiguration, AFiltersZeroProcessNoiseIsTakenAtTheSmoothersLeast) {
  // A heading that is its yaw rate's integral (fusion.proc_stddev_yaw_c: 0) is the filter's to take;
  // the smoother weighs the motion by its inverse and takes its least instead.
  pipeline::Config config;
  config.fusion.proc_stddev_yaw_c = 0.0;
  config.fusion.proc_stddev_wz_c = 0.0;
  const smoother::SmootherOptions o = smootherOptionsFor(config);
  EXPECT_EQ(o.proc_stddev_yaw_c, smoother::SmootherOptions::kLeastProcessNoise);
  EXPECT_EQ(o.proc_stddev_wz_c, smoother::SmootherOptions::kLeastProcessNoise);
  EXPECT_EQ(o.proc_stddev_vx_c, config.fusion.proc_stddev_vx_c) << "a figure above the least as the filter's";
}

TEST(SmootherConfiguration, TheFilesDefaultsAreTheLibrarysDefaults) {
  const smoother::SmootherOptions library;
  const pipeline::Config defaults;
  const smoother::SmootherOptions file = smootherOptionsFor(defaults);
  EXPECT_EQ(file.rate, library.rate);
  EXPECT_EQ(file.proc_stddev_yaw_c, library.proc_stddev_yaw_c);
  EXPECT_EQ(file.proc_stddev_vx_c, library.proc_stddev_vx_c);
  EXPECT_EQ(file.proc_stddev_wz_c, library.proc_stddev_wz_c);
  EXPECT_EQ(file.proc_stddev_position_c, library.proc_stddev_position_c);
  EXPECT_EQ(file.proc_stddev_yaw_bias_c, library.proc_stddev_yaw_bias_c);
  EXPECT_EQ(file.initial_yaw_bias_variance, library.initial_yaw_bias_variance);
  EXPECT_EQ(file.gate_alpha, library.gate_alpha);
  EXPECT_EQ(file.robust, library.robust);
  EXPECT_EQ(file.estimate_noise, library.estimate_noise);
  EXPECT_EQ(file.calibrate_odometry, library.calibrate_odometry);
  EXPECT_EQ(file.odometry_scale_sd, library.odometry_scale_sd);
  EXPECT_EQ(file.odometry_yaw_rate_bias_sd, library.odometry_yaw_rate_bias_sd);
  EXPECT_EQ(file.pose_bias, library.pose_bias);
  EXPECT_EQ(file.pose_bias_time, library.pose_bias_time);
  // Calibrating RSUs turns the pose bias on (pose_bias: when_calibrating).
  EXPECT_TRUE(smootherOptionsFor(defaults, true).pose_bias);
}

}  // namespace
}  // namespace coloc::replay
