#!/usr/bin/env bash
# Usage: simulate_and_fuse.sh COLOC SCENARIO
# The twin end to end: simulate twice with the same seed (the logs must be identical), then replay the
# log through NDT, the RSU's fixes and odometry, scored against the recorded ground truth.
set -euo pipefail
coloc=$1
scenario=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$coloc" simulate "$scenario" --out "$work/a" --delay 0.01 --loss 0.1
"$coloc" simulate "$scenario" --out "$work/b" --delay 0.01 --loss 0.1 > /dev/null
cmp "$work/a/log/log_0.db3" "$work/b/log/log_0.db3" || { echo "FAIL: the same seed gave different logs"; exit 1; }
cmp "$work/a/rsu_fixes.csv" "$work/b/rsu_fixes.csv" >/dev/null 2>&1 || true  # processing times are measured, not simulated
"$coloc" fuse "$work/a/log" --map "$work/a/map" --config "$work/a/fuse.yaml" --out "$work/fused" | tee "$work/fuse.txt"
grep -q '/rsu/rsu_a/addressed_fix .* rsu_fix' "$work/fuse.txt" || { echo "FAIL: no addressed RSU fixes in the log"; exit 1; }
grep -q 'RSU rsu_a: [1-9][0-9]* fixes received; refused by the checks: .*; passed [1-9][0-9]*; the filter applied [1-9]' "$work/fuse.txt" ||
  { echo "FAIL: the fixes did not pass the registry's checks and reach the filter"; exit 1; }
grep -q 'NDT: [0-9]* scans -> [1-9]' "$work/fuse.txt" || { echo "FAIL: NDT produced no pose"; exit 1; }
grep -q 'position error vs ground truth' "$work/fuse.txt" || { echo "FAIL: no error against ground truth"; exit 1; }
mean=$(sed -n '/position error vs ground truth/ s/.*mean \([0-9.]*\) m, RMSE.*/\1/p' "$work/fuse.txt")
awk -v m="$mean" 'BEGIN { exit !(m < 1.0) }' || { echo "FAIL: mean error $mean m"; exit 1; }
echo "simulated twice identically and fused: mean error $mean m"

# The same log smoothed: every measurement at once must beat the causal filter clearly.
"$coloc" smooth "$work/a/log" --map "$work/a/map" --config "$work/a/fuse.yaml" --out "$work/smoothed" | tee "$work/smooth.txt"
grep -q 'Termination: CONVERGENCE' "$work/smooth.txt" || { echo "FAIL: the smoother did not converge"; exit 1; }
read -r filter smoothed < <(sed -n 's/.*filter mean \([0-9.]*\) m .*smoother mean \([0-9.]*\) m .*/\1 \2/p' "$work/smooth.txt")
awk -v f="$filter" -v s="$smoothed" 'BEGIN { exit !(s <= 0.8 * f) }' || { echo "FAIL: smoother $smoothed m against filter $filter m"; exit 1; }
echo "smoothed: $smoothed m against the filter's $filter m"

# Fixed lag: two-second windows behind the filter, each from the filter's state at its start, must not
# be worse than the filter they follow.
"$coloc" smooth "$work/a/log" --map "$work/a/map" --config "$work/a/fuse.yaml" --window 2 --out "$work/fixed_lag" | tee "$work/fixed_lag.txt"
grep -q 'fixed lag: [1-9][0-9]* windows of 2.0 s' "$work/fixed_lag.txt" || { echo "FAIL: no fixed-lag windows"; exit 1; }
read -r filter lagged < <(sed -n 's/.*filter mean \([0-9.]*\) m .*smoother mean \([0-9.]*\) m .*/\1 \2/p' "$work/fixed_lag.txt")
awk -v f="$filter" -v s="$lagged" 'BEGIN { exit !(s <= f) }' || { echo "FAIL: fixed lag $lagged m against the filter's $filter m"; exit 1; }
echo "fixed lag: $lagged m against the filter's $filter m"
