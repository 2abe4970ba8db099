#!/usr/bin/env bash
# Usage: input_reference.sh COLOC SCENARIO
# `coloc fuse` with replay.input_reference: the filter beside NDT also where NDT was accurate on a
# reference drive over the same road (another seed of the scenario), which carries no luck of the drive
# compared. With the drive itself as its reference every place chosen has NDT under 2 cm, so NDT's mean
# over those places is too. A reference that is missing, lacks a column or holds a field that is not a
# number stops the replay with the file, line and column named.
set -euo pipefail
coloc=$1
scenario=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's/^seed: 1$/seed: 2/' "$scenario" > "$work/reference.yaml"
grep -q '^seed: 2$' "$work/reference.yaml" || { echo "FAIL: the scenario has no 'seed: 1' line to change"; exit 1; }
"$coloc" simulate "$work/reference.yaml" --out "$work/ref" > /dev/null
"$coloc" simulate "$scenario" --out "$work/drive" > /dev/null
"$coloc" fuse "$work/ref/log" --map "$work/ref/map" --config "$work/ref/fuse.yaml" --out "$work/ref_fused" > /dev/null
[ -s "$work/ref_fused/input_error.csv" ] || { echo "FAIL: no input_error.csv for the reference drive"; exit 1; }
# reference FUSE_YAML CSV: FUSE_YAML with replay.input_reference set to CSV (relative to the config's folder).
reference() { cat "$1"; printf 'replay:\n  input_reference: %s\n' "$2"; }
grep -q '^replay:' "$work/drive/fuse.yaml" && { echo "FAIL: fuse.yaml has a replay section already"; exit 1; }
reference "$work/drive/fuse.yaml" ../ref_fused/input_error.csv > "$work/drive/with_reference.yaml"
"$coloc" fuse "$work/drive/log" --map "$work/drive/map" --config "$work/drive/with_reference.yaml" --out "$work/fused" > "$work/fused.txt"
# python-free JSON reading: the summary is pretty-printed, one key per line.
field() { sed -n "/\"where_accurate_on_reference\"/,/}/ s/.*\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -1; }
samples=$(field samples "$work/fused/summary.json")
mean=$(field input_mean_m "$work/fused/summary.json")
file=$(field file "$work/fused/summary.json")
all=$(sed -n '/"fused_at_stamps"/,/}/ s/.*"samples": *\([0-9]*\).*/\1/p' "$work/fused/summary.json" | head -1)
echo "another drive's places: $samples of $all NDT poses, NDT's mean there $mean m (reference $file)"
[ -n "$samples" ] && [ -n "$all" ] && [ "$samples" -gt 0 ] && [ "$samples" -le "$all" ] || { echo "FAIL: no pose compared on the reference's places"; exit 1; }
[ "$file" = "$work/ref_fused/input_error.csv" ] || { echo "FAIL: the reference is reported as '$file', not resolved beside the config"; exit 1; }
grep -q 'where it was accurate on the reference drive' "$work/fused.txt" || { echo "FAIL: coloc fuse does not print the comparison"; exit 1; }
# The drive as its own reference.
reference "$work/ref/fuse.yaml" "$work/ref_fused/input_error.csv" > "$work/ref/itself.yaml"
"$coloc" fuse "$work/ref/log" --map "$work/ref/map" --config "$work/ref/itself.yaml" --out "$work/itself" > /dev/null
self=$(field input_mean_m "$work/itself/summary.json")
echo "the drive's own places: NDT's mean there $self m"
awk -v m="$self" 'BEGIN { exit !(m > 0 && m < 0.02) }' || { echo "FAIL: on places the drive itself chose, NDT's mean is $self m, not under 0.02"; exit 1; }
# Bad references.
refused() {  # refused NAME CSV_PATH EXPECTED_TEXT
  reference "$work/drive/fuse.yaml" "$2" > "$work/drive/bad.yaml"
  if "$coloc" fuse "$work/drive/log" --map "$work/drive/map" --config "$work/drive/bad.yaml" --out "$work/bad_$1" > "$work/bad_$1.txt" 2>&1; then
    echo "FAIL: a reference $1 was taken"; exit 1
  fi
  grep -qF "$3" "$work/bad_$1.txt" || { echo "FAIL: a reference $1: '$(cat "$work/bad_$1.txt")' does not say '$3'"; exit 1; }
}
refused missing "$work/none.csv" "$work/none.csv: cannot be read"
cut -d, -f1,2,3,4,5,7 "$work/ref_fused/input_error.csv" > "$work/no_truth_y.csv"
refused "without truth_y" "$work/no_truth_y.csv" "no column truth_y"
awk -F, -v OFS=, 'NR == 3 { $7 = "1.2.3" } { print }' "$work/ref_fused/input_error.csv" > "$work/garbled.csv"
refused garbled "$work/garbled.csv" "garbled.csv:3: error_m: '1.2.3' is not a finite number"
awk -F, -v OFS=, 'NR == 4 { $7 = "-0.01" } { print }' "$work/ref_fused/input_error.csv" > "$work/negative.csv"
refused "with a negative error" "$work/negative.csv" "negative.csv:4: error_m: -0.01 is negative"
echo "the reference's places are compared, reported and resolved beside the config; bad references are refused by name"
