# Sourced by process tests whose DDS discovery multicasts (Fast DDS's and Cyclone's defaults): skips
# (status 77) where the machine allows no network namespace, since multicast must not leave the
# machine; otherwise re-runs the calling script in a namespace of its own with a multicast route on
# its loopback, and gives it a work folder (process_logs.sh).
if [ -z "${COLOC_IN_NETNS:-}" ] && ! unshare -n true 2>/dev/null; then
  echo "SKIP: no network namespace here, and default DDS discovery multicasts: it runs only inside one"
  exit 77
fi
source "$(dirname "${BASH_SOURCE[0]}")/in_network_namespace.sh"
source "$(dirname "${BASH_SOURCE[0]}")/process_logs.sh"
ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo
