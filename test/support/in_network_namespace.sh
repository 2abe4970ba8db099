# Sourced by process tests: re-runs the calling script in a network namespace of its own (only a
# loopback interface, so DDS discovery can reach nothing else), when the machine allows one. Fast
# DDS's shared-memory transport meets the participants of every namespace in /dev/shm, so where the
# machine also allows a mount namespace the script gets a /dev/shm of its own: nothing another test
# runs at the same time can reach it (test/CMakeLists.txt lets such tests run side by side).
if [ -z "${COLOC_IN_NETNS:-}" ]; then
  if unshare -n -m sh -c 'mount -t tmpfs tmpfs /dev/shm' 2>/dev/null; then
    exec unshare -n -m env COLOC_IN_NETNS=1 bash -c 'mount -t tmpfs tmpfs /dev/shm && ip link set lo up && exec "$0" "$@"' "$0" "$@"
  elif unshare -n true 2>/dev/null; then
    exec unshare -n env COLOC_IN_NETNS=1 bash -c 'ip link set lo up && exec "$0" "$@"' "$0" "$@"
  fi
fi
