#pragma once
// The pipeline's counters as JSON text, in one shape for every summary.json that reports them
// (`coloc fuse`, `coloc localize`).
#include <map>
#include <string>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/pipeline/pipeline.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::pipeline {

/// [{name, kind, counters: {received, applied, gated, ...}}, ...]
std::string sourcesJson(const std::vector<fusion::SourceReport>& sources);
/// {scans, poses, scans_without_guess, no_map, ..., map_builds, tiles_in_target}
std::string ndtJson(const ndt::NdtPoseSourceCounters& ndt, const ndt::DynamicMapStats& map, std::uint64_t scans_without_guess);
/// {RSU_ID: {received, passed_checks, refused_by_checks: {unknown_rsu, ...}, applied, gated,
/// not_initialized, too_old, ...}, ...}: "applied" is what the filter applied, nothing else.
std::string fixesJson(const std::map<std::string, rsu_client::FixCounters>& fixes, const std::map<std::string, fusion::SourceCounters>& filter);
/// {state, reason, started_how, starts, recoveries, ..., events}
std::string localizationJson(const PipelineReport& report);
/// What NDT's poses taught and where they were widened: {ndt_travel_check, ndt_fix_agreement,
/// ndt_quality_map, odometry_speed_scale, odometry_yaw_rate_bias, lidar_mount_yaw[,
/// filter_odometry_states]}, the keys a summary.json has beside "ndt".
std::string learnedJson(const PipelineReport& report);

}  // namespace coloc::pipeline
