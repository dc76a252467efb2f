#!/usr/bin/env bash
# ParaView itself opens what basalt-run writes (docs/reliability.md, "ParaView's three XDMF readers"): a short
# run's ckpt_series.xmf and single checkpoints' .xmf, each with XDMFReader, Xdmf3ReaderS and Xdmf3ReaderT
# (tests/paraview/xdmf_readers.py checks time steps, points, cells, arrays and that particles are drawn).
# pvpython comes from Debian's packages unpacked under the build tree (tests/paraview/fetch_pvpython.sh);
# exit 77 (CTest: SKIPPED) when that cannot be done here, or without xvfb-run.
# Environment (tests/paraview/CMakeLists.txt): BASALT_RUN MPIEXEC SCENE GEOMETRY WORK PARAVIEW_DIR.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
W="$WORK"
rm -rf "$W"
mkdir -p "$W"

rc=0
bash "$here/fetch_pvpython.sh" "$PARAVIEW_DIR" || rc=$?
if [ "$rc" -eq 77 ]; then
  echo "SKIPPED: no pvpython here (above)"
  exit 77
elif [ "$rc" -ne 0 ]; then
  exit "$rc"
fi
command -v xvfb-run >/dev/null || {
  echo "SKIPPED: no xvfb-run (package xvfb) to draw in"
  exit 77
}

run() { "$MPIEXEC" -np 2 "$BASALT_RUN" "$SCENE" --geometry "$GEOMETRY" --io-ranks 1 --quiet "$@" >>"$W/run.log" 2>&1 ||
  { cat "$W/run.log"; echo "FAIL: basalt-run $*"; exit 1; }; }
# Two checkpoints, then the vertex file made longer than any checkpoint (as a checkpoint with more particles
# would leave it) and a restart adding a third: every grid then reads the first N of a longer file.
run --steps 100 --checkpoint-every 50 --output "$W/run"
/usr/bin/python3 - "$W/run/xdmf_vertices.h5" <<'PY'
import sys, h5py, numpy as np
with h5py.File(sys.argv[1], "r+") as h:
    n = h["vertices"].shape[0]
    del h["vertices"]
    h["vertices"] = np.arange(2 * n, dtype=np.int64)
PY
run --steps 50 --checkpoint-every 50 --output "$W/run" --restart "$W/run/ckpt_000100.h5"

/usr/bin/python3 "$here/xdmf_readers.py" expect "$W/run" "$W/expected.npz"
source "$PARAVIEW_DIR/env.sh"
xvfb-run -a -s "-screen 0 640x480x24" pvpython --force-offscreen-rendering "$here/xdmf_readers.py" check "$W/run" \
  "$W/expected.npz" "$W/run/ckpt_series.xmf" "$W/run/ckpt_000050.xmf" "$W/run/ckpt_000150.xmf"
