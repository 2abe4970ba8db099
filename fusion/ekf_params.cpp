#include "coloc/fusion/ekf_params.hpp"

#include "coloc/core/number_text.hpp"

namespace coloc::fusion {

const std::vector<EkfParam>& ekfParams() {
  using C = EkfConfig;
  static const std::vector<EkfParam> params = {
      {"predict_frequency", "Hz", "fixed prediction rate, on the caller's clock (log time offline)", &C::predict_frequency},
      {"history_steps", "ticks", "how far back a delayed measurement is still applied exactly (50 = 1 s)", &C::history_steps},
      {"relinearize_on_replay", "", "re-evaluate the motion model when replaying after a late measurement (exact); false reproduces Autoware's augmented filter", &C::relinearize_on_replay},
      {"enable_yaw_bias_estimation", "", "estimate a constant offset between measured yaw and direction of motion", &C::enable_yaw_bias_estimation},
      {"proc_stddev_yaw_c", "rad/s", "yaw process noise; Q = (c dt)^2", &C::proc_stddev_yaw_c},
      {"proc_stddev_vx_c", "m/s^2", "speed process noise", &C::proc_stddev_vx_c},
      {"proc_stddev_wz_c", "rad/s^2", "yaw-rate process noise", &C::proc_stddev_wz_c},
      {"yaw_bias_walk", "rad/sqrt(s)", "the yaw bias's random walk (its variance grows by walk^2 per second); 0 = constant (Autoware)", &C::yaw_bias_walk},
      {"yaw_rate_sampling_noise", "", "each twist adds to the yaw variance the heading's error from a yaw rate that changed since the last twist at an unknown moment, (change x interval)^2 / 12; off = Autoware", &C::yaw_rate_sampling_noise},
      {"pose_smoothing_steps", "ticks", "a pose is applied over this many ticks, each with covariance x steps", &C::pose_smoothing_steps},
      {"max_pose_queue_size", "poses", "poses of one source being smoothed at once; the oldest is folded in when full", &C::max_pose_queue_size},
      {"twist_smoothing_steps", "ticks", "as pose_smoothing_steps, for twists", &C::twist_smoothing_steps},
      {"max_twist_queue_size", "twists", "as max_pose_queue_size, for twists", &C::max_twist_queue_size},
      {"pose_gate_alpha", "", "chance a correct pose is gated: d^2 = e' S^-1 e against the chi-square (1 - alpha) quantile; 0 = no gate", &C::pose_gate_alpha},
      {"twist_gate_alpha", "", "as pose_gate_alpha, for twists", &C::twist_gate_alpha},
      {"pose_time_alignment", "", "carry a pose from its stamp to the tick it is applied at (up to half a tick) with the state's speed and yaw rate; off = Autoware's rounding", &C::pose_time_alignment},
      {"pose_gate_recovery", "poses", "after this many gated poses of a source in a row, the next are applied at the gate's weight until one passes; 0 = off", &C::pose_gate_recovery},
      {"twist_gate_recovery", "twists", "as pose_gate_recovery, for twists (a yaw rate that steps beyond a tight gate); 0 = off", &C::twist_gate_recovery},
      {"z_filter_proc_dev", "m/s", "random walk of the separate z filter", &C::z_filter_proc_dev},
      {"roll_filter_proc_dev", "rad/s", "random walk of the separate roll filter", &C::roll_filter_proc_dev},
      {"pitch_filter_proc_dev", "rad/s", "random walk of the separate pitch filter", &C::pitch_filter_proc_dev},
      {"threshold_observable_velocity_mps", "m/s", "below this speed a twist's vx variance becomes 10000; 0 = off", &C::threshold_observable_velocity_mps},
      {"future_tolerance", "s", "a stamp ahead of the clock by more than this is rejected; within it, it waits for its tick", &C::future_tolerance},
      {"initial_yaw_bias_variance", "rad^2", "yaw-bias variance at initialisation", &C::initial_yaw_bias_variance},
      {"initial_vx_variance", "(m/s)^2", "speed variance at initialisation (an initial pose says nothing of speed)", &C::initial_vx_variance},
      {"initial_wz_variance", "(rad/s)^2", "yaw-rate variance at initialisation", &C::initial_wz_variance},
      {"auto_initialize", "", "the first pose measuring x, y and yaw initialises the filter", &C::auto_initialize},
      {"integrity_lost_after_gated_anchors", "poses", "anchor poses (RSU fixes) gated in a row, agreeing with each other, that make the filter lost (one: degraded); 0 = never", &C::integrity_lost_after_gated_anchors},
      {"integrity_anchor_agreement", "m", "gated anchor poses whose disagreements with the filter differ by less than this tell the same story", &C::integrity_anchor_agreement},
      {"integrity_anchor_window", "poses", "the last anchor poses (within 2 s) whose mean squared Mahalanobis distance, telling one story, makes the filter lost; 0 = off", &C::integrity_anchor_window},
      {"integrity_anchor_mean_nis", "", "that mean's limit (chi-square(2) 0.999 quantile: 13.8)", &C::integrity_anchor_mean_nis},
      {"integrity_lost_min_distance", "m", "lost only when the anchors' disagreement is at least this (an RSU's own error could tell a smaller one); below, degraded", &C::integrity_lost_min_distance},
      {"integrity_degraded_after_gated", "poses", "poses of another source (NDT) gated in a row that make the filter degraded; 0 = off", &C::integrity_degraded_after_gated},
      {"integrity_dead_reckoning_limit", "s", "time without any pose applied that makes the filter degraded; 0 = off", &C::integrity_dead_reckoning_limit},
      {"integrity_anchor_memory", "s", "time of other poses applied after which one gated anchor pose (an outlier) no longer degrades the filter", &C::integrity_anchor_memory},
      {"map_error_sd", "m", "the map's own error against the world (its survey's accuracy, per axis): added to the reported x/y covariance, not the filter's; 0 = the map is the world", &C::map_error_sd},
      {"map_match_bias_sd", "m", "a bias NDT's poses share from scan to scan (the map's, the place's), as two more states: its stationary sd; the roadside fixes (anchors) tell it apart; 0 = not modelled (Autoware's 6 states)", &C::map_match_bias_sd},
      {"map_match_bias_length", "m", "travel over which that bias fades to 1/e (a random walk in distance)", &C::map_match_bias_length},
      {"odometry_scale_sd", "", "the odometry's speed scale error as a state (the twist measures (1 + scale) vx), learned from the poses: its initial sd; 0 = not modelled (unless odometry_yaw_rate_bias_sd is)", &C::odometry_scale_sd},
      {"odometry_scale_walk", "1/sqrt(m)", "that error's random walk in distance", &C::odometry_scale_walk},
      {"odometry_yaw_rate_bias_sd", "rad/s", "the gyro's bias as a state (the twist measures wz + bias), learned from the poses: its initial sd; 0 = not modelled (unless odometry_scale_sd is)", &C::odometry_yaw_rate_bias_sd},
      {"odometry_yaw_rate_bias_walk", "rad/s/sqrt(s)", "that bias's random walk in time", &C::odometry_yaw_rate_bias_walk},
  };
  return params;
}

std::string formatValue(const EkfParam& param, const EkfConfig& config) {
  if (const auto* d = std::get_if<double EkfConfig::*>(&param.field)) {
    std::string text = exactNumberText(config.*(*d), 10);
    // YAML 1.2 reads "50" as an integer; keep floats recognisable as floats.
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
    return text;
  }
  if (const auto* i = std::get_if<int EkfConfig::*>(&param.field)) return std::to_string(config.*(*i));
  return config.*std::get<bool EkfConfig::*>(param.field) ? "true" : "false";
}

}  // namespace coloc::fusion
