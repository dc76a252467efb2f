#!/bin/sh
# A granular pile held at rest for 1e7 steps, in double, float and mixed precision, one after the other: its
# kinetic energy and creep (docs/stability.md, "A pile held for 1e7 steps"). One rank; the program is
# tools/bench/pile_drift.cpp.
#   tools/bench/pile_drift.sh [build dir] [steps] [extra pile_drift options, e.g. --side 5 --layers 6]
set -eu
build=${1:-build}
steps=${2:-10000000}
[ $# -ge 2 ] && shift 2 || shift $#
for precision in double float mixed; do
  nice -n 5 "$build/bin/pile_drift" --precision "$precision" --steps "$steps" --every 10000 "$@" |
    if [ "$precision" = double ]; then cat; else tail -n 1; fi
done
