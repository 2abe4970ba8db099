# Sourced by process tests after in_network_namespace.sh: a work folder whose *.txt logs are printed
# if the test fails (so that a failure on a machine we cannot reach says what each process did), and
# `bounded SECONDS LOG CMD...`, which runs CMD with its output in LOG and stops it if it overruns, so a
# stalled process fails the test with its name rather than running into CTest's timeout.
work=$(mktemp -d)
dump_logs_on_failure() {
  local status=$?
  if [ "$status" -ne 0 ]; then
    for f in "$work"/*.txt; do [ -e "$f" ] && { echo "== $(basename "$f")"; cat "$f"; }; done
  fi
  rm -rf "$work"
  return "$status"
}
trap dump_logs_on_failure EXIT
bounded() {
  local seconds=$1 log=$2
  shift 2
  local status=0
  timeout -k 5 "$seconds" "$@" > "$log" 2>&1 || status=$?
  if [ "$status" -eq 124 ] || [ "$status" -eq 137 ]; then
    echo "STALLED: $(basename "$log" .txt) was still running after $seconds s and was stopped" | tee -a "$log"
  fi
  return "$status"
}
