#include "coloc/pipeline/report_json.hpp"

#include <nlohmann/json.hpp>

namespace coloc::pipeline {

std::string sourcesJson(const std::vector<fusion::SourceReport>& sources) {
  auto list = nlohmann::ordered_json::array();
  for (const auto& s : sources) {
    const fusion::SourceCounters& c = s.counters;
    const nlohmann::ordered_json counters = {
        {"received", c.received},   {"applied", c.applied},         {"gated", c.gated},
        {"too_old", c.too_old},     {"from_future", c.from_future}, {"invalid", c.invalid},
        {"not_initialized", c.not_initialized}, {"numerical", c.numerical}, {"pending", c.pending},
        {"smoothing_shortened", c.smoothing_shortened}, {"gate_recovered", c.gate_recovered}};
    const auto band = fusion::nisBand(c.nis_dof);
    nlohmann::ordered_json nis = {{"samples", c.nis_samples},
                                  {"dof", c.nis_dof},
                                  {"mean_per_dof", c.nis_dof ? c.nis_sum / static_cast<double>(c.nis_dof) : 0.0},
                                  {"band_95", {band.first, band.second}},
                                  {"above_97_5", c.nis_above},
                                  {"below_2_5", c.nis_below}};
    // Each component measured: its mean e_i^2 / S_ii and that mean's 95 % band.
    nlohmann::ordered_json parts = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < c.nis_component_sum.size(); ++k) {
      const std::uint64_t n = c.nis_component_samples[k];
      if (n == 0) continue;
      const auto part_band = fusion::nisBand(n);
      parts[fusion::toString(static_cast<fusion::NisComponent>(k))] = {
          {"samples", n},
          {"mean", c.nis_component_sum[k] / static_cast<double>(n)},
          {"band_95", {part_band.first, part_band.second}},
          {"prediction_share", c.nis_prediction_share_sum[k] / static_cast<double>(n)}};
    }
    nis["per_component"] = parts;
    list.push_back({{"name", s.name}, {"kind", s.kind == fusion::SourceKind::kPose ? "pose" : "twist"}, {"counters", counters}, {"nis", nis}});
  }
  return list.dump();
}

std::string ndtJson(const ndt::NdtPoseSourceCounters& n, const ndt::DynamicMapStats& map, std::uint64_t scans_without_guess) {
  const nlohmann::ordered_json j = {{"scans", n.scans},
                                    {"poses", n.poses},
                                    {"scans_without_guess", scans_without_guess},
                                    {"no_map", n.no_map},
                                    {"bad_prediction", n.bad_prediction},
                                    {"empty_scan", n.empty_scan},
                                    {"max_iterations", n.max_iterations},
                                    {"oscillation", n.oscillation},
                                    {"low_score", n.low_score},
                                    {"map_builds", map.builds},
                                    {"tiles_in_target", map.tiles_in_target}};
  return j.dump();
}

std::string fixesJson(const std::map<std::string, rsu_client::FixCounters>& fixes, const std::map<std::string, fusion::SourceCounters>& filter) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& [id, c] : fixes) {
    nlohmann::ordered_json o = {{"received", c.received}, {"passed_checks", c.passed_checks}};
    nlohmann::ordered_json refused = nlohmann::ordered_json::object();
    for (const auto& [reason, count] : rsu_client::refusals(c)) refused[reason] = count;
    o["refused_by_checks"] = std::move(refused);
    const auto f = filter.find(id);
    const fusion::SourceCounters none;
    const fusion::SourceCounters& fc = f == filter.end() ? none : f->second;
    o["applied"] = fc.applied;
    o["gated"] = fc.gated;
    o["not_initialized"] = fc.not_initialized;
    o["too_old"] = fc.too_old;
    o["other_filter_refusals"] = fc.from_future + fc.invalid + fc.numerical;
    o["pending"] = fc.pending;
    j[id] = std::move(o);
  }
  return j.dump();
}

std::string localizationJson(const PipelineReport& r) {
  const nlohmann::ordered_json j = {{"state", fusion::toString(r.state)},
                                    {"reason", r.state_reason},
                                    {"started_how", r.started_how},
                                    {"starts", r.starts},
                                    {"recoveries", r.recoveries},
                                    {"recovery_reasons", r.recovery_reasons},
                                    {"degradations", r.degradations},
                                    {"losses", r.losses},
                                    {"clock_resets", r.clock_resets},
                                    {"inputs_dropped_by_reset", r.inputs_dropped_by_reset},
                                    {"events", r.first_events}};
  return j.dump();
}

std::string learnedJson(const PipelineReport& r) {
  nlohmann::ordered_json j;
  j["ndt_travel_check"] = {{"disagreements", r.ndt_travel_disagreements}, {"max_excess_m", r.ndt_travel_max_excess},
                           {"unverified", r.ndt_travel_unverified}, {"turn_disagreements", r.ndt_turn_disagreements},
                           {"turn_max_disagreement_rad", r.ndt_turn_max_disagreement}};
  j["ndt_fix_agreement"] = {{"disagreements", r.ndt_fix_disagreements}, {"max_excess_m", r.ndt_fix_max_excess}};
  j["ndt_quality_map"] = {{"raised", r.ndt_quality_raised}, {"lowered", r.ndt_quality_lowered}};
  j["odometry_speed_scale"] = {{"scale", r.speed_scale}, {"compared_m", r.speed_scale_distance}};
  j["odometry_yaw_rate_bias"] = {{"bias_rad_s", r.yaw_rate_bias}, {"compared_s", r.yaw_rate_bias_time}};
  j["lidar_mount_yaw"] = {{"yaw_rad", r.mount_yaw}, {"compared_m", r.mount_yaw_distance}};
  if (r.filter_odometry_modelled)
    j["filter_odometry_states"] = {{"speed_scale_error", r.filter_odometry_scale_error},
                                   {"speed_scale_error_sd", r.filter_odometry_scale_sd},
                                   {"yaw_rate_bias_rad_s", r.filter_yaw_rate_bias},
                                   {"yaw_rate_bias_sd_rad_s", r.filter_yaw_rate_bias_sd}};
  return j.dump();
}

}  // namespace coloc::pipeline
