#!/usr/bin/env bash
# Usage: uncalibrated_start.sh COLOC SCENARIO
# The first metres of a drive taken up while moving, before the odometry's speed scale and the LiDAR's
# mounting are learned (config/scenarios/uncalibrated_start.yaml: odometry 1 % high, LiDAR turned 0.6
# deg, NDT accurate, the start given by hand and doubted for its first seconds, the street being alike
# along its length): with the defaults the fused pose is no worse than NDT's own poses over the first
# 12 m and over the drive, and using the learned scale from its first chord beats waiting for 15 m
# (docs/experiment.md, "The first metres").
# Three drives, the scenario's seed 1, 2 and 3: over the first 12 m one drive's means move by as much as
# what is compared (on eight seeds fused / NDT 0.79-1.00x, fused / waiting 0.67-0.90x), so those two are
# held over the three drives together, and each drive's whole length alone.
set -euo pipefail
coloc=$1
scenario=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# mean_of PATTERN FILE: the mean of the report line matching PATTERN, in metres.
mean_of() { sed -n "/$1/ s/.*mean \([0-9.]*\) m, RMSE.*/\1/p" "$2"; }
# The mean error within 12 m of the drive's start: the filter's every tick (error.csv), NDT's poses (input_error.csv).
first_metres() {
  awk -F, -v source="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
    source != "" && $c["source"] != source { next }
    !started { x0 = $c["truth_x"]; y0 = $c["truth_y"]; started = 1 }
    sqrt(($c["truth_x"] - x0)^2 + ($c["truth_y"] - y0)^2) <= 12 { s += $c["error_m"]; n++ }
    END { if (n) printf "%.5f", s / n }' "$1"
}
sum_fused12=0; sum_ndt12=0; sum_waited12=0
for seed in 1 2 3; do
  d="$work/seed_$seed"
  mkdir -p "$d"
  sed "s/^seed: .*/seed: $seed/" "$scenario" > "$d/scenario.yaml"
  grep -q "^seed: $seed$" "$d/scenario.yaml" || { echo "FAIL: the scenario has no seed key"; exit 1; }
  "$coloc" simulate "$d/scenario.yaml" --out "$d/sim" > /dev/null
  "$coloc" fuse "$d/sim/log" --map "$d/sim/map" --config "$d/sim/fuse.yaml" --out "$d/fused" > "$d/fused.txt"
  sed 's/^pipeline:$/pipeline:\n  speed_scale_min_distance: 15.0/' "$d/sim/fuse.yaml" > "$d/sim/waited.yaml"
  grep -q 'speed_scale_min_distance: 15.0' "$d/sim/waited.yaml" || { echo "FAIL: fuse.yaml has no pipeline section"; exit 1; }
  "$coloc" fuse "$d/sim/log" --map "$d/sim/map" --config "$d/sim/waited.yaml" --out "$d/waited" > "$d/waited.txt"
  fused=$(mean_of "position error vs ground truth" "$d/fused.txt")
  ndt=$(mean_of "ndt  .*its own poses" "$d/fused.txt")
  fused12=$(first_metres "$d/fused/error.csv" "")
  ndt12=$(first_metres "$d/fused/input_error.csv" ndt)
  waited12=$(first_metres "$d/waited/error.csv" "")
  echo "seed $seed: over the drive fused $fused m, NDT's own poses $ndt m; over the first 12 m fused $fused12 m, NDT $ndt12 m, the scale waiting for 15 m $waited12 m"
  [ -n "$fused" ] && [ -n "$ndt" ] && [ -n "$fused12" ] && [ -n "$ndt12" ] && [ -n "$waited12" ] || { echo "FAIL: seed $seed: no error reported within the drive or its first 12 m"; exit 1; }
  # NDT's travel check lays the odometry's travel along the direction of motion (NDT's yaw and the
  # filter's yaw bias): along NDT's yaw alone, the LiDAR's 0.6 deg put each 4 m chord 4 cm aside, and 67
  # of the 80 poses were taken as disagreeing with the odometry (measured before NDT started from the
  # yaw it measures; docs/experiment.md, "The first metres").
  disagreements=$(sed -n '/"ndt_travel_check"/,/}/ s/.*"disagreements": *\([0-9]*\).*/\1/p' "$d/fused/summary.json")
  poses=$(grep -c ',ndt,' "$d/fused/input_error.csv")
  echo "seed $seed: NDT's travel check: $disagreements of $poses poses disagreeing with the odometry"
  [ -n "$disagreements" ] && [ "$poses" -gt 0 ] || { echo "FAIL: seed $seed: no travel check or NDT poses reported"; exit 1; }
  awk -v d="$disagreements" -v n="$poses" 'BEGIN { exit !(d <= 0.1 * n) }' || { echo "FAIL: seed $seed: $disagreements of $poses NDT poses disagree with the odometry"; exit 1; }
  awk -v a="$fused" -v n="$ndt" 'BEGIN { exit !(a <= n) }' || { echo "FAIL: seed $seed: fused $fused m against NDT's own $ndt m over the drive"; exit 1; }
  awk -v a="$fused12" -v b="$waited12" 'BEGIN { exit !(a < b) }' || { echo "FAIL: seed $seed: the first chord's scale $fused12 m against waiting for 15 m $waited12 m over the first 12 m"; exit 1; }
  sum_fused12=$(awk -v s="$sum_fused12" -v a="$fused12" 'BEGIN { printf "%.5f", s + a }')
  sum_ndt12=$(awk -v s="$sum_ndt12" -v a="$ndt12" 'BEGIN { printf "%.5f", s + a }')
  sum_waited12=$(awk -v s="$sum_waited12" -v a="$waited12" 'BEGIN { printf "%.5f", s + a }')
done
echo "the three drives' first 12 m: fused $sum_fused12, NDT $sum_ndt12, waiting for 15 m $sum_waited12 (sums of the means, m)"
awk -v a="$sum_fused12" -v n="$sum_ndt12" 'BEGIN { exit !(a <= n) }' || { echo "FAIL: fused $sum_fused12 against NDT's own $sum_ndt12 over the first 12 m of the three drives"; exit 1; }
awk -v a="$sum_fused12" -v b="$sum_waited12" 'BEGIN { exit !(a < 0.85 * b) }' || { echo "FAIL: the first chord's scale $sum_fused12 against waiting for 15 m $sum_waited12 over the first 12 m of the three drives"; exit 1; }
