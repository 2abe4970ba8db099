// The live node's /diagnostics say what Autoware's monitors look for, at the levels ekf_localizer uses,
// and what coloc knows beyond: the localization state with its reason, and losses in transport.
#include "diagnostics.hpp"

#include <gtest/gtest.h>

namespace coloc::live {
namespace {

constexpr Stamp kNow = 1'700'000'010'000'000'000LL;

const io::DiagnosticStatus& statusNamed(const io::DiagnosticArray& a, const std::string& name) {
  for (const auto& s : a.status)
    if (s.name == name) return s;
  throw std::runtime_error("no status " + name);
}

std::string valueOf(const io::DiagnosticStatus& s, const std::string& key) {
  for (const auto& [k, v] : s.values)
    if (k == key) return v;
  return "(none)";
}

LiveStatus localized() {
  LiveStatus s;
  s.estimate = fusion::Estimate{};
  s.estimate->pose_covariance = Matrix6d::Identity() * 0.0009;
  s.report.state = fusion::LocalizationState::kLocalized;
  return s;
}

TEST(LiveDiagnostics, ANodeNotActivatedWarnsAndOneWithoutAnInitialPoseIsAnError) {
  DiagnosticsMemory memory;
  LiveStatus waiting;  // no estimate yet
  const io::DiagnosticArray off = diagnosticsOf(waiting, false, kNow, 0.02, memory);
  const auto& ekf = statusNamed(off, "localization: ekf_localizer");
  EXPECT_EQ(ekf.level, io::DiagnosticStatus::kWarn);
  EXPECT_EQ(ekf.message, "[WARN]process is not activated");
  EXPECT_EQ(valueOf(ekf, "is_activated"), "False");
  const io::DiagnosticArray on = diagnosticsOf(waiting, true, kNow, 0.02, memory);
  EXPECT_EQ(statusNamed(on, "localization: ekf_localizer").level, io::DiagnosticStatus::kError);
  EXPECT_EQ(valueOf(statusNamed(on, "localization: ekf_localizer"), "is_set_initialpose"), "False");
  EXPECT_EQ(statusNamed(diagnosticsOf(localized(), true, kNow, 0.02, memory), "localization: ekf_localizer").level, io::DiagnosticStatus::kOk);
}

TEST(LiveDiagnostics, ALostFilterIsAnErrorWithItsReason) {
  DiagnosticsMemory memory;
  LiveStatus s = localized();
  s.report.state = fusion::LocalizationState::kLost;
  s.report.state_reason = "RSU fixes disagree by 4.8 m";
  const io::DiagnosticArray a = diagnosticsOf(s, true, kNow, 0.02, memory);
  const auto& ekf = statusNamed(a, "localization: ekf_localizer");
  EXPECT_EQ(ekf.level, io::DiagnosticStatus::kError);
  EXPECT_NE(ekf.message.find("RSU fixes disagree by 4.8 m"), std::string::npos);
  EXPECT_EQ(valueOf(ekf, "localization_state"), "lost");
}

TEST(LiveDiagnostics, NewTransportLossesAndSilentInputsWarnOnce) {
  DiagnosticsMemory memory;
  LiveStatus s = localized();
  TopicStatus scans;
  scans.topic = "/points";
  scans.received = 100;
  scans.last_arrival = kNow - 50'000'000;
  s.topics.push_back(scans);
  EXPECT_EQ(statusNamed(diagnosticsOf(s, true, kNow, 0.02, memory), "coloc: inputs").level, io::DiagnosticStatus::kOk);
  s.topics[0].sequence_gaps = 3;
  const io::DiagnosticArray with_loss = diagnosticsOf(s, true, kNow, 0.02, memory);
  const auto& lost = statusNamed(with_loss, "coloc: inputs");
  EXPECT_EQ(lost.level, io::DiagnosticStatus::kWarn);
  EXPECT_NE(lost.message.find("3 samples lost"), std::string::npos);
  EXPECT_EQ(statusNamed(diagnosticsOf(s, true, kNow, 0.02, memory), "coloc: inputs").level, io::DiagnosticStatus::kOk);  // no new loss
  s.topics[0].last_arrival = kNow - 5'000'000'000LL;
  const io::DiagnosticArray with_silence = diagnosticsOf(s, true, kNow, 0.02, memory);
  const auto& silent = statusNamed(with_silence, "coloc: inputs");
  EXPECT_EQ(silent.level, io::DiagnosticStatus::kWarn);
  EXPECT_NE(silent.message.find("/points silent"), std::string::npos);
}

}  // namespace
}  // namespace coloc::live
