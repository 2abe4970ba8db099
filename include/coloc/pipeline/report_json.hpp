#pragma once
// The pipeline's counters as JSON text, in one shape for every summary.json that reports them
// (`coloc fuse`, `coloc localize`).
#include <map>
#include <string>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::pipeline {

/// [{name, kind, counters: {received, applied, gated, ...}}, ...]
std::string sourcesJson(const std::vector<fusion::SourceReport>& sources);
/// {scans, poses, scans_without_guess, no_map, ..., map_builds, tiles_in_target}
std::string ndtJson(const ndt::NdtPoseSourceCounters& ndt, const ndt::DynamicMapStats& map, std::uint64_t scans_without_guess);
/// {RSU_ID: {received, accepted, unknown_rsu, ...}, ...}
std::string fixesJson(const std::map<std::string, rsu_client::FixCounters>& fixes);

}  // namespace coloc::pipeline
