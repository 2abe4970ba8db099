#!/usr/bin/env bash
# Sets up a fresh Debian bookworm machine for coloc, builds it, and runs the main job on built-in
# defaults. Re-running it is cheap: packages already present are skipped, the build is incremental.
set -euo pipefail
cd "$(dirname "$0")"

packages=(
  build-essential cmake pkg-config ccache
  libeigen3-dev
  libfastcdr-dev libfastrtps-dev fastddsgen
  libsqlite3-dev libzstd-dev liblz4-dev libyaml-cpp-dev openssl iproute2
  libcli11-dev nlohmann-json3-dev
  libpcl-dev libembree-dev libceres-dev libabsl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  cyclonedds-dev cyclonedds-tools
)
missing=()
for p in "${packages[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if ((${#missing[@]})); then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "coloc setup: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2

# The main job on built-in defaults: the paper's experiment on the digital twin in quick mode, a first
# look (Table I on every site, one trial; `coloc experiment` without --quick runs the full ten trials,
# the whole network grid and the RSU calibration study).
build/tools/coloc experiment --quick --out results/experiment
