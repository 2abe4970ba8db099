#!/usr/bin/env bash
# Usage: autoware_contract.sh COLOC SCENARIO CYCLONE_ENDPOINTS
# coloc where Autoware's ndt_scan_matcher and ekf_localizer stand (config/autoware.yaml), in a network
# namespace of its own with default discovery:
#   1. an independent DDS (Eclipse Cyclone) sees every endpoint of the contract with its ROS 2 type
#      name and QoS;
#   2. nothing is published before activation;
#   3. pose_initializer's sequence from another participant (`coloc initialize`: both triggers off,
#      NDT's alignment around a pose 1 m and 10 deg off, the result on /initialpose3d, both triggers
#      on) lands within 0.3 m of the truth;
#   4. then the outputs flow at 50 Hz, /tf and /diagnostics included.
set -euo pipefail
coloc=$1
scenario=$2
endpoints=$3
source "$(dirname "$0")/../support/in_multicast_namespace.sh"
unset ROS_DOMAIN_ID ROS_LOCALHOST_ONLY CYCLONEDDS_URI

# A slow, straight drive (15 m at 0.5 m/s), so that a pose given a few seconds in is known to within a metre.
sed 's/speed: [0-9.]*/speed: 0.5/; s/pieces: .*/pieces: [{length: 15}]/' "$scenario" > "$work/site.yaml"
"$coloc" simulate "$work/site.yaml" --out "$work/sim" > "$work/simulate.txt"
"$coloc" fuse "$work/sim/log" --map "$work/sim/map" --config "$work/sim/fuse.yaml" --out "$work/offline" > "$work/fuse.txt"
read -r x0 y0 z0 yaw0 < <(sed -n 's/.*initial_pose: \[\(.*\)\]/\1/p' "$work/sim/fuse.yaml" | tr -d ',')
# The twin's configuration with Autoware's names, and no initial pose: it waits for the initializer.
{ sed '/initial_pose/d; /^pipeline:/d' "$work/sim/fuse.yaml"; cat "$(dirname "$0")/../../config/autoware.yaml"; } > "$work/sim/autoware.yaml"

bounded 60 "$work/cyclone.txt" "$endpoints" 12 &
lister=$!
bounded 90 "$work/localize.txt" "$coloc" localize --map "$work/sim/map" --config "$work/sim/autoware.yaml" --use-sim-time \
  --out "$work/live" --idle-exit 3 --duration 70 &
localizer=$!
bounded 60 "$work/play.txt" "$coloc" play "$work/sim/log" --delay 3 \
  --remap /points:=/localization/util/downsample/pointcloud --remap /vehicle/twist:=/localization/twist_estimator/twist_with_covariance &
player=$!

# 2.-3. The initializer's sequence about 6.5 s into the drive (about 3.3 m along), 1 m to the left and 10 deg off.
sleep 10
read -r gx gy gyaw < <(awk -v x="$x0" -v y="$y0" -v a="$yaw0" 'BEGIN { d = 3.3; printf "%.3f %.3f %.4f\n", x + d * cos(a) - sin(a), y + d * sin(a) + cos(a), a + 10 * 3.14159265 / 180 }')
bounded 40 "$work/initialize.txt" "$coloc" initialize --config "$work/sim/autoware.yaml" --use-sim-time --pose "$gx,$gy,$gyaw" --z "$z0" || true
cat "$work/initialize.txt"
wait "$lister"
wait "$player"
wait "$localizer"

