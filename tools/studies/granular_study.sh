#!/bin/sh
# The granular speed-against-accuracy study of docs/accuracy.md ("Granular: the column collapse"), issue 46:
# basalt-study on scenes/column-collapse.toml with its own geometry (the 10 x 8 x 10 column of the scene's header,
# 551 grains), 8,000 steps of the scene's dt (t = 0 .. 20), contact stiffness x 1 .. 1e-3, dt fraction 0.05 .. 1,
# double and float, against a double reference at dt fraction 0.02 and 4 perturbed references.
#   sh tools/studies/granular_study.sh [BUILD_DIR] [OUT_DIR] [STEPS]   (2-4 min on 2 shared cores)
# Writes OUT_DIR (default out/study-column-collapse): table.md, study.json, study.png, setting.toml. STEPS (8000)
# is the window; docs/accuracy.md shows 8000 (t = 20, the deposit) and 2000 (t = 5, the flow at its fastest).
set -e
build=${1:-build}
out=${2:-out/study-column-collapse}
steps=${3:-8000}
cd "$(dirname "$0")/../.."
. scripts/mpi-env.sh
geometry=out/column-collapse/a1/column.h5
if [ ! -f "$geometry" ]; then
  mkdir -p "$(dirname "$geometry")"
  "$build/bin/basalt-pack" box --size 10,8,10 --rmin 0.4 --rmax 0.6 --no-bonds --seed 1 -o "$geometry" -q
fi
"$build/bin/basalt-study" scenes/column-collapse.toml --steps "$steps" \
  -q fields.kinetic_energy:max -q checkpoint.position.x:mean -q checkpoint.position.x:p99 \
  -q checkpoint.position.z:p99 \
  --precision double,float --dt-fraction 0.05,0.1,0.2,0.4,0.8,1.0 --stiffness 1,0.1,0.01,0.001 \
  --ensemble 4 --budget 1e-2 -o "$out"
