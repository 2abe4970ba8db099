# Sourced by the process tests that simulate a scenario and fuse it: COLOC and SCENARIO from the
# arguments, a work directory removed on exit, the drive simulated into $work/sim, and mean_of to read
# a mean error from `coloc fuse`'s report.
set -euo pipefail
coloc=$1
scenario=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$coloc" simulate "$scenario" --out "$work/sim" > /dev/null
# mean_of PATTERN FILE: the mean of the report line matching PATTERN ("position error vs ground truth",
# "ndt  .*its own poses"), in metres.
mean_of() { sed -n "/$1/ s/.*mean \([0-9.]*\) m, RMSE.*/\1/p" "$2"; }
