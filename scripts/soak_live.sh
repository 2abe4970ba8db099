#!/usr/bin/env bash
# Usage: scripts/soak_live.sh [MINUTES_OF_LOG] [RATE] [SCENARIO]
# Memory of the live node over a long drive (not a CI test): the scenario's drive is simulated once,
# played in a loop at RATE (default 4x) into `coloc localize --use-sim-time` until MINUTES_OF_LOG
# minutes of log (default 30) have gone through, inside a private network namespace. The localizer's
# resident memory (VmRSS) is sampled every 10 s of wall time: soak_rss.csv (wall s, log min, RSS MB) and
# soak_rss.svg in ./soak_out, and the growth after warm-up (the first pass) is printed: the medians of the
# samples' two halves.
set -euo pipefail
minutes=${1:-30}
rate=${2:-4}
root=$(cd "$(dirname "$0")/.." && pwd)
scenario=${3:-$root/config/scenarios/site_a.yaml}
coloc=${COLOC:-$root/build/tools/coloc}
out=$PWD/soak_out
if [ -z "${COLOC_IN_NETNS:-}" ]; then
  exec unshare -n env COLOC_IN_NETNS=1 bash -c 'ip link set lo up && exec "$0" "$@"' "$0" "$minutes" "$rate" "$scenario"
fi
export ROS_LOCALHOST_ONLY=1
mkdir -p "$out"
[ -d "$out/sim/log" ] || "$coloc" simulate "$scenario" --out "$out/sim" > "$out/simulate.txt"
log_seconds=$(awk '/duration:/ { getline; if ($1 == "nanoseconds:") { print $2 / 1e9; exit } }' "$out/sim/log/metadata.yaml")
passes=$(awk -v m="$minutes" -v s="$log_seconds" 'BEGIN { p = int(m * 60 / s) + 1; print (p < 2 ? 2 : p) }')
wall=$(awk -v p="$passes" -v s="$log_seconds" -v r="$rate" 'BEGIN { printf "%d", p * s / r + 60 }')
echo "soak: $passes passes of a $log_seconds s drive at ${rate}x (~$minutes min of log, ~$((wall / 60)) min of wall time)"
"$coloc" localize --map "$out/sim/map" --config "$out/sim/fuse.yaml" --use-sim-time --out "$out/live" --idle-exit 5 --duration "$wall" \
  > "$out/localize.txt" 2>&1 &
localizer=$!
"$coloc" play "$out/sim/log" --delay 3 --rate "$rate" --loop --passes "$passes" > "$out/play.txt" 2>&1 &
player=$!
echo "wall_s,log_min,rss_mb" > "$out/soak_rss.csv"
start=$(date +%s)
while kill -0 "$localizer" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ { print $2 / 1024 }' "/proc/$localizer/status" 2>/dev/null || true)
  [ -n "$rss" ] || break
  t=$(( $(date +%s) - start ))
  echo "$t,$(awk -v t="$t" -v r="$rate" 'BEGIN { printf "%.2f", t * r / 60 }'),$rss" >> "$out/soak_rss.csv"
  printf '\r%6d s  %6.1f MB' "$t" "$rss"
  sleep 10
done
echo
wait "$player" || true
wait "$localizer" || true
# Growth after warm-up (the first pass): RSS swings by some MB within each pass (a restart of the filter,
# map tiles built again), so the two halves of the samples after warm-up are compared by their medians.
warm=$(awk -v s="$log_seconds" -v r="$rate" 'BEGIN { print s / r + 10 }')
awk -F, -v warm="$warm" 'NR > 1 && $1 >= warm { print $3 }' "$out/soak_rss.csv" > "$out/after_warmup"
n=$(wc -l < "$out/after_warmup")
if [ "$n" -lt 4 ]; then
  echo "too short to tell" | tee "$out/soak_summary.txt"
else
  median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
  first=$(head -n $((n / 2)) "$out/after_warmup" | median)
  second=$(tail -n $((n - n / 2)) "$out/after_warmup" | median)
  awk -v a="$first" -v b="$second" -v n="$n" -v m="$minutes" 'BEGIN {
    printf "RSS after warm-up, median of the first half of %d samples %.1f MB, of the second %.1f MB: %+.2f MB over ~%s min of log\n", n, a, b, b - a, m }' |
    tee "$out/soak_summary.txt"
fi
# The same as a plot.
awk -F, -v warm="$warm" 'NR > 1 && $1 >= warm { n++; x[n] = $2; y[n] = $3; if (y[n] > ymax) ymax = y[n]; if (ymin == "" || y[n] < ymin) ymin = y[n]; xmax = x[n] }
  END {
    if (n < 2) exit; if (ymax - ymin < 1) { ymax += 0.5; ymin -= 0.5 }
    printf "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"320\"><rect width=\"640\" height=\"320\" fill=\"white\"/>\n"
    printf "<text x=\"320\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">coloc localize: resident memory over the log played</text>\n"
    printf "<text x=\"320\" y=\"310\" text-anchor=\"middle\" font-size=\"12\">log played (min, after the first pass); RSS %.1f-%.1f MB</text>\n", ymin, ymax
    printf "<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" points=\""
    for (i = 1; i <= n; i++) printf "%.1f,%.1f ", 50 + 570 * x[i] / xmax, 280 - 240 * (y[i] - ymin) / (ymax - ymin)
    printf "\"/></svg>\n" }' "$out/soak_rss.csv" > "$out/soak_rss.svg"
echo "wrote $out/soak_rss.csv, $out/soak_rss.svg"
