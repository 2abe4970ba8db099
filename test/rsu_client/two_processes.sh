#!/usr/bin/env bash
# Usage: two_processes.sh COLOC REGISTRY
# An RSU process publishes 20 fixes at 20 Hz through an emulated link that loses 25 % of them (seeded),
# plus one fix far outside its coverage; the vehicle process must receive every fix the link let
# through, accept the valid ones and refuse the out-of-coverage one with its reason; the RSU must get
# the vehicle's dimensions, which the vehicle publishes as its CAMs.
set -euo pipefail
coloc=$1
registry=$2
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
# Loopback only, as a ROS 2 node is told with ROS_LOCALHOST_ONLY: nothing leaves the machine.
export ROS_LOCALHOST_ONLY=1
printf '0.00,95,-3\n0.05,96,-3\n0.10,500,500\n' > "$work/extra.csv"

# The listener stops 4 s after the last fix (both publishers have sent by then), or after 60 s.
# Reliable QoS: the losses counted here must be the emulated link's, not best effort's.
bounded 80 "$work/listen.txt" "$coloc" rsu-listen --registry "$registry" --station-id 7 --reliable --timeout 60 --idle-exit 4 --dimensions 7 4.8 1.9 &
listener=$!
bounded 30 "$work/publish.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --generate 20 --rate 20 --loss 0.25 \
  --seed 3 --dimensions
bounded 30 "$work/publish2.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --from "$work/extra.csv"
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
grep -q 'dimensions station 7 length 4.800 width 1.900' "$work/publish.txt" || { echo "FAIL: the RSU got no vehicle dimensions"; exit 1; }
echo "two processes exchanged fixes and dimensions over loopback DDS"
