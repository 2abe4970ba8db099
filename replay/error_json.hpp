#pragma once
// One shape for every error statistic a summary.json gives (coloc fuse, coloc smooth).
#include <nlohmann/json.hpp>
#include <vector>

#include "coloc/replay/evaluation.hpp"

namespace coloc::replay {

/// {samples, mean_m, rmse_m, max_m, along_mean_m, across_mean_m[, file]}; null without samples.
inline nlohmann::ordered_json errorJson(const std::vector<ErrorSample>& errors, const char* file = nullptr) {
  if (errors.empty()) return nullptr;
  const ErrorStats s = errorStats(errors);
  nlohmann::ordered_json j = {{"samples", errors.size()}, {"mean_m", s.mean},   {"rmse_m", s.rmse},
                              {"max_m", s.max},           {"along_mean_m", s.along_mean}, {"across_mean_m", s.across_mean}};
  if (file) j["file"] = file;
  return j;
}

}  // namespace coloc::replay
