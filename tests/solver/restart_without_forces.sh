#!/bin/sh
# A velocity-Verlet checkpoint without /particles/force_x ... torque_z (as an older basalt-run wrote it)
# still restarts, with a warning that the continuation agrees with the uninterrupted run to rounding only.
# Usage: restart_without_forces.sh BASALT_RUN SCENE GEOMETRY CHECKPOINT DIR
set -e
run=$1 scene=$2 geo=$3 ckpt=$4 dir=$5
rm -rf "$dir" && mkdir -p "$dir"
cp "$ckpt" "$dir/"
/usr/bin/python3 - "$dir/$(basename "$ckpt")" <<'PY'
import sys
import h5py
with h5py.File(sys.argv[1], "r+") as f:
    names = [n for n in ("force_x", "force_y", "force_z", "torque_x", "torque_y", "torque_z") if n in f["particles"]]
    if len(names) != 6:
        sys.exit(f"FAIL: the checkpoint holds {names}, expected the forces and torques")
    for n in names:
        del f["particles"][n]
PY
"$run" "$scene" --geometry "$geo" --steps 10 --output "$dir" --restart "$dir" --quiet > "$dir/log" 2>&1 || { cat "$dir/log"; echo "FAIL: the restart failed"; exit 1; }
if grep -q "warning: the checkpoint has no /particles/force_x" "$dir/log"; then
  echo "PASS: restarted with the warning"
else
  cat "$dir/log"
  echo "FAIL: no warning that the restart is not bit for bit"
  exit 1
fi
