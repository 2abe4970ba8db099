#!/usr/bin/env bash
# Usage: rsu_node_live.sh COLOC SCENARIO
# The roadside unit's own node in the loop: a twin drive with a second connected vehicle 3.5 m to the
# side, its RSU's LiDAR frames and both vehicles' CAMs recorded; `coloc play` puts the frames, the CAMs
# and the ego's sensors on DDS (not the twin's own fixes); `coloc rsu-node` makes the fixes live and
# addresses each to its vehicle; the ego's `coloc localize` and the other vehicle's each take only their
# own. In a network namespace of its own.
set -euo pipefail
coloc=$1
scenario=$2
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
export ROS_LOCALHOST_ONLY=1

cp "$scenario" "$work/two.yaml"
printf 'traffic:\n  - {lane_offset: 3.5, start: 0.0, speed: 8.0, station_id: 1002}\n' >> "$work/two.yaml"
"$coloc" simulate "$work/two.yaml" --out "$work/sim" --rsu-frames > "$work/simulate.txt"
# Offline first: the node over the recorded frames, scored against the ego's ground truth.
"$coloc" rsu-node --registry "$work/sim/rsu.yaml" --log "$work/sim/log" --out "$work/offline" --commission 20 --truth-station 1001 > "$work/offline.txt"
read -r fixes median worst < <(sed -n 's/.*station 1001.s fixes against \/ground_truth\/odom: \([0-9]*\), median \([0-9.]*\) m, p90 [0-9.]* m, worst \([0-9.]*\) m/\1 \2 \3/p' "$work/offline.txt")
echo "offline: $fixes fixes of the ego, median ${median} m, worst ${worst} m"
awk -v n="$fixes" -v m="$median" -v w="$worst" 'BEGIN { exit !(n >= 80 && m < 0.05 && w < 0.3) }' || { echo "FAIL: offline fixes of the ego"; exit 1; }
grep -q "^[0-9.]*,1002,fix," "$work/offline/fixes.csv" || { echo "FAIL: no fix for the second vehicle offline"; exit 1; }

# Live: the ego localizes without an initial pose; the other vehicle has no scans and no map, only its fixes.
sed '/initial_pose/d; /^pipeline:/d' "$work/sim/fuse.yaml" > "$work/sim/ego.yaml"
sed 's/station_id: 1001.*/station_id: 1002/' "$work/sim/ego.yaml" > "$work/sim/other.yaml"
grep -q "station_id: 1002" "$work/sim/other.yaml"
bounded 120 "$work/node.txt" "$coloc" rsu-node --registry "$work/sim/rsu.yaml" --commission 20 --reliable --idle-exit 4 --duration 100 &
node=$!
bounded 120 "$work/ego.txt" "$coloc" localize --map "$work/sim/map" --config "$work/sim/ego.yaml" --use-sim-time --reliable --out "$work/live_ego" \
  --idle-exit 4 --duration 100 &
ego=$!
bounded 120 "$work/other.txt" "$coloc" localize --config "$work/sim/other.yaml" --use-sim-time --reliable --out "$work/live_other" \
  --idle-exit 4 --duration 100 &
other=$!
bounded 100 "$work/play.txt" "$coloc" play "$work/sim/log" --delay 3 --reliable \
  --topics /points /vehicle/twist /rsu/rsu_a/points /v2x/cam
wait "$node" "$ego" "$other"
json() { sed -n "s/.*\"$2\": \([^,]*\),*$/\1/p" "$1" | head -n1; }
sent=$(sed -n 's/^rsu-node rsu_a stopped: \([0-9]*\) fixes sent$/\1/p' "$work/node.txt")
echo "live: the RSU node sent $sent fixes"
[ "${sent:-0}" -ge 100 ] || { echo "FAIL: the RSU node sent ${sent:-no} fixes live"; exit 1; }
for who in ego other; do
  s="$work/live_$who/summary.json"
  passed=$(json "$s" passed_checks)
  other_fixes=$(json "$s" addressed_to_another)
  echo "$who: $passed fixes taken as its own, $other_fixes refused as another's"
  [ "${passed:-0}" -ge 40 ] && [ "${other_fixes:-0}" -ge 40 ] || { echo "FAIL: $who did not take its own fixes and only those"; exit 1; }
done
grep -q '"started_how": "position from /rsu/rsu_a/fix' "$work/live_ego/summary.json" || { echo "FAIL: the ego did not start from the RSU node's fixes"; exit 1; }
echo "the RSU node's live fixes reached each vehicle, addressed to it alone"
