#!/usr/bin/env bash
# Usage: ros2_defaults.sh COLOC REGISTRY CYCLONE_PUBLISHER
# A ROS 2 node as rmw_cyclonedds makes it (Eclipse Cyclone DDS with no configuration: its default
# interface, multicast discovery, sensor-data QoS) publishes 10 fixes, and `coloc rsu-listen` with its
# defaults (no interface option) must discover it and accept every one; then the same on the domain
# both take from ROS_DOMAIN_ID. The network is a namespace of its own with a multicast-capable
# interface, the case in which loopback-only discovery fails; default discovery multicasts, so the
# test runs only in such a namespace (skipped where the machine allows none).
set -euo pipefail
coloc=$1
registry=$2
publisher=$3
if [ -z "${COLOC_IN_NETNS:-}" ] && ! unshare -n true 2>/dev/null; then
  echo "SKIP: no network namespace here, and default DDS discovery multicasts: it runs only inside one"
  exit 77
fi
source "$(dirname "$0")/../support/in_network_namespace.sh"
source "$(dirname "$0")/../support/process_logs.sh"
unset ROS_LOCALHOST_ONLY ROS_DOMAIN_ID CYCLONEDDS_URI

# The vehicle network: a veth pair with multicast, its far end inside the namespace too (loopback with
# a multicast route where the kernel has no veth). Either way nothing leaves the namespace.
if ip link add coloc0 type veth peer name coloc1 2>/dev/null; then
  ip addr add 10.77.0.1/24 dev coloc0 && ip link set coloc1 up && ip link set coloc0 up
  ip route add 224.0.0.0/4 dev coloc0
  echo "network: veth coloc0, 10.77.0.1/24, multicast"
else
  ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo
  echo "network: loopback with a multicast route"
fi

exchange() {  # NAME [STATION]: a listener with defaults, the Cyclone node publishing 10 fixes (addressed to STATION, or unaddressed)
  local name=$1 station=${2:-}
  if [ -n "$station" ]; then
    bounded 60 "$work/listen_$name.txt" "$coloc" rsu-listen --registry "$registry" --station-id "$station" --timeout 45 --idle-exit 3 &
  else
    bounded 60 "$work/listen_$name.txt" "$coloc" rsu-listen --registry "$registry" --accept-unaddressed --timeout 45 --idle-exit 3 &
  fi
  local listener=$!
  bounded 40 "$work/cyclone_$name.txt" "$publisher" rsu_a 10 95 -3 0.01486 30 $station
  wait "$listener"
  local accepted
  accepted=$(grep -c ' accepted (variance' "$work/listen_$name.txt" || true)
  echo "$name: the ROS 2 node published 10 fixes, coloc accepted $accepted"
  [ "$accepted" -eq 10 ] || { echo "FAIL ($name): expected 10 accepted fixes, got $accepted"; exit 1; }
}

exchange defaults 7  # addressed fixes, the protocol, as a ROS 2 node publishes them with standard types
grep -q 'domain 0, every interface' "$work/listen_defaults.txt" || { echo "FAIL: coloc did not run on domain 0, every interface"; exit 1; }
export ROS_DOMAIN_ID=42
exchange ros_domain_id  # the unaddressed form, taken with --accept-unaddressed
grep -q 'domain 42, every interface' "$work/listen_ros_domain_id.txt" || { echo "FAIL: coloc did not take ROS_DOMAIN_ID"; exit 1; }
echo "a default ROS 2 node (Cyclone DDS) and coloc's default participant exchanged fixes"
