#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>
#include <stdexcept>
#include <thread>

#include "coloc/ndt/alignment_memo.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/target_cache.hpp"
#include "real_data.hpp"

namespace coloc::ndt {
namespace {

// The real HDL-32E pair: the target scan is the map, the source scan is what the vehicle sees.
struct RealPair {
  std::string map = testing::realData("hdl32e_pair/target.pcd");
  std::shared_ptr<const PointCloud> scan = std::make_shared<const PointCloud>(loadPcd(testing::realData("hdl32e_pair/source.pcd")));
  NdtPoseSourceConfig config;
  Pose predicted;
  std::shared_ptr<TargetCache> targets = std::make_shared<TargetCache>();  // the sources share targets, as replays do
  RealPair() {
    config.preprocess.voxel_size = 1.0;
    config.ndt.threads = 1;
    config.map.background = false;
    const Eigen::Matrix4d gt1 = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
    predicted.position = gt1.topRightCorner<3, 1>() + Eigen::Vector3d(0.3, -0.2, 0.0);
    predicted.orientation = Eigen::Quaterniond(gt1.topLeftCorner<3, 3>()).normalized();
  }
  NdtPoseSource source(std::shared_ptr<AlignmentMemo> memo, const NdtPoseSourceConfig* other = nullptr, bool own_target = false) const {
    return NdtPoseSource(TileMap::open(map), other ? *other : config, own_target ? nullptr : targets, std::move(memo));
  }
};

void expectSameOutcome(const ScanOutcome& a, const ScanOutcome& b) {
  EXPECT_EQ(a.produced, b.produced);
  EXPECT_EQ(a.alignment.transform, b.alignment.transform);
  EXPECT_EQ(a.alignment.covariance, b.alignment.covariance);
  EXPECT_EQ(a.alignment.iterations, b.alignment.iterations);
  EXPECT_EQ(a.alignment.nvtl, b.alignment.nvtl);
  EXPECT_EQ(a.pose.pose.position, b.pose.pose.position);
  EXPECT_EQ(a.points_used, b.points_used);
  EXPECT_EQ(a.detail, b.detail);
}

TEST(AlignmentMemo, SourcesAskingTheSameQuestionShareOneComputationAndGetItsBytes) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource first = pair.source(memo), second = pair.source(memo), alone = pair.source(nullptr);
  const ScanOutcome computed = first.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  const ScanOutcome shared = second.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  const ScanOutcome own = alone.process(*pair.scan, 100, pair.predicted, 5.0, 0.1);
  ASSERT_TRUE(own.produced) << own.detail;
  expectSameOutcome(computed, own);
  expectSameOutcome(shared, own);
  EXPECT_EQ(memo->stats().asked, 2u);
  EXPECT_EQ(memo->stats().computed, 1u);
  EXPECT_EQ(first.counters().shared, 0u);
  EXPECT_EQ(second.counters().shared, 1u);
  // The shared outcome counts as the source's own in every other counter.
  EXPECT_EQ(second.counters().scans, alone.counters().scans);
  EXPECT_EQ(second.counters().poses, alone.counters().poses);
}

TEST(AlignmentMemo, AnyDifferenceInTheQuestionIsComputedAfresh) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource source = pair.source(memo);
  source.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  Pose nudged = pair.predicted;
  nudged.position.x() += 0.005;  // a step of the guess's rounding
  source.process(pair.scan, 100, nudged, 5.0, 0.1);
  source.process(pair.scan, 100, pair.predicted, 5.001, 0.1);  // the twist deskews (to the millimetre per second)
  source.process(pair.scan, 101, pair.predicted, 5.0, 0.1);                       // the stamp is in the pose
  const auto copy = std::make_shared<const PointCloud>(*pair.scan);  // equal, but another scan
  source.process(copy, 100, pair.predicted, 5.0, 0.1);
  EXPECT_EQ(memo->stats().computed, 5u);
  NdtPoseSourceConfig other = pair.config;
  other.ndt.nvtl_threshold = 2.0;  // the same target, another configuration
  NdtPoseSource differently = pair.source(memo, &other);
  differently.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  EXPECT_EQ(memo->stats().computed, 6u);
  EXPECT_EQ(differently.counters().shared, 0u);
  NdtPoseSource apart = pair.source(memo, nullptr, true);  // an equal target, but its own
  apart.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  EXPECT_EQ(memo->stats().computed, 7u);
}

