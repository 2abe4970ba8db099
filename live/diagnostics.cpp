#include "diagnostics.hpp"

#include <algorithm>
#include <string>

namespace coloc::live {

namespace {

using Level = io::DiagnosticStatus::Level;

std::string flag(bool b) { return b ? "True" : "False"; }  // as Autoware's diagnostics write booleans

void raise(io::DiagnosticStatus& s, Level level, const std::string& message) {
  if (level > s.level) s.level = level;
  s.message = s.message == "OK" || s.message.empty() ? message : s.message + "; " + message;
}

}  // namespace

io::DiagnosticArray diagnosticsOf(const LiveStatus& status, bool activated, Stamp now, double tick, DiagnosticsMemory& memory) {
  const pipeline::PipelineReport& r = status.report;
  std::uint64_t ndt_applied = 0, twists_applied = 0;
  for (const auto& source : r.sources) {
    if (source.name == pipeline::kNdtSource) ndt_applied = source.counters.applied;
    if (source.kind == fusion::SourceKind::kTwist) twists_applied += source.counters.applied;
  }
  if (ndt_applied != memory.ndt_applied || memory.ndt_moved == 0) memory.ndt_applied = ndt_applied, memory.ndt_moved = now;
  if (twists_applied != memory.twists_applied || memory.twists_moved == 0) memory.twists_applied = twists_applied, memory.twists_moved = now;
  const auto ticksSince = [&](Stamp t) { return static_cast<long long>(std::max(0.0, toSeconds(now - t)) / tick); };
  const bool initialised = status.estimate.has_value();

  io::DiagnosticArray out;
  out.header.stamp = now;

  // Where ekf_localizer reports: activation, initial pose, no-update counts, and coloc's integrity.
  io::DiagnosticStatus ekf{Level::kOk, "localization: ekf_localizer", "OK", "coloc", {}};
  ekf.values.emplace_back("is_activated", flag(activated));
  if (!activated) raise(ekf, Level::kWarn, "[WARN]process is not activated");
  ekf.values.emplace_back("is_set_initialpose", flag(initialised));
  if (activated && !initialised) raise(ekf, Level::kError, "[ERROR]initial pose is not set");
  const long long pose_count = r.ndt_used ? ticksSince(memory.ndt_moved) : 0;
  ekf.values.emplace_back("pose_no_update_count", std::to_string(pose_count));
  ekf.values.emplace_back("twist_no_update_count", std::to_string(ticksSince(memory.twists_moved)));
  ekf.values.emplace_back("localization_state", fusion::toString(r.state));
  ekf.values.emplace_back("localization_state_reason", r.state_reason);
  ekf.values.emplace_back("started_how", r.started_how);
  ekf.values.emplace_back("recoveries", std::to_string(r.recoveries));
  ekf.values.emplace_back("clock_resets", std::to_string(r.clock_resets));
  if (status.estimate) {
    const auto& c = status.estimate->pose_covariance;
    ekf.values.emplace_back("position_sd_m", std::to_string(std::sqrt(std::max(0.0, c(0, 0) + c(1, 1)))));
  }
  if (activated && initialised) {
    if (r.state == fusion::LocalizationState::kDegraded) raise(ekf, Level::kWarn, "[WARN]degraded: " + r.state_reason);
    if (r.state == fusion::LocalizationState::kLost) raise(ekf, Level::kError, "[ERROR]lost: " + r.state_reason);
  }
  out.status.push_back(ekf);

  // Where ndt_scan_matcher reports its scan matching.
  if (r.ndt_used) {
    io::DiagnosticStatus ndt{Level::kOk, "ndt_scan_matcher: scan_matching_status", "OK", "coloc", {}};
    ndt.values.emplace_back("is_activated", flag(activated));
    ndt.values.emplace_back("scans", std::to_string(r.ndt.scans));
    ndt.values.emplace_back("poses", std::to_string(r.ndt.poses));
    ndt.values.emplace_back("skipping_publish_num", std::to_string(r.scans_superseded));
    ndt.values.emplace_back("low_score", std::to_string(r.ndt.low_score));
    ndt.values.emplace_back("execution_time", std::to_string(r.ndt.scans ? r.ndt.align_ms_total / static_cast<double>(r.ndt.scans) : 0.0));
    if (!activated) raise(ndt, Level::kWarn, "Node is not activated.");
    out.status.push_back(ndt);
  }

  // coloc's own: every input, what DDS saw lost, and silences beyond a second.
  io::DiagnosticStatus inputs{Level::kOk, "coloc: inputs", "OK", "coloc", {}};
  std::uint64_t lost = 0;
  for (const TopicStatus& t : status.topics) {
    const std::uint64_t l = t.sequence_gaps + t.rejected;
    lost += l;
    inputs.values.emplace_back(t.topic, std::to_string(t.received) + " received, " + std::to_string(l) + " lost, " +
                                            std::to_string(t.matched_writers) + " writers");
    if (t.last_arrival != 0 && now > t.last_arrival && toSeconds(now - t.last_arrival) > 1.0 && t.topic != "/clock")
      raise(inputs, Level::kWarn, t.topic + " silent for " + std::to_string(toSeconds(now - t.last_arrival)) + " s");
  }
  if (lost > memory.lost) raise(inputs, Level::kWarn, std::to_string(lost - memory.lost) + " samples lost in transport since the last report");
  memory.lost = lost;
  out.status.push_back(inputs);
  return out;
}

}  // namespace coloc::live
