#!/usr/bin/env bash
# basalt-run's sliced start-up (each compute rank reads a slice of the geometry's rows, docs/formats.md
# "Start-up") gives the same run, bit for bit, as every rank reading the whole file (--whole-geometry):
# fields.csv and the checkpoint files byte for byte, on 1, 2, 3 and 4 compute ranks, with --io-ranks 0 and 1;
# and no rank reads more than its share of the rows. Usage: sliced_start.sh NP with BASALT_RUN, MPIEXEC,
# SCENE, GEOMETRY (.geo), WORK set by CTest.
set -u
np=$1
W=$WORK/np$np
rm -rf "$W"
mkdir -p "$W"
export HWLOC_COMPONENTS=-gl
fail() { echo "FAIL (np $np): $*"; exit 1; }
run() {  # run NAME RANKS ARGS...
  local name=$1 ranks=$2; shift 2
  "$MPIEXEC" -np "$ranks" "$BASALT_RUN" "$SCENE" --quiet --steps 150 --checkpoint-every 50 --fields-every 1 \
    --output "$W/$name" "$@" >"$W/$name.log" 2>&1 || { cat "$W/$name.log"; fail "basalt-run $name exited non-zero"; }
}
same() {  # same A B
  for f in fields.csv ckpt_000050.h5 ckpt_000100.h5 ckpt_000150.h5; do
    cmp "$W/$1/$f" "$W/$2/$f" || fail "$1/$f and $2/$f differ"
  done
}
# The .geo is converted once (by compute rank 0) to HDF5 in the output folder; both ways read that file.
run geo_sliced "$np" --geometry "$GEOMETRY"
grep -q "converted to" "$W/geo_sliced.log" || true
h5=$W/geo_sliced/$(basename "${GEOMETRY%.*}").from-geo.h5
[ -f "$h5" ] || fail "the .geo was not converted to $h5"
BASALT_DEBUG_LOAD=1 run sliced "$np" --geometry "$h5"
run whole "$np" --geometry "$h5" --whole-geometry
same sliced whole
same sliced geo_sliced
run sliced_q1 $((np + 1)) --geometry "$h5" --io-ranks 1
run whole_q1 $((np + 1)) --geometry "$h5" --io-ranks 1 --whole-geometry
same sliced_q1 whole_q1
# Rows read per rank: its slice (ceil(N / P) particle rows, ceil(M / P) bond rows), never the whole file;
# particles held: owned ones and the far ends of its bonds.
/usr/bin/python3 - "$W/sliced.log" "$np" <<'PY' || fail "a rank read more than its share"
import math, re, sys
log, p = open(sys.argv[1]).read(), int(sys.argv[2])
rows = re.findall(r"load: compute rank (\d+) read (\d+) particle rows and (\d+) bond rows of (\d+) and (\d+); "
                  r"holds (\d+) owned particles, (\d+) far bond ends, (\d+) bonds", log)
assert len(rows) == p, f"{len(rows)} load lines for {p} ranks"
owned = 0
for r, pr, br, n, m, o, far, b in (tuple(map(int, x)) for x in rows):
    assert pr <= math.ceil(n / p) and br <= math.ceil(m / p), (r, pr, br, n, m)
    if p > 1:
        assert pr < n and o + far < n, f"rank {r} holds {pr} rows, {o} + {far} particles of {n}"
    owned += o
    print(f"rank {r}: read {pr}/{n} particle rows, {br}/{m} bond rows; holds {o} owned + {far} far ends")
assert owned == n, f"owned particles sum to {owned}, not {n}"
PY
echo "np $np: sliced start-up = whole-file start-up, byte for byte (fields.csv, 3 checkpoints; Q = 0 and 1; .geo input)"
