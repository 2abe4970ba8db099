// summary.json and error.csv of a replay: everything in them follows from the log and the config, so
// that reruns give the same bytes; run times are reported apart (timing.json).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>

#include "coloc/core/error.hpp"
#include "coloc/replay/log_replay.hpp"
#include "coloc/pipeline/report_json.hpp"
#include "error_json.hpp"
#include "recovered_json.hpp"

namespace coloc::replay {

std::string ReplayResult::summaryJson(const std::string& log) const {
  nlohmann::ordered_json j;
  j["log"] = log;
  j["messages"] = messages_read;
  if (!recovered.empty()) j["recovered"] = recoveredJson(recovered);  // only then: a closed log's summary is as it always was
  j["log_duration_s"] = log_duration;
  j["clock"] = {{"mode", clock == ClockMode::kSeparate ? "separate" : "same"}};
  if (clock == ClockMode::kSeparate) {
    j["clock"]["rate"] = clock_fit.rate;
    j["clock"]["log_origin"] = formatSeconds(clock_fit.log_origin);
    j["clock"]["stamp_origin"] = formatSeconds(clock_fit.stamp_origin);
  }
  auto& topic_list = j["topics"] = nlohmann::ordered_json::array();
  for (const TopicUse& t : topics) {
    nlohmann::ordered_json o = {{"topic", t.topic}, {"type", t.type}, {"role", toString(t.role)}, {"messages", t.messages}};
    if (t.role == InputRole::kPose || t.role == InputRole::kTwist || t.role == InputRole::kRsuFix) o["source"] = t.source;
    if (t.role != InputRole::kIgnore) o["decode_errors"] = t.decode_errors;
    if (t.role != InputRole::kIgnore && t.role != InputRole::kStaticTransforms) {  // inputs the filter takes
      o["fallback_covariance"] = t.fallback_covariance;
      o["link_dropped"] = t.link_dropped;
      o["delay_median_s"] = t.delay_median;
      o["delay_max_s"] = t.delay_max;
    }
    if (!t.first_error.empty()) o["first_error"] = t.first_error;
    if (!t.note.empty()) o["note"] = t.note;
    topic_list.push_back(o);
  }
  j["sources"] = nlohmann::ordered_json::parse(pipeline::sourcesJson(sources));
  j["fused"] = {{"file", "fused.tum"}, {"poses", fused.size()}, {"first_stamp", formatSeconds(first_stamp)}, {"last_stamp", formatSeconds(last_stamp)}};
  j["position_error"] = errorJson(errors, "error.csv");
  if (!input_errors.empty()) {
    auto& inputs = j["input_error"] = nlohmann::ordered_json::object();
    for (const auto& [source, samples] : input_errors) {
      inputs[source] = errorJson(samples);
      const auto c = input_comparison.find(source);
      if (inputs[source].is_null() || c == input_comparison.end() || c->second.samples == 0) continue;
      const InputComparison& k = c->second;
      // The filter beside its input at the input's stamps, and the input's mean square per axis: what
      // a drive with a reference measures for the source's fixed covariance.
      inputs[source]["fused_at_stamps"] = {{"samples", k.samples}, {"input_mean_m", k.input_mean}, {"fused_mean_m", k.fused_mean},
                                           {"settled_mean_m", k.settled_mean}};
      inputs[source]["where_accurate"] = {{"stretch_m", k.stretch_length}, {"input_mean_below_m", k.accurate_below},
                                          {"samples", k.accurate_samples}, {"input_mean_m", k.accurate_input_mean},
                                          {"fused_mean_m", k.accurate_fused_mean}, {"settled_mean_m", k.accurate_settled_mean}};
      if (k.places_given)
        inputs[source]["where_accurate_on_reference"] = {{"file", input_reference}, {"cell_m", k.stretch_length}, {"input_mean_below_m", k.accurate_below},
                                                         {"samples", k.place_samples}, {"input_mean_m", k.place_input_mean},
                                                         {"fused_mean_m", k.place_fused_mean}, {"settled_mean_m", k.place_settled_mean}};
      inputs[source]["covariance_estimate"] = {{"xy_mean_square_m2", k.mean_square_xy}, {"yaw_variance_rad2", k.yaw_variance},
                                               {"yaw_mean_rad", k.yaw_mean}};
    }
    inputs["file"] = "input_error.csv";
  }
  if (ndt_used) {
    j["ndt"] = nlohmann::ordered_json::parse(pipeline::ndtJson(ndt, map, scans_without_guess));
    j.update(nlohmann::ordered_json::parse(pipeline::learnedJson(pipeline_report)));
    j["lidar_pose"] = {{"xyz_rpy", std::vector<double>(lidar_pose.data(), lidar_pose.data() + 6)}, {"from", lidar_pose_from}};
  }
  if (!fixes.empty()) j["rsu_fixes"] = nlohmann::ordered_json::parse(pipeline::fixesJson(fixes, pipeline_report.filter_of_fixes));
  j["localization"] = nlohmann::ordered_json::parse(pipeline::localizationJson(pipeline_report));
  j["rejections_first"] = rejections;
  return j.dump(2) + "\n";
}

void ReplayResult::writeErrorCsv(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  out << "stamp_s,estimate_x,estimate_y,truth_x,truth_y,error_m,along_m,across_m,heading_error_deg,sd_x_m,sd_y_m,state\n";
  // Each tick's reported deviations and state, by stamp. A stamp can carry two estimates (the tick's,
  // then a restart's at the same stamp): the k-th error sample at a stamp is the k-th estimate's.
  std::map<Stamp, std::vector<std::size_t>> tick;
  for (std::size_t i = 0; i < fused.size() && i < fused_sd.size() && i < fused_localization.size(); ++i) tick[fused[i].stamp].push_back(i);
  std::map<Stamp, std::size_t> used;
  char line[360];
  for (const ErrorSample& s : errors) {
    const auto t = tick.find(s.stamp);
    std::optional<std::size_t> i;
    if (t != tick.end()) i = t->second[std::min(used[s.stamp]++, t->second.size() - 1)];
    const Eigen::Vector2d sd = i ? fused_sd[*i] : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    const char* state = i ? fusion::toString(fused_localization[*i]) : "";
    std::snprintf(line, sizeof line, "%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%s\n", formatSeconds(s.stamp).c_str(), s.estimate.x(),
                  s.estimate.y(), s.truth.x(), s.truth.y(), s.error, s.along, s.across, s.heading_error * 180.0 / M_PI, sd.x(), sd.y(), state);
    out << line;
  }
}

std::map<std::pair<std::string, Stamp>, Eigen::Matrix2d> ReplayResult::claimedCovariances() const {
  std::map<std::pair<std::string, Stamp>, Eigen::Matrix2d> claimed;
  for (std::size_t i = 0; i < pose_inputs.size() && i < pose_input_covariances.size() && i < pose_input_sources.size(); ++i)
    claimed.emplace(std::make_pair(pose_input_sources[i], pose_inputs[i].stamp), pose_input_covariances[i]);
  return claimed;
}

void ReplayResult::writeInputErrorCsv(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  // Beside each input's error, the standard deviation it claimed along and across the road: where a
  // source said it did not know (NDT on a featureless stretch) and where it was wrong while sure. Then
  // the filter at the same stamp: its output as given out then, and its settled estimate once the input
  // was in, so that where and why the filter trails an input can be read stretch by stretch (the
  // summary's where_accurate gives only their means).
  out << "stamp_s,source,estimate_x,estimate_y,truth_x,truth_y,error_m,along_m,across_m,heading_error_deg,sd_along_m,sd_across_m,"
         "output_error_m,settled_error_m,settled_along_m,settled_across_m\n";
  const auto claimed = claimedCovariances();
  const auto byStamp = [](const std::map<std::string, std::vector<ErrorSample>>& all, const std::string& source) {
    std::map<Stamp, const ErrorSample*> index;
    if (const auto it = all.find(source); it != all.end())
      for (const ErrorSample& s : it->second) index.emplace(s.stamp, &s);
    return index;
  };
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  char line[480];
  for (const auto& [source, samples] : input_errors) {
    const auto output = byStamp(fused_at_inputs, source), settled = byStamp(settled_at_inputs, source);
    for (const ErrorSample& s : samples) {
      const auto c = claimed.find({source, s.stamp});
      const Eigen::Vector2d sd = c == claimed.end() ? Eigen::Vector2d::Constant(kNone) : alongAcrossDeviation(c->second, s.truth_heading);
      const auto o = output.find(s.stamp);
      const auto k = settled.find(s.stamp);
      const ErrorSample* at = k == settled.end() ? nullptr : k->second;
      std::snprintf(line, sizeof line, "%s,%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", formatSeconds(s.stamp).c_str(),
                    source.c_str(), s.estimate.x(), s.estimate.y(), s.truth.x(), s.truth.y(), s.error, s.along, s.across,
                    s.heading_error * 180.0 / M_PI, sd[0], sd[1], o == output.end() ? kNone : o->second->error, at ? at->error : kNone,
                    at ? at->along : kNone, at ? at->across : kNone);
      out << line;
    }
  }
}

}  // namespace coloc::replay
