# Sourced by process tests: re-runs the calling script in a network namespace of its own (only a
# loopback interface, so DDS discovery can reach nothing else), when the machine allows one.
if [ -z "${COLOC_IN_NETNS:-}" ] && unshare -n true 2>/dev/null; then
  exec unshare -n env COLOC_IN_NETNS=1 bash -c 'ip link set lo up && exec "$0" "$@"' "$0" "$@"
fi
