#!/usr/bin/env bash
# Usage: scans_with_ros2_defaults.sh COLOC SCENARIO
# No scan lost on one host with ROS 2's defaults: a drive whose scans are as large as a 32-beam LiDAR's
# (about 0.8 MB of PointCloud2 each) is played by `coloc play` into `coloc localize`, both best effort
# (ROS 2's sensor-data QoS, what Autoware's NDT subscribes with), at 1x and 2x, once with
# ROS_LOCALHOST_ONLY=1 and once with Fast DDS's default discovery (multicast, kept inside the network
# namespace). At least 99 % of the scans must arrive, and what did not arrive must be counted as lost.
set -euo pipefail
coloc=$1
scenario=$2
source "$(dirname "$0")/../support/in_multicast_namespace.sh"
unset ROS_DOMAIN_ID

sed 's/lidar: VLP-16/lidar: VLP-32C/' "$scenario" > "$work/site.yaml"
"$coloc" simulate "$work/site.yaml" --out "$work/sim" > "$work/simulate.txt"

run() {  # NAME RATE LOCALHOST_ONLY
  local name=$1 rate=$2
  export ROS_LOCALHOST_ONLY=$3
  bounded 120 "$work/localize_$name.txt" "$coloc" localize --map "$work/sim/map" --config "$work/sim/fuse.yaml" --use-sim-time \
    --out "$work/live_$name" --idle-exit 3 --duration 100 &
  local localizer=$!
  bounded 90 "$work/play_$name.txt" "$coloc" play "$work/sim/log" --delay 3 --rate "$rate"
  wait "$localizer"
  local played received lost
  played=$(sed -n 's|^ */points *\([0-9]*\)$|\1|p' "$work/play_$name.txt")
  received=$(sed -n 's|^ */points *\([0-9]*\) messages .*|\1|p' "$work/localize_$name.txt")
  lost=$(sed -n 's|^ */points .* \([0-9]*\) lost (.*|\1|p' "$work/localize_$name.txt")
  echo "$name: $played scans played, $received received, $lost counted as lost"
  [ -n "$played" ] && [ "$played" -gt 100 ] || { echo "FAIL ($name): too few scans played"; exit 1; }
  awk -v r="$received" -v p="$played" 'BEGIN { exit !(r >= 0.99 * p) }' || { echo "FAIL ($name): fewer than 99 % of the scans arrived"; exit 1; }
  # A loss between two scans that arrived is seen by DDS; one at the very end cannot be.
  [ "$lost" -le $((played - received)) ] && [ "$lost" -ge $((played - received - 1)) ] ||
    { echo "FAIL ($name): $((played - received)) scans missing, $lost counted"; exit 1; }
}
run localhost_1x 1 1
run localhost_2x 2 1
run default_1x 1 0
run default_2x 2 0
echo "with ROS 2's defaults on one host, at least 99 % of the scans arrived at 1x and 2x, and every loss was counted"
