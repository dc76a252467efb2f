#!/usr/bin/env bash
# The main job, on a fresh Debian 12 machine: installs what is missing, builds Basalt, packs the
# paper's base cube, runs the wave benchmark with one I/O rank writing checkpoints, and renders
# the step-800 picture and the kinetic-energy plot. Safe to run twice.
#   BASALT_DEMO_STEPS   steps to run (default 10000, the paper's benchmark)
#   BASALT_DEMO_OUT     output folder (default ./out)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/install-deps.sh"
source "$here/scripts/mpi-env.sh"

build="${BASALT_BUILD_DIR:-$here/build}"
out="${BASALT_DEMO_OUT:-$here/out}"
steps="${BASALT_DEMO_STEPS:-10000}"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j "$(nproc)" --target basalt-pack basalt-run basalt-view
bin="$build/bin"
mkdir -p "$out"

echo "== 1/4 pack the paper's base cube (15 mm, radii 0.2-1.0 mm)"
"$bin/basalt-pack" box --size 15,15,15 --rmin 0.2 --rmax 1.0 --seed 7 -o "$out/cube.h5"

echo "== 2/4 wave benchmark: 1 compute rank + 1 I/O rank, checkpoints every 100 steps"
rm -rf "$out/wave"
mpirun -np 2 "$bin/basalt-run" "$here/scenes/wave.toml" --geometry "$out/cube.h5" --steps "$steps" \
  --io-ranks 1 --checkpoint-every 100 --output "$out/wave"

echo "== 3/4 render step 800 (speed, cut through the middle)"
"$bin/basalt-view" render "$out/wave/ckpt_000800.h5" -o "$out/wave_step800.png" --color speed --cut y

echo "== 4/4 plot the kinetic energy"
"$bin/basalt-view" plot "$out/wave/fields.csv" -o "$out/kinetic_energy.png"

echo
echo "Done. Pictures:"
echo "  $out/wave_step800.png     particle speeds at step 800 (like the paper's Figure 3)"
echo "  $out/kinetic_energy.png   total kinetic energy against time"
echo "Checkpoints: $out/wave/ckpt_*.h5   field series: $out/wave/fields.csv"
