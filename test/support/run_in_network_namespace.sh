#!/usr/bin/env bash
# Usage: run_in_network_namespace.sh PROGRAM [ARGS...]
# Runs a program that talks DDS in a network namespace of its own (only a loopback interface) when the
# machine allows one, so that nothing it sends can leave the machine.
set -euo pipefail
source "$(dirname "$0")/in_network_namespace.sh"
exec "$@"