// A twist within the deskew's rounding (1 mm/s, 1e-5 rad/s) is the same twist: the same question.
// Sources whose predictions differ match afresh, but the scan is preprocessed once for them all, and
// each gets the bytes a source alone computes.
TEST(AlignmentMemo, TwistsThatRoundAlikeShareTheScansPreprocessingWhateverThePrediction) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource first = pair.source(memo), second = pair.source(memo), alone = pair.source(nullptr);
  first.process(pair.scan, 100, pair.predicted, 5.0, 0.1);
  const ScanOutcome same = second.process(pair.scan, 100, pair.predicted, 5.0004, 0.100004);
  EXPECT_EQ(memo->stats().computed, 1u);
  EXPECT_EQ(second.counters().shared, 1u);
  expectSameOutcome(same, alone.process(*pair.scan, 100, pair.predicted, 5.0, 0.1));
  Pose nudged = pair.predicted;
  nudged.position.x() += 0.05;
  const ScanOutcome elsewhere = second.process(pair.scan, 100, nudged, 4.9996, 0.1);
  EXPECT_EQ(memo->stats().computed, 2u);
  expectSameOutcome(elsewhere, alone.process(*pair.scan, 100, nudged, 5.0, 0.1));
  EXPECT_EQ(memo->stats().preprocessings_asked, 2u);
  EXPECT_EQ(memo->stats().preprocessings_computed, 1u);
  // A twist a step away deskews differently.
  second.process(pair.scan, 100, nudged, 5.002, 0.1);
  EXPECT_EQ(memo->stats().preprocessings_computed, 2u);
  EXPECT_EQ(memo->stats().computed, 3u);
}

// NDT starts from the prediction taken to 5 mm and 0.25 mrad: predictions within half a step of that
// rounding are one question, with the bytes a source alone computes from either; a step away, the
// match is computed afresh and lands where the first did (within a micrometre and a microradian; on
// the real pair 0.04 um and 0.01 urad), the rounding being below NDT's own stop.
TEST(AlignmentMemo, PredictionsWithinTheGuesssRoundingAreOneQuestionAndAStepAwayMatchesAlike) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource first = pair.source(memo), second = pair.source(memo), alone = pair.source(nullptr);
  // A prediction on the rounding's grid, and one nudged by less than half a step in every coordinate.
  Pose grid;
  for (int i = 0; i < 3; ++i) grid.position[i] = std::round(pair.predicted.position[i] / 0.005) * 0.005;
  const Eigen::Vector3d rpy = rollPitchYaw(pair.predicted.orientation);
  const auto onGrid = [](double a) { return std::round(a / 2.5e-4) * 2.5e-4; };
  grid.orientation = quaternionFromRollPitchYaw(onGrid(rpy.x()), onGrid(rpy.y()), onGrid(rpy.z()));
  Pose nudged = grid;
  nudged.position += Eigen::Vector3d(0.002, -0.002, 0.001);
  nudged.orientation = quaternionFromRollPitchYaw(onGrid(rpy.x()) + 1e-4, onGrid(rpy.y()) - 1e-4, onGrid(rpy.z()) + 1.2e-4);
  const ScanOutcome computed = first.process(pair.scan, 100, grid, 5.0, 0.1);
  const ScanOutcome shared = second.process(pair.scan, 100, nudged, 5.0, 0.1);
  ASSERT_TRUE(computed.produced) << computed.detail;
  EXPECT_EQ(memo->stats().computed, 1u);
  expectSameOutcome(shared, computed);
  expectSameOutcome(alone.process(*pair.scan, 100, nudged, 5.0, 0.1), computed);
  // A step away in x and in yaw: matched afresh, to the same place.
  Pose step = grid;
  step.position.x() += 0.005;
  step.orientation = quaternionFromRollPitchYaw(onGrid(rpy.x()), onGrid(rpy.y()), onGrid(rpy.z()) + 2.5e-4);
  const ScanOutcome again = second.process(pair.scan, 100, step, 5.0, 0.1);
  EXPECT_EQ(memo->stats().computed, 2u);
  ASSERT_TRUE(again.produced) << again.detail;
  EXPECT_NE(again.alignment.transform, computed.alignment.transform);
  EXPECT_LT((again.pose.pose.position - computed.pose.pose.position).norm(), 1e-6);
  EXPECT_LT(again.pose.pose.orientation.angularDistance(computed.pose.pose.orientation), 1e-6);
}