# 1. The contract's endpoints, as Cyclone sees them (topic "rt" + name, type pkg::msg::dds_::Name_).
expect() {  # KIND TOPIC TYPE RELIABILITY
  grep -q "^$1 $2 $3 $4 volatile$" "$work/cyclone.txt" || { echo "FAIL: Cyclone does not see $*"; exit 1; }
}
expect reader rt/localization/util/downsample/pointcloud sensor_msgs::msg::dds_::PointCloud2_ best_effort
expect reader rt/localization/twist_estimator/twist_with_covariance geometry_msgs::msg::dds_::TwistWithCovarianceStamped_ best_effort
expect reader rt/initialpose3d geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ best_effort
expect writer rt/localization/pose_twist_fusion_filter/kinematic_state nav_msgs::msg::dds_::Odometry_ reliable
expect writer rt/localization/pose_twist_fusion_filter/twist_with_covariance geometry_msgs::msg::dds_::TwistWithCovarianceStamped_ reliable
expect writer rt/localization/pose_twist_fusion_filter/biased_pose_with_covariance geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ reliable
expect writer rt/localization/pose_twist_fusion_filter/pose geometry_msgs::msg::dds_::PoseStamped_ reliable
expect writer rt/localization/pose_with_covariance geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ reliable
expect writer rt/localization/pose_estimator/pose_with_covariance geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ reliable
expect writer rt/tf tf2_msgs::msg::dds_::TFMessage_ reliable
expect writer rt/diagnostics diagnostic_msgs::msg::dds_::DiagnosticArray_ reliable
for s in /localization/pose_twist_fusion_filter/trigger_node /localization/pose_estimator/trigger_node; do
  expect reader "rq${s}Request" std_srvs::srv::dds_::SetBool_Request_ reliable
  expect writer "rr${s}Reply" std_srvs::srv::dds_::SetBool_Response_ reliable
done
expect reader rq/localization/pose_estimator/ndt_align_srvRequest autoware_internal_localization_msgs::srv::dds_::PoseWithCovarianceStamped_Request_ reliable
expect writer rr/localization/pose_estimator/ndt_align_srvReply autoware_internal_localization_msgs::srv::dds_::PoseWithCovarianceStamped_Response_ reliable
echo "Cyclone sees every endpoint of the contract with its ROS 2 type and QoS"

grep -q '^initialized' "$work/initialize.txt" || { echo "FAIL: the initializer's sequence did not complete"; exit 1; }

# Before activation nothing went out: the first estimate published is after the initial pose.
first=$(awk '!/^#/ { print $1; exit }' "$work/live/fused.tum")
[ -n "$first" ] || { echo "FAIL: nothing was published after activation"; exit 1; }
# The aligned pose against the truth at its scan, and the track after it (offline error.csv: stamp, estimate, truth).
read -r ax ay < <(sed -n 's/.*ndt_align_srv: x=\([-0-9.]*\) y=\([-0-9.]*\) .*/\1 \2/p' "$work/initialize.txt")
awk -F'[ ,]' -v ax="$ax" -v ay="$ay" 'NR > 1 { d = sqrt(($4 - ax) ^ 2 + ($5 - ay) ^ 2); if (best == "" || d < best) best = d }
  END { printf "aligned pose %.3f m from the nearest point of the true track\n", best; exit !(best < 0.3) }' "$work/offline/error.csv" ||
  { echo "FAIL: NDT's alignment is not within 0.3 m of the truth"; exit 1; }
# 4. 50 Hz: the published estimates' spacing (median, and no gap over 0.1 s).
awk '!/^#/ { if (last != "") printf "%.6f\n", $1 - last; last = $1 }' "$work/live/fused.tum" | sort -g > "$work/spacing"
n=$(wc -l < "$work/spacing")
median=$(sed -n "$(( (n + 1) / 2 ))p" "$work/spacing")
gaps=$(awk '$1 > 0.1' "$work/spacing" | wc -l)
echo "$((n + 1)) estimates after activation, median spacing $median s, $gaps gaps over 0.1 s"
awk -v n="$n" -v m="$median" -v g="$gaps" 'BEGIN { exit !(n > 300 && m > 0.0195 && m < 0.0205 && g == 0) }' ||
  { echo "FAIL: the outputs did not come at 50 Hz"; exit 1; }
grep -q '"published"' "$work/live/summary.json"
echo "coloc stands where ndt_scan_matcher and ekf_localizer stand: contract seen by Cyclone, initializer sequence, 50 Hz"
