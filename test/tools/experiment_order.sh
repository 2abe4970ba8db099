#!/usr/bin/env bash
# Usage: experiment_order.sh COLOC TEST_DIR
# The replays of the experiment's drives are queued across drives: a thread that ends one drive's last
# replay goes on to the next drive's, and what a later drive is set up from (a site's noise calibration
# and calibration drives) is taken before it is. The results must not depend on the order the replays
# ran in: one replay at a time and three side by side give every CSV the same to the digit (runs.csv
# but its replay time).
set -euo pipefail
coloc=$1
dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$dir"  # the experiment file names its scenario relative to here
"$coloc" experiment experiment_order.yaml --jobs 1 --out "$work/jobs_1" > "$work/run_1.txt"
# Recorded, so that the replays' configurations show what each drive was set up from.
"$coloc" experiment experiment_order.yaml --jobs 3 --recordings --out "$work/jobs_3" > "$work/run_3.txt"
for f in table1.csv network.csv smoother.csv calibration.csv ndt_vs_fused.csv error_along_road.csv attribution.csv fix_error_by_distance.csv; do
  [ -s "$work/jobs_1/$f" ] || { echo "FAIL: $f missing or empty"; exit 1; }
  cmp -s "$work/jobs_1/$f" "$work/jobs_3/$f" || { echo "FAIL: $f differs between one replay at a time and three"; diff "$work/jobs_1/$f" "$work/jobs_3/$f" | head; exit 1; }
done
# runs.csv's last column is each replay's time.
strip() { sed 's/,[^,]*$//' "$1"; }
[ "$(wc -l < "$work/jobs_1/runs.csv")" -gt 20 ] || { echo "FAIL: runs.csv has too few rows"; exit 1; }
cmp -s <(strip "$work/jobs_1/runs.csv") <(strip "$work/jobs_3/runs.csv") || { echo "FAIL: runs.csv differs"; exit 1; }
grep -q 'calibrated registry' "$work/jobs_3/runs.csv" || { echo "FAIL: no next drive with the calibrated registry"; exit 1; }
# Every evaluated drive's replays floor NDT at its error by place on the site's noise calibration drive.
for trial in trial_0 trial_1; do
  grep -q '^  quality_map: "../../noise_calibration_drive/ndt_quality.yaml"' "$work/jobs_3/recordings/small_site/$trial/replays/ndt_only.yaml" ||
    { echo "FAIL: $trial was set up before the noise calibration drive's findings"; exit 1; }
done
echo "one replay at a time and three side by side: every CSV the same ($(wc -l < "$work/jobs_1/runs.csv") rows of runs.csv)"
