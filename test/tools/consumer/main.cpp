// A vehicle stack's first use of coloc: link coloc::fusion only (no PCL, DDS or file formats).
#include <coloc/fusion/localizer.hpp>

#include <cstdio>

int main() {
  coloc::fusion::Localizer localizer;
  const auto ndt = localizer.addPoseSource("ndt");
  coloc::PoseMeasurement pose;
  pose.stamp = 1'000'000'000;
  pose.pose.position = {2.0, 1.0, 0.0};
  pose.covariance.diagonal() << 0.0225, 0.0225, coloc::kInfinity, coloc::kInfinity, coloc::kInfinity, 0.000625;
  if (!localizer.feedPose(ndt, pose).applied()) return 1;
  localizer.advanceTo(pose.stamp + 100'000'000);
  std::printf("consumer fused x=%.3f\n", localizer.estimate()->pose.position.x());
  return 0;
}
