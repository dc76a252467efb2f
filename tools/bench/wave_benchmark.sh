#!/usr/bin/env bash
# The wave benchmark (docs/BENCHMARKS.md): basalt-run on the 15 mm cube (cube1.geo) and a 30 mm cube,
# 1 and 2 ranks, repeated, medians; LAMMPS and ESyS-Particle in the same run when installed; peak
# memory per particle at ~1 M particles. Writes docs/bench/wave.md. Options: see wave_benchmark.py --help.
#   bash tools/bench/wave_benchmark.sh [--repeats 3] [--steps 2000] [--peer-dir DIR] [--no-peers]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
source "$root/scripts/mpi-env.sh"
exec /usr/bin/python3 "$root/tools/bench/wave_benchmark.py" --root "$root" "$@"
