#!/usr/bin/env bash
# Usage: experiment_replays.sh COLOC TEST_DIR
# `coloc experiment --recordings` keeps each replay's configuration beside the drive's log: `coloc fuse`
# of the log with it must give the experiment's replay (the same fixes applied, gated and lost on the
# emulated link, the same mean error within the RSU's coverage).
set -euo pipefail
coloc=$1
dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$dir"  # the experiment file names its scenario relative to here
"$coloc" experiment experiment_replays.yaml --out "$work/out" > "$work/run.txt"
label="NDT + VLP-32C, 30 ms, 20 % loss"
file="$work/out/recordings/small_site/trial_0/replays/ndt_vlp_32c_30_ms_20_loss.yaml"
[ -s "$file" ] || { echo "FAIL: $file missing"; exit 1; }
# Its second line is the command; run it with another output folder.
command=$(sed -n 2p "$file" | sed 's/^# coloc //')
# shellcheck disable=SC2086
"$coloc" $command --out "$work/fuse" > "$work/fuse.txt"
# runs.csv, the quoted label taken out: ...,11 error_mean_m,12 samples,13 applied,14 gated,15 lost
row=$(grep -F "\"$label\"" "$work/out/runs.csv" | grep ',VLP-32C,50,' | sed 's/"[^"]*"//g')
expected_applied=$(echo "$row" | cut -d, -f13)
expected_gated=$(echo "$row" | cut -d, -f14)
expected_lost=$(echo "$row" | cut -d, -f15)
expected_mean=$(echo "$row" | cut -d, -f11)
expected_samples=$(echo "$row" | cut -d, -f12)
counters=$(grep -E '^ +/rsu/rsu_a_vlp32c/fix +[0-9]' "$work/fuse.txt" | head -1)  # the counters' row, not the consistency table's
applied=$(echo "$counters" | awk '{print $3}')
gated=$(echo "$counters" | awk '{print $4}')
lost=$(grep -E 'rsu_a_vlp32c/addressed_fix .* lost on the emulated link' "$work/fuse.txt" | sed -E 's/.* ([0-9]+) lost on the emulated link.*/\1/')
# The fused error within 50 m of the RSU (30, -7), from coloc fuse's error.csv.
read -r samples mean < <(awk -F, 'NR > 1 { dx = $4 - 30; dy = $5 + 7; if (dx * dx + dy * dy <= 2500) { n++; s += $6 } }
                                 END { printf "%d %.9f\n", n, s / n }' "$work/fuse/error.csv")
echo "experiment: applied $expected_applied, gated $expected_gated, lost $expected_lost, mean $expected_mean m over $expected_samples"
echo "coloc fuse: applied $applied, gated $gated, lost $lost, mean $mean m over $samples"
[ "$applied" = "$expected_applied" ] && [ "$gated" = "$expected_gated" ] && [ "$lost" = "$expected_lost" ] ||
  { echo "FAIL: the fixes differ"; exit 1; }
[ "$samples" = "$expected_samples" ] || { echo "FAIL: a different number of samples within coverage"; exit 1; }
# runs.csv prints six significant digits: equal to them (half a unit in the sixth is 5e-6 of the value).
awk -v a="$mean" -v b="$expected_mean" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 5e-6 * b) }' ||
  { echo "FAIL: the mean error within coverage differs"; exit 1; }
# NDT beside the filter where it was accurate on the noise calibration drive: the configuration names
# that drive's input_error.csv, kept beside its log, and coloc fuse compares on its places.
reference=$(sed -n 's/^ *input_reference: *"\{0,1\}\([^"]*\)"\{0,1\}$/\1/p' "$file")
[ "$reference" = "../../noise_calibration_drive/input_error.csv" ] && [ -s "$(dirname "$file")/$reference" ] ||
  { echo "FAIL: the replay's configuration names '$reference' as the reference drive's errors"; exit 1; }
grep -q '"where_accurate_on_reference"' "$work/fuse/summary.json" || { echo "FAIL: coloc fuse did not compare on the reference's places"; exit 1; }
echo "coloc fuse with the written configuration gave the experiment's replay"
