#pragma once
// Lines people read at the end of a run, in the same words for `coloc fuse` and `coloc localize`.
#include <string>

#include "coloc/pipeline/pipeline.hpp"

namespace coloc::tools {

/// "RSU A: 53 received; refused by the checks: addressed_to_another 20; passed 33; the filter applied
/// 30, gated 1, not initialised 2": received, refused and gated are never counted as applied.
std::string fixLine(const std::string& rsu_id, const pipeline::PipelineReport& report);
/// "localized since 12.3 s; started: position from ..., heading ...; 1 recovery; 0 clock resets"
std::string localizationLine(const pipeline::PipelineReport& report);
/// What the pipeline learned and corrected where NDT ran: its travel and fix checks, its quality map,
/// the odometry's scale and gyro bias, the LiDAR's mounting yaw, the filter's odometry states; one
/// line each, indented.
std::string learnedLines(const pipeline::PipelineReport& report);

}  // namespace coloc::tools
