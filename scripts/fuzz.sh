#!/usr/bin/env bash
# Fuzzes every reader of outside data: builds fuzz/ with clang under AddressSanitizer and
# UndefinedBehaviorSanitizer (build-fuzz/), makes the seed corpora from data/, and runs each target for
# SECONDS (default 60). Fails on any finding (crash, sanitizer report, an exception other than a
# refusal, a hang over 10 s, more than 2 GB); the input that found it is kept in build-fuzz/findings/.
# Prints the executions per target.
set -euo pipefail
seconds=${1:-60}
cd "$(dirname "$0")/.."
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined"
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Debug -DCOLOC_BUILD_FUZZERS=ON \
  -DCOLOC_BUILD_NDT=OFF -DCOLOC_BUILD_ROADSIDE=OFF -DCOLOC_BUILD_SIM=OFF -DCOLOC_BUILD_SMOOTHER=OFF -DCOLOC_BUILD_TESTS=OFF \
  -DCOLOC_BUILD_BENCHMARKS=OFF -DCOLOC_BUILD_TOOLS=OFF \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" > /dev/null
cmake --build build-fuzz -j2 --target coloc_fuzzers
rm -rf build-fuzz/corpus build-fuzz/findings
mkdir -p build-fuzz/findings
build-fuzz/fuzz/make_seeds . build-fuzz/corpus
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for target in mcap_fuzzer sqlite_bag_fuzzer bag_metadata_fuzzer cdr_fuzzer pcd_fuzzer config_fuzzer dds_payload_fuzzer node_interfaces_fuzzer; do
  log=build-fuzz/findings/$target.log
  if build-fuzz/fuzz/$target build-fuzz/corpus/$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -max_len=65536 -print_final_stats=1 -artifact_prefix=build-fuzz/findings/$target- > "$log" 2>&1; then
    echo "fuzz $target: $(sed -n 's/^stat::number_of_executed_units: *//p' "$log") executions in ${seconds} s, no finding"
  else
    status=1
    echo "fuzz $target: FINDING"
    grep -m1 -A30 "ERROR: \|runtime error\|deadly signal\|Timeout\|out-of-memory\|terminate called" "$log" || tail -40 "$log"
    ls build-fuzz/findings/$target-* 2>/dev/null || true
  fi
done
exit $status
