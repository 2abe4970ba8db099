#include "report_lines.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace coloc::tools {

std::string fixLine(const std::string& rsu_id, const pipeline::PipelineReport& report) {
  std::ostringstream out;
  const rsu_client::FixCounters& c = report.fixes.at(rsu_id);
  out << "RSU " << rsu_id << ": " << c.received << " fixes received; refused by the checks:";
  bool any = false;
  for (const auto& [reason, count] : rsu_client::refusals(c))
    if (count) out << " " << reason << " " << count, any = true;
  if (!any) out << " none";
  out << "; passed " << c.passed_checks;
  const auto f = report.filter_of_fixes.find(rsu_id);
  if (f != report.filter_of_fixes.end()) {
    const fusion::SourceCounters& k = f->second;
    out << "; the filter applied " << k.applied << ", gated " << k.gated << ", not initialised " << k.not_initialized;
    if (k.too_old) out << ", too old " << k.too_old;
    if (k.from_future + k.invalid + k.numerical) out << ", refused otherwise " << k.from_future + k.invalid + k.numerical;
    if (k.pending) out << ", waiting " << k.pending;
  }
  return out.str();
}

std::string localizationLine(const pipeline::PipelineReport& r) {
  std::ostringstream out;
  out << fusion::toString(r.state);
  if (!r.state_reason.empty()) out << " (" << r.state_reason << ")";
  out << "; started " << r.starts << (r.starts == 1 ? " time" : " times");
  if (!r.started_how.empty()) out << ", last from " << r.started_how;
  out << "; " << r.recoveries << (r.recoveries == 1 ? " recovery" : " recoveries") << ", " << r.losses << " times lost, " << r.degradations
      << " degraded; " << r.clock_resets << " clock resets";
  return out.str();
}

namespace {

template <typename... Args>
void line(std::string& out, const char* format, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, args...);
  out += buffer;
}

}  // namespace

std::string learnedLines(const pipeline::PipelineReport& r) {
  std::string out;
  line(out, "  NDT's travel against the odometry's: %llu poses disagreed beyond the tolerance (covariance widened; largest by %.3f m), "
            "%llu had none to compare yet\n",
       (unsigned long long)r.ndt_travel_disagreements, r.ndt_travel_max_excess, (unsigned long long)r.ndt_travel_unverified);
  if (r.ndt_turn_disagreements > 0)
    line(out, "  NDT's turn against the yaw rate's: %llu poses disagreed beyond the tolerance (yaw variance widened by it; largest %.4f rad)\n",
         (unsigned long long)r.ndt_turn_disagreements, r.ndt_turn_max_disagreement);
  if (r.ndt_fix_disagreements > 0)
    line(out, "  NDT's position against the roadside's fixes: %llu poses disagreed beyond the tolerance (covariance widened; largest by %.3f m)\n",
         (unsigned long long)r.ndt_fix_disagreements, r.ndt_fix_max_excess);
  if (r.ndt_quality_raised > 0)
    line(out, "  NDT's error by place (ndt.quality_map): %llu poses' covariance raised to their place's figure\n", (unsigned long long)r.ndt_quality_raised);
  if (r.ndt_quality_lowered > 0)
    line(out, "  NDT's error by place (ndt.quality_map): %llu poses' covariance taken down to what NDT was there\n", (unsigned long long)r.ndt_quality_lowered);
  line(out, "  odometry speed scale learned from NDT: %.4f over %.0f m (twists corrected by it)\n", r.speed_scale, r.speed_scale_distance);
  line(out, "  odometry yaw-rate bias learned from NDT: %.5f rad/s over %.0f s (twists corrected by it)\n", r.yaw_rate_bias, r.yaw_rate_bias_time);
  line(out, "  LiDAR mounting yaw learned from NDT: %.3f deg over %.0f m (NDT's poses corrected by it)\n", r.mount_yaw * 180.0 / M_PI, r.mount_yaw_distance);
  if (r.filter_odometry_modelled)
    line(out, "  the filter's odometry states: speed reading high by %+.4f (sd %.4f), gyro bias %+.5f rad/s (sd %.5f)\n", r.filter_odometry_scale_error,
         r.filter_odometry_scale_sd, r.filter_yaw_rate_bias, r.filter_yaw_rate_bias_sd);
  return out;
}

}  // namespace coloc::tools
