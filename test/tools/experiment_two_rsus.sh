#!/usr/bin/env bash
# Usage: experiment_two_rsus.sh COLOC TEST_DIR
# `coloc experiment` on a site with several RSUs of each LiDAR model: every RSU of the model is fused
# (more fixes applied than either RSU sent alone), each is measured, calibrated and reported on its
# own, and an RSU the route never reaches is noted, not fatal.
set -euo pipefail
coloc=$1
dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$dir"
"$coloc" experiment --quick experiment_two_rsus.yaml --out "$work/out" | tee "$work/run.txt"
fixes="$work/out/recordings/two_rsu_site/trial_0/rsu_fixes.csv"
for lidar in VLP-16 VLP-32C; do
  slug=$(echo "$lidar" | tr -d - | tr 'A-Z' 'a-z')
  west=$(awk -F, -v id="rsu_west_$slug" '$2 == id && $9 == 1' "$fixes" | wc -l)
  east=$(awk -F, -v id="rsu_east_$slug" '$2 == id && $9 == 1' "$fixes" | wc -l)
  # runs.csv: site,trial,configuration,lidar,delay_s,loss,variant,coverage_lidar,range_m,...,fixes_applied,fixes_gated,fixes_lost,replay_s
  used=$(awk -F, -v l="$lidar" '$4 == l && $7 == "\"\"" && $8 == l { print $(NF-3) + $(NF-2); exit }' "$work/out/runs.csv")
  echo "$lidar: rsu_west sent $west fixes, rsu_east $east; the fused replay took $used"
  [ "$west" -gt 0 ] && [ "$east" -gt 0 ] || { echo "FAIL: both RSUs should have sent fixes"; exit 1; }
  [ "$used" -gt "$west" ] && [ "$used" -gt "$east" ] || { echo "FAIL: the replay fused only one RSU's fixes"; exit 1; }
  grep -q "note: two_rsu_site $lidar (rsu_far): 0 fixes on the noise calibration drive" "$work/run.txt" || { echo "FAIL: no note for the unreached RSU"; exit 1; }
  for rsu in rsu_west rsu_east rsu_far; do
    grep -q "^two_rsu_site,$lidar,$rsu," "$work/out/calibration.csv" || { echo "FAIL: no calibration row for $rsu ($lidar)"; exit 1; }
  done
done
grep -q '| two_rsu_site | VLP-16 (rsu_west) |' "$work/out/README.md" || { echo "FAIL: the report does not name the RSUs apart"; exit 1; }
echo "every RSU of each model fused, calibrated and reported; the unreached one noted"
