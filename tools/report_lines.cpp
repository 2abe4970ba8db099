#include "report_lines.hpp"

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

}  // namespace coloc::tools
