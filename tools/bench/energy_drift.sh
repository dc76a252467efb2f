#!/bin/sh
# The energy drift of a closed bonded block over 1e7 steps, double and float, bonds alone and bonds with
# contacts, with the net momentum removed ("at rest") and as drawn ("drifting") (docs/stability.md, "Energy
# drift over 1e7 steps"). One rank, eight rows of about 1.5 minutes each.
#   tools/bench/energy_drift.sh [build dir] [geometry] [steps]
set -eu
build=${1:-build}
root=$(cd "$(dirname "$0")/../.." && pwd)
geometry=${2:-${BASALT_REFERENCE_DIR:-$root/tests/data}/cube1.geo}
steps=${3:-10000000}
exec nice -n 5 "$build/bin/energy_drift" --geometry "$geometry" --steps "$steps" --every 10000
