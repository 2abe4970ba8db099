#!/usr/bin/env bash
# Usage: security.sh COLOC REGISTRY MAKE_SECURITY_SCRIPT
# DDS Security end to end: openssl makes a road operator's CA, an RSU, the vehicle and two intruders.
# The vehicle listens with security on. The RSU's fixes must arrive; none from the intruders may:
# one has a certificate from a CA the vehicle does not trust, one is trusted but not permitted to
# publish fixes, and a third sends with security off.
set -euo pipefail
coloc=$1
registry=$2
make_security=$3
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
# Loopback only, as a ROS 2 node is told with ROS_LOCALHOST_ONLY: nothing leaves the machine.
export ROS_LOCALHOST_ONLY=1
"$make_security" "$work/sec" rsu_a rsu_b > /dev/null
# Intruders send from x = 999 so that any of their fixes that got through would stand out.
printf '0.0,999,0\n0.1,999,0\n0.2,999,0\n0.3,999,0\n' > "$work/intruder.csv"

# The listener stops 8 s after the RSU's last fix (the intruders have tried by then), or after 60 s.
bounded 80 "$work/listen.txt" "$coloc" rsu-listen --registry "$registry" --station-id 7 --reliable --security "$work/sec" --name vehicle \
  --timeout 60 --idle-exit 8 &
listener=$!
bounded 30 "$work/rsu.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --generate 6 --rate 10 --security "$work/sec"
# The rogue intruder sends without waiting for a match (it will never get one).
bounded 20 "$work/rogue.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --name intruder_rogue \
  --security "$work/sec/rogue" --from "$work/intruder.csv" --wait-subscribers 0 || true
bounded 20 "$work/listed.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --name intruder_listed \
  --security "$work/sec" --from "$work/intruder.csv" --wait-subscribers 0 || true
bounded 20 "$work/plain.txt" "$coloc" rsu-publish --registry "$registry" --station-id 7 --reliable --rsu rsu_a --name plain \
  --from "$work/intruder.csv" --wait-subscribers 0 || true
wait "$listener"
for f in rsu rogue listed plain listen; do echo "== $f"; grep -v 'SECURITY\|DATA_WRITER\|Function' "$work/$f.txt" || true; done

accepted=$(grep -c ' accepted (variance' "$work/listen.txt" || true)
intruding=$(grep -c 'x=999' "$work/listen.txt" || true)
echo "accepted=$accepted intruder_fixes_received=$intruding"
grep -q 'DDS Security on' "$work/listen.txt" || { echo "FAIL: the listener did not run with security"; exit 1; }
[ "$accepted" -eq 6 ] || { echo "FAIL: expected the RSU's 6 fixes, got $accepted"; exit 1; }
[ "$intruding" -eq 0 ] || { echo "FAIL: intruder fixes reached the vehicle"; exit 1; }
grep -q 'not permitted' "$work/listed.txt" || { echo "FAIL: the unpermitted intruder was allowed to create a writer"; exit 1; }
echo "the RSU's fixes arrived under DDS Security; no intruder fix did"
