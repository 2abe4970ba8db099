#!/usr/bin/env bash
# Usage: two_processes.sh COLOC REGISTRY
# An RSU process publishes 20 fixes at 20 Hz through an emulated link that loses 25 % of them (seeded),
# plus one fix far outside its coverage; the vehicle process must receive every fix the link let
# through, accept the valid ones, refuse the out-of-coverage one with its reason, and get the vehicle
# dimensions.
set -euo pipefail
coloc=$1
registry=$2
if [ -z "${COLOC_IN_NETNS:-}" ] && unshare -n true 2>/dev/null; then
  exec unshare -n env COLOC_IN_NETNS=1 bash -c 'ip link set lo up && exec "$0" "$@"' "$0" "$@"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf '0.00,95,-3\n0.05,96,-3\n0.10,500,500\n' > "$work/extra.csv"

"$coloc" rsu-listen --registry "$registry" --timeout 12 --dimensions > "$work/listen.txt" 2>&1 &
listener=$!
"$coloc" rsu-publish --registry "$registry" --rsu rsu_a --generate 20 --rate 20 --loss 0.25 --seed 3 \
  --dimensions 7 4.8 1.9 > "$work/publish.txt" 2>&1
"$coloc" rsu-publish --registry "$registry" --rsu rsu_a --from "$work/extra.csv" > "$work/publish2.txt" 2>&1
wait "$listener"
cat "$work/publish.txt" "$work/publish2.txt" "$work/listen.txt"

sent=$(sed -n 's/^published \([0-9]*\) fixes.*/\1/p' "$work/publish.txt")
dropped=$(sed -n 's/.* \([0-9]*\) dropped by the emulated link/\1/p' "$work/publish.txt")
accepted=$(grep -c ' accepted (variance' "$work/listen.txt" || true)
refused=$(grep -c 'rejected (out_of_coverage)' "$work/listen.txt" || true)
echo "sent=$sent dropped=$dropped accepted=$accepted refused_out_of_coverage=$refused"
[ "$((sent + dropped))" -eq 20 ] || { echo "FAIL: the publisher did not account for all 20 fixes"; exit 1; }
[ "$dropped" -gt 0 ] || { echo "FAIL: a 25 % lossy link lost nothing"; exit 1; }
[ "$accepted" -eq "$((sent + 2))" ] || { echo "FAIL: expected $((sent + 2)) accepted fixes, got $accepted"; exit 1; }
[ "$refused" -eq 1 ] || { echo "FAIL: the out-of-coverage fix was not refused"; exit 1; }
grep -q 'dimensions station 7 length 4.800 width 1.900' "$work/listen.txt" || { echo "FAIL: no vehicle dimensions"; exit 1; }
echo "two processes exchanged fixes and dimensions over loopback DDS"
