#!/usr/bin/env bash
# Usage: nav2_live.sh COLOC LOG
# A real ROS 2 recording localized live as offline: the nav2 TurtleBot drive (AMCL poses and wheel
# odometry, header stamps on the simulator's clock while the player's /clock is the recorder's wall
# clock) is fused by `coloc fuse`, then played by `coloc play` into `coloc localize --use-sim-time
# --discover-inputs` with no map and no configuration, at four times its pace. The live track must lie within 3 cm (mean) of the
# offline one, over at least 80 % of the drive.
set -euo pipefail
coloc=$1
log=$2
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
export ROS_LOCALHOST_ONLY=1

"$coloc" fuse "$log" --out "$work/offline" > "$work/fuse.txt"
bounded 150 "$work/localize.txt" "$coloc" localize --use-sim-time --discover-inputs --out "$work/live" --idle-exit 3 --duration 140 &
localizer=$!
bounded 130 "$work/play.txt" "$coloc" play "$log" --delay 3 --rate 4
wait "$localizer"
grep -q 'subscribed to /amcl_pose (geometry_msgs/msg/PoseWithCovarianceStamped) as pose' "$work/localize.txt" ||
  { echo "FAIL: /amcl_pose was not taken as a pose source"; exit 1; }
grep -q 'subscribed to /odom (nav_msgs/msg/Odometry) as twist' "$work/localize.txt" || { echo "FAIL: /odom was not taken as a twist source"; exit 1; }

# The live estimates against the offline track interpolated at their stamps (both on the header stamps' clock).
awk '
  FNR == NR { if ($0 ~ /^#/) next; n++; t[n] = $1; x[n] = $2; y[n] = $3; next }
  /^#/ { next }
  {
    s = $1
    while (j < n && t[j + 1] < s) j++
    if (j < 1 || j >= n || t[j + 1] - t[j] > 0.5) next
    w = (s - t[j]) / (t[j + 1] - t[j])
    sum += sqrt(($2 - x[j] - w * (x[j + 1] - x[j])) ^ 2 + ($3 - y[j] - w * (y[j + 1] - y[j])) ^ 2); m++
    if (first == "") first = s; last = s
  }
  END {
    span = t[n] - t[1]; covered = m ? (last - first) / span : 0
    printf "live: %d estimates over %.1f of %.1f s of the offline track (%.0f %%), mean %.4f m from it\n", m, last - first, span, 100 * covered, m ? sum / m : -1
    exit !(m > 0 && covered >= 0.8 && sum / m <= 0.03) }' "$work/offline/fused.tum" "$work/live/fused.tum" ||
  { echo "FAIL: the live track is not within 3 cm of the offline one over 80 % of the drive"; exit 1; }
echo "the nav2 recording played live gives the offline track"
