#pragma once
// Every tunable of the filter, with its default, in one place. The defaults are Autoware
// ekf_localizer's (ekf_localizer.param.yaml) except where a comment says why coloc differs.
// Units are SI; durations are seconds here because this is the human-facing edge.
namespace coloc::fusion {

struct EkfConfig {
  double predict_frequency = 50.0;  ///< Hz; the fixed prediction rate on the caller's clock
  int history_steps = 50;           ///< ticks of state history kept for delayed measurements (1 s)
  bool enable_yaw_bias_estimation = true;
  /// Re-evaluate the motion model and its Jacobian when a delayed measurement is replayed through the
  /// history. On: a late measurement gives exactly the estimate an on-time one would. Off: the
  /// linearisation of each step is frozen at prediction time, which reproduces Autoware's
  /// extended-state filter to rounding error.
  bool relinearize_on_replay = true;

  double proc_stddev_yaw_c = 0.005;  ///< rad/s; yaw process noise, Q = (c * dt)^2
  double proc_stddev_vx_c = 10.0;    ///< m/s^2; speed process noise
  double proc_stddev_wz_c = 5.0;     ///< rad/s^2; yaw-rate process noise
  /// rad/sqrt(s); the yaw bias as a random walk in time (its variance grows by walk^2 per second), with
  /// enable_yaw_bias_estimation. 0: constant, as Autoware's. NDT's heading is off by a tenth of a
  /// degree that changes with the place (the map, the scene), and a constant bias then turns the
  /// direction of motion wherever NDT's yaw is trusted near its scan-to-scan noise (docs/filter.md, *NDT
  /// at its noise*).
  double yaw_bias_walk = 0.0;
  /// The heading's error between two twists (coloc's; off = Autoware). The filter turns the heading at
  /// one twist's yaw rate until the next; where the rate changed between them (into or out of a bend)
  /// it changed at a moment neither twist tells, and the heading is off by up to the change times the
  /// interval. On: each twist adds that moment's spread to the yaw variance, (change x interval)^2 / 12
  /// (the moment uniform between the two). On the twin's site C the filter left the bend at 0.4 rad/s
  /// with its heading 4.6 mrad past NDT's while it stated 0.4 mrad: four poses in a row at a
  /// normalized innovation squared of 60-150 in yaw, all of the site's excess there.
  bool yaw_rate_sampling_noise = false;

  int pose_smoothing_steps = 5;   ///< ticks over which one pose is applied, each with covariance x steps
  int max_pose_queue_size = 5;    ///< poses of one source being smoothed at once
  int twist_smoothing_steps = 2;
  int max_twist_queue_size = 2;

  /// Probability that a correct measurement is rejected by the Mahalanobis gate; the gate compares the
  /// squared distance with the chi-square quantile of 1 - alpha for the measurement's dimension.
  /// 1e-10 gives Autoware's 49.5 (3 dof) and 46.1 (2 dof), now applied to the squared distance. 0 = off.
  double pose_gate_alpha = 1e-10;
  double twist_gate_alpha = 1e-10;
  /// After this many poses of one source in a row failed the gate, the next ones are applied at reduced
  /// weight (their innovation covariance scaled up to the gate) until one passes on its own: when a
  /// source keeps disagreeing, the filter is more likely to have drifted with a covariance too small for
  /// its error (biased NDT) than the source to fail every time, and a hard gate would lock it out for
  /// good. 0 = off (Autoware: a gated pose is dropped, always).
  int pose_gate_recovery = 0;
  /// The same for twists: after this many twists of a source gated in a row, the next are applied at the
  /// gate's weight until one passes on its own. With the odometry's covariance at its sensor's noise and
  /// a process noise near the vehicle's dynamics, a yaw rate that steps (a bend entered, a lane changed)
  /// lies beyond the gate, and without it the twists after the step are refused until the filter's doubt
  /// of its yaw rate grows to it, which NDT's poses can keep from happening: the filter keeps the old
  /// yaw rate and runs off the road (the twin's site C, NDT alone: 13 m mean error, 51 m at worst).
  /// 0 = off (Autoware: a gated twist is dropped, always).
  int twist_gate_recovery = 0;
  /// A pose is applied at the tick nearest its stamp, up to half a tick (10 ms at 50 Hz) away; at
  /// 10 m/s that is up to 10 cm along the track, the same every time when the sensor's rate and the
  /// filter's are in step. On: the pose is first carried from its stamp to its tick with the state's
  /// own speed and yaw rate. Off: Autoware's rounding.
  bool pose_time_alignment = true;

  double z_filter_proc_dev = 5.0;      ///< m/s; random walk of the separate z filter
  double roll_filter_proc_dev = 0.1;   ///< rad/s
  double pitch_filter_proc_dev = 0.1;  ///< rad/s

  /// Below this |vx| a twist's speed variance is raised to 10000 (Autoware's dead band). 0 = off.
  double threshold_observable_velocity_mps = 0.0;

  /// A measurement stamped later than the caller's clock by more than this is rejected as from the
  /// future; within it, it waits until the filter's clock reaches its stamp.
  double future_tolerance = 0.05;  ///< s

