#include "coloc/sim/error_sources.hpp"

namespace coloc::sim {

ErrorSources ErrorSources::ideal() {
  ErrorSources e;
  e.survey_position_sd = 0.0;
  e.survey_yaw_sd = 0.0;
  e.clock_offset_sd = 0.0;
  e.clock_jitter_sd = 0.0;
  e.detailed_vehicle = false;
  e.range_noise = 0.02;
  e.range_noise_per_m = 0.0;
  e.dropout = 0.0;
  e.dropout_at_max_range = 0.0;
  e.lidar_mount_yaw = 0.0;
  e.map_position_sd = 0.0;
  e.map_yaw_sd = 0.0;
  e.cam_size_step = 0.0;
  e.beam_divergence = 0.0;
  e.beam_divergence_vertical = 0.0;
  return e;
}

}  // namespace coloc::sim
