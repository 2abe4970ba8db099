#!/usr/bin/env bash
# Usage: play_into_localize.sh COLOC SCENARIO
# The vehicle side live end to end: a simulated drive is fused offline (`coloc fuse`), then played over
# DDS (`coloc play`, at its recorded pace, its time on /clock) into the live localizer (`coloc localize
# --use-sim-time`). The live estimate must be as good as the offline one (mean error against ground
# truth within 1.2x) and no fix may be lost on loopback.
set -euo pipefail
coloc=$1
scenario=$2
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
# Loopback only, as a ROS 2 node is told with ROS_LOCALHOST_ONLY: nothing leaves the machine.
export ROS_LOCALHOST_ONLY=1

"$coloc" simulate "$scenario" --out "$work/sim" > "$work/simulate.txt"
"$coloc" fuse "$work/sim/log" --map "$work/sim/map" --config "$work/sim/fuse.yaml" --out "$work/offline" > "$work/fuse.txt"

# Reliable QoS on the inputs: on loopback nothing may be lost, so every loss would be coloc's.
bounded 150 "$work/localize.txt" "$coloc" localize --map "$work/sim/map" --config "$work/sim/fuse.yaml" --use-sim-time --reliable \
  --out "$work/live" --idle-exit 3 --duration 120 &
localizer=$!
bounded 90 "$work/play.txt" "$coloc" play "$work/sim/log" --delay 3
wait "$localizer"
cat "$work/play.txt" "$work/localize.txt"

# Mean planar error of a TUM trajectory against the ground truth the offline run interpolated at its
# ticks (error.csv: stamp, estimate, truth), interpolated again at each live stamp.
mean_error() {
  awk -F'[ ,]' '
    FNR == NR { if (FNR > 1) { n++; t[n] = $1; x[n] = $4; y[n] = $5 } next }
    /^#/ { next }
    {
      s = $1
      while (j < n && t[j + 1] < s) j++
      if (j < 1 || j >= n || t[j + 1] - t[j] > 0.05) next
      w = (s - t[j]) / (t[j + 1] - t[j])
      tx = x[j] + w * (x[j + 1] - x[j]); ty = y[j] + w * (y[j + 1] - y[j])
      sum += sqrt(($2 - tx) ^ 2 + ($3 - ty) ^ 2); m++
    }
    END { if (m < 100) { print "nan"; exit } printf "%.5f %d\n", sum / m, m }' "$work/offline/error.csv" "$1"
}
read -r offline offline_n < <(mean_error "$work/offline/fused.tum")
read -r live live_n < <(mean_error "$work/live/fused.tum")
played=$(sed -n 's|^ */rsu/rsu_a/addressed_fix *\([0-9]*\)$|\1|p' "$work/play.txt")
received=$(sed -n 's|^ *RSU rsu_a: \([0-9]*\) fixes received.*|\1|p' "$work/localize.txt")
echo "offline mean error $offline m over $offline_n ticks; live $live m over $live_n ticks; fixes played $played, received $received"
[ "$live" != nan ] || { echo "FAIL: the live localizer gave fewer than 100 estimates on the drive"; exit 1; }
awk -v l="$live" -v o="$offline" 'BEGIN { exit !(l <= 1.2 * o) }' || { echo "FAIL: live error $live m is more than 1.2x offline $offline m"; exit 1; }
[ -n "$played" ] && [ "$played" -gt 0 ] || { echo "FAIL: no fix was played"; exit 1; }
[ "$received" = "$played" ] || { echo "FAIL: $played fixes played, $received received"; exit 1; }
echo "live over DDS matches offline: $live m against $offline m, all $played fixes received"