  // Initial uncertainty of the states an initial pose does not give. Autoware uses 0.01 for vx and wz,
  // which assumes a standing start: with a correct gate, a filter started on a moving vehicle would
  // then refuse its odometry for most of a second. A pose says nothing about speed, so coloc starts
  // with sigma 10 m/s and 1 rad/s and lets the first twist set them.
  double initial_yaw_bias_variance = 1e-4;  ///< rad^2
  double initial_vx_variance = 100.0;       ///< (m/s)^2
  double initial_wz_variance = 1.0;         ///< (rad/s)^2

  /// A pose measurement that measures x, y and yaw initialises the filter when none has been given.
  bool auto_initialize = true;

  // Integrity (coloc's; Autoware's EKF has none): when the filter's estimate cannot be believed.
  // An anchor is a pose source independent of the vehicle's own map matching (a roadside fix, GNSS).
  /// Anchor poses gated in a row, each within integrity_anchor_agreement of the previous one's
  /// disagreement, that make the filter `lost` (one makes it `degraded`). 0 = never lost by anchors.
  int integrity_lost_after_gated_anchors = 2;
  double integrity_anchor_agreement = 1.0;  ///< m
  /// Anchor poses applied but far off, again and again: the last this many (within 2 s) whose mean
  /// squared Mahalanobis distance exceeds integrity_anchor_mean_nis, telling the same story, make the
  /// filter `lost` too (its map matching holds it in a wrong place just inside the gate). 0 = off.
  int integrity_anchor_window = 5;
  /// Chi-square(2)'s 0.999 quantile: the mean of 5 consistent draws exceeds it with a chance of about 1e-10.
  double integrity_anchor_mean_nis = 13.8;
  /// Lost only when the anchors' disagreement is at least this: below it an anchor's own error (a
  /// miscalibrated RSU: 10-40 cm) could tell the same story, and the filter stays degraded, its
  /// reported covariance covering the disagreement, instead of jumping to the anchor.
  double integrity_lost_min_distance = 1.0;  ///< m
  /// Poses of any other source gated in a row that make the filter `degraded`. 0 = off.
  int integrity_degraded_after_gated = 5;
  /// Seconds without any pose applied (dead reckoning on the twist alone) that make it `degraded`. 0 = off.
  double integrity_dead_reckoning_limit = 3.0;  ///< s
  /// Seconds of other poses applied, with no anchor disagreeing again, after which a single anchor's
  /// disagreement (an outlier fix) no longer counts.
  double integrity_anchor_memory = 2.0;  ///< s
  /// The map's own error against the world the truth and the RSUs' surveys are in (its survey's
  /// accuracy, per axis), added to the reported x/y covariance, not to the filter's. NDT's poses, the
  /// filter's main source, carry that error whole and alike from scan to scan, so averaging them cannot
  /// remove it while the filter, taking them as independent, reports centimetres below it: on the twin's
  /// site C (map drawn at 5 cm per axis) NDT was 10 cm across the road in a bend for 4 s and the filter
  /// said 3 cm. 0: the map is the world (Autoware's view).
  double map_error_sd = 0.0;  ///< m

  // The map-matching bias (coloc's; off by default, which is Autoware's 6-state filter). NDT's error
  // in a place is mostly the map's and the scene's, the same from one scan to the next, and a filter
  // that takes each pose as independent either trusts it at its scan-to-scan noise and follows the
  // bias, or at its whole error and then weighs it as independent poses, against fixes that are better.
  // On: two more states, the bias (x, y, map frame) that every pose of a source that is not an anchor
  // carries; a random walk in distance (Gauss-Markov: it fades to 1/e over map_match_bias_length of
  // travel towards a stationary sd of map_match_bias_sd, or the place's from Localizer::
  // setMapMatchBiasVariance). Anchors (roadside fixes) measure the position alone, so in coverage they
  // tell the bias apart and NDT's poses then correct by their noise alone.
  double map_match_bias_sd = 0.0;       ///< m; 0 = not modelled
  double map_match_bias_length = 10.0;  ///< m

  // The odometry's slow errors as states (coloc's; off by default). A wheel's radius off by 1 % and a
  // gyro's bias of a few mrad/s are not white noise: a filter that takes the odometry at its white
  // noise alone follows them between poses, and one that takes it at Autoware's 0.2 m/s and 0.1 rad/s
  // hides them but then weighs every pose against a prediction far looser than it is. On: two more
  // states, the share by which the twist's speed reads high (it measures (1 + scale) vx) and the
  // gyro's bias (it measures wz + bias), learned from the poses; each starts at zero with the sd
  // given and wanders by its walk. The pipeline's own learners (pipeline.speed_scale_estimation,
  // yaw_rate_bias_estimation) correct the twists before the filter; with these states on they are
  // best off, or the states see only what those leave.
  double odometry_scale_sd = 0.0;            ///< initial sd of the speed scale's error; 0 = not modelled
  double odometry_scale_walk = 0.0;          ///< 1/sqrt(m); its variance grows by walk^2 per metre
  double odometry_yaw_rate_bias_sd = 0.0;    ///< rad/s; initial sd of the gyro's bias
  double odometry_yaw_rate_bias_walk = 0.0;  ///< rad/s/sqrt(s); its variance grows by walk^2 per second

  /// Whether the odometry's slow errors are states (either sd given).
  bool modelsOdometryErrors() const { return odometry_scale_sd > 0.0 || odometry_yaw_rate_bias_sd > 0.0; }
};

}  // namespace coloc::fusion
