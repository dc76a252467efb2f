#!/usr/bin/env bash
# The main job, on a fresh Debian 12 machine: installs what is missing, builds Basalt, packs the
# paper's base cube, runs the wave benchmark with one I/O rank writing checkpoints, and renders
# the wave as four panels (steps 200-800, like the paper's Figure 3) and the kinetic-energy plot.
# Safe to run twice.
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
cmake --build "$build" -j "$(nproc)" --target basalt-pack basalt-run basalt-view basalt-python
# `import basalt` in any new shell (docs/python.md): basalt.pth in the user's site-packages; a failure here
# leaves the demo going (PYTHONPATH=$build/python works too).
"$here/scripts/python-path.sh" "$build" || echo "demo: the Python package is not on python3's path (above); PYTHONPATH=$build/python"
bin="$build/bin"
mkdir -p "$out"

echo "== 1/4 pack the paper's base cube (15 mm, radii 0.2-1.0 mm)"
"$bin/basalt-pack" box --size 15,15,15 --rmin 0.2 --rmax 1.0 --seed 7 -o "$out/cube.h5"

echo "== 2/4 wave benchmark: 1 compute rank + 1 I/O rank, checkpoints every 100 steps"
rm -rf "$out/wave"
mpirun -np 2 "$bin/basalt-run" "$here/scenes/wave.toml" --geometry "$out/cube.h5" --steps "$steps" \
  --io-ranks 1 --checkpoint-every 100 --output "$out/wave"

# A build without VTK (beside Debian's ParaView, README "Without VTK"): basalt-view draws nothing; ParaView reads
# the checkpoints through their XDMF descriptions.
if grep -q '^BASALT_HAS_VTK:INTERNAL=OFF$' "$build/CMakeCache.txt"; then
  echo "== 3/4 and 4/4 left out: this build has no VTK (BASALT_WITH_VTK=OFF), so basalt-view cannot draw"
  echo
  echo "Done. Open $out/wave/ckpt_series.xmf in ParaView (the checkpoints $out/wave/ckpt_*.h5 as a time series)."
  echo "Field series: $out/wave/fields.csv"
  exit 0
fi

echo "== 3/4 render the wave: steps 200, 400, 600, 800, vertical velocity on the cut face, one colour range"
# The default colour range is the 1st-99th percentile of the drawn particles of all four panels.
panels=()
for s in 200 400 600 800; do
  [ -e "$out/wave/ckpt_$(printf %06d "$s").h5" ] && panels+=("$out/wave/ckpt_$(printf %06d "$s").h5")
done
# A run shorter than 200 steps (BASALT_DEMO_STEPS): its last checkpoint alone, if any.
if [ ${#panels[@]} -eq 0 ]; then
  last="$(ls "$out"/wave/ckpt_*.h5 2>/dev/null | tail -n 1 || true)"
  [ -z "$last" ] || panels=("$last")
fi
if [ ${#panels[@]} -gt 0 ]; then
  "$bin/basalt-view" render "${panels[@]}" -o "$out/wave.png" --color velocity_z --cut y --view -y
else
  echo "no checkpoint yet (fewer than 100 steps): no picture"
fi

echo "== 4/4 plot the kinetic energy"
"$bin/basalt-view" plot "$out/wave/fields.csv" -o "$out/kinetic_energy.png"

echo
echo "Done. Pictures:"
echo "  $out/wave.png             vertical velocity at steps 200-800 on the cut face (like the paper's Figure 3)"
echo "  $out/kinetic_energy.png   total kinetic energy against time"
echo "Checkpoints: $out/wave/ckpt_*.h5   field series: $out/wave/fields.csv"
echo "From Python (docs/python.md): /usr/bin/python3 -c 'import basalt; print(basalt.read_checkpoint(\"$out/wave\"))'"