// A prediction that is no pose (NaN or infinite position, a zero or NaN quaternion) is not rounded
// into one: each gives no pose and says why, shared or not, and the source matches the next scan as
// if they had not come.
TEST(AlignmentMemo, APredictionThatIsNoPoseGivesNoPoseAndLeavesTheSourceAsItWas) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource shared = pair.source(memo), alone = pair.source(nullptr);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<Pose> bad(4, pair.predicted);
  bad[0].position.x() = nan;
  bad[1].position.y() = inf;
  bad[2].orientation = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  bad[3].orientation = Eigen::Quaterniond(nan, 0.0, 0.0, 1.0);
  for (std::size_t i = 0; i < bad.size(); ++i) {
    for (NdtPoseSource* source : {&shared, &alone}) {
      const ScanOutcome out = source == &shared ? source->process(pair.scan, 100, bad[i], 5.0, 0.1) : source->process(*pair.scan, 100, bad[i], 5.0, 0.1);
      EXPECT_FALSE(out.produced) << "prediction " << i;
      EXPECT_FALSE(out.detail.empty()) << "prediction " << i;
    }
  }
  EXPECT_EQ(shared.counters().bad_prediction, 4u);
  EXPECT_EQ(alone.counters().bad_prediction, 4u);
  EXPECT_EQ(memo->stats().asked, 0u) << "nothing asked of the memo for them";
  NdtPoseSource fresh = pair.source(nullptr);
  expectSameOutcome(alone.process(*pair.scan, 100, pair.predicted, 5.0, 0.1), fresh.process(*pair.scan, 100, pair.predicted, 5.0, 0.1));
  EXPECT_TRUE(shared.process(pair.scan, 100, pair.predicted, 5.0, 0.1).produced);
}

TEST(AlignmentMemo, AQuestionAskedTwiceAtOnceIsComputedOnce) {
  const RealPair pair;
  auto memo = std::make_shared<AlignmentMemo>();
  NdtPoseSource a = pair.source(memo), b = pair.source(memo);
  ScanOutcome from_a, from_b;
  std::thread ta([&] { from_a = a.process(pair.scan, 100, pair.predicted, 5.0, 0.1); });
  std::thread tb([&] { from_b = b.process(pair.scan, 100, pair.predicted, 5.0, 0.1); });
  ta.join();
  tb.join();
  expectSameOutcome(from_a, from_b);
  EXPECT_EQ(memo->stats().computed, 1u);
  EXPECT_EQ(a.counters().shared + b.counters().shared, 1u);
}

TEST(AlignmentMemo, AFailedComputationReachesItsCallerAndIsNotKept) {
  const RealPair pair;
  AlignmentMemo memo;
  const std::string config = configFingerprint(pair.config);
  const AlignmentMemo::Question q{pair.scan, 100, nullptr, pair.predicted, 5.0, 0.1};
  EXPECT_THROW(memo.answer(config, q, []() -> ScanOutcome { throw std::runtime_error("out of memory"); }), std::runtime_error);
  ScanOutcome made;
  made.detail = "computed again";
  EXPECT_EQ(memo.answer(config, q, [&] { return made; }).detail, "computed again");
  EXPECT_EQ(memo.stats().computed, 2u);
}

TEST(AlignmentMemo, ConfigurationsDifferingInAnySettingHaveDifferentFingerprints) {
  const NdtPoseSourceConfig base;
  std::vector<NdtPoseSourceConfig> changed(10, base);
  changed[0].ndt.resolution = 1.0;
  changed[1].ndt.threads = 3;
  changed[2].ndt.fixed_covariance[5] = 1e-3;
  changed[3].ndt.covariance = CovarianceMode::kLaplace;
  changed[4].preprocess.deskew = false;
  changed[5].preprocess.max_points = 10;
  changed[6].preprocess.seed = 2;
  changed[7].map.update_distance = 5.0;
  changed[8].lidar_pose[5] = 0.01;
  changed[9].ndt.max_oscillations = 3;
  for (std::size_t i = 0; i < changed.size(); ++i) EXPECT_NE(configFingerprint(changed[i]), configFingerprint(base)) << "change " << i;
  EXPECT_EQ(configFingerprint(NdtPoseSourceConfig{}), configFingerprint(base));
}

}  // namespace
}  // namespace coloc::ndt
