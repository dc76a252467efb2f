#!/usr/bin/env bash
# basalt-run's sliced restart (each compute rank reads a slice of the checkpoint's rows and the ranks route
# them to their owners, docs/solver.md "Restart") gives the same run, bit for bit, as every rank reading the
# whole checkpoint (--whole-checkpoint): fields.csv and the next checkpoint byte for byte, on NP compute
# ranks, with --io-ranks 0 and 1, for
#   wave      the wave benchmark's scene (bonds, a moving wall);
#   balanced  the same with run.balance = "count" on an uneven packing (the checkpoint's cuts);
#   granular  rotating spheres with friction histories (contact rows);
#   ucs       rotational bonds, some broken before the checkpoint (/bonds/break_position rows).
# No rank reads more than its share of the rows.
# Usage: sliced_restart.sh NP with BASALT_RUN, MPIEXEC, WAVE, CUBE (.geo), GRANULAR, COLUMN (.geo), UCS,
# UCS_GEOMETRY and WORK set by CTest.
set -u
np=$1
W=$WORK/np$np
rm -rf "$W"
mkdir -p "$W"
export HWLOC_COMPONENTS=-gl
fail() { echo "FAIL (np $np): $*"; exit 1; }
run() {  # run NAME RANKS SCENE ARGS...
  local name=$1 ranks=$2 scene=$3; shift 3
  "$MPIEXEC" -np "$ranks" "$BASALT_RUN" "$scene" --quiet --output "$W/$name" "$@" >"$W/$name.log" 2>&1 ||
    { cat "$W/$name.log"; fail "basalt-run $name exited non-zero"; }
}
same() {  # same A B FILE...
  local a=$1 b=$2; shift 2
  for f in "$@"; do
    cmp "$W/$a/$f" "$W/$b/$f" || fail "$a/$f and $b/$f differ"
  done
}
# scenario NAME SCENE GEOMETRY N IO_RANKS_TOO ARGS...: 2N steps with checkpoints every N, then restarts from
# step N (sliced, whole; with IO_RANKS_TOO = 1 also with one I/O rank) compared byte for byte.
scenario() {
  local name=$1 scene=$2 geo=$3 n=$4 io=$5; shift 5
  local c0 c1
  c0=ckpt_$(printf %06d "$n").h5
  c1=ckpt_$(printf %06d $((2 * n))).h5
  run "$name" "$np" "$scene" --geometry "$geo" --steps $((2 * n)) --checkpoint-every "$n" --fields-every 10 "$@"
  local variants="sliced whole"
  [ "$io" = 1 ] && variants="$variants sliced_q1 whole_q1"
  for v in $variants; do
    local d=$name.$v ranks=$np extra=()
    mkdir -p "$W/$d"
    cp "$W/$name/$c0" "$W/$d/"
    head -n $((n / 10 + 1)) "$W/$name/fields.csv" >"$W/$d/fields.csv"
    case $v in *_q1) ranks=$((np + 1)) extra+=(--io-ranks 1) ;; esac
    case $v in whole*) extra+=(--whole-checkpoint) ;; esac
    BASALT_DEBUG_LOAD=1 run "$d" "$ranks" "$scene" --geometry "$geo" --steps "$n" --checkpoint-every "$n" \
      --fields-every 10 --restart "$W/$d/$c0" "${extra[@]}" "$@"
  done
  same "$name.sliced" "$name.whole" fields.csv "$c1"
  [ "$io" = 1 ] && same "$name.sliced_q1" "$name.whole_q1" fields.csv "$c1"
  # The uninterrupted run: told, not required (on more than one rank the granular scene's restart, sliced or
  # whole, differs from it in the last digit, as before the sliced restart).
  if cmp -s "$W/$name/fields.csv" "$W/$name.sliced/fields.csv"; then
    echo "np $np: $name: the restart continues the uninterrupted run bit for bit"
  else
    echo "np $np: $name: note: the restart (sliced and whole alike) differs from the uninterrupted run:"
    diff "$W/$name/fields.csv" "$W/$name.sliced/fields.csv" | head -3
  fi
  # Rows read per rank: its slice (ceil(N / P) particle rows, ceil(M / P) bond rows), never the whole file.
  /usr/bin/python3 - "$W/$name.sliced.log" "$np" <<'PY' || fail "$name: a rank read more than its share"
import math, re, sys
log, p = open(sys.argv[1]).read(), int(sys.argv[2])
rows = re.findall(r"restart: compute rank (\d+) read (\d+) particle rows and (\d+) bond rows of (\d+) and (\d+); "
                  r"holds (\d+) owned particles, (\d+) bonds", log)
assert len(rows) == p, f"{len(rows)} restart lines for {p} ranks"
owned = 0
for r, pr, br, n, m, o, b in (tuple(map(int, x)) for x in rows):
    assert pr <= math.ceil(n / p) and br <= math.ceil(m / p), (r, pr, br, n, m)
    if p > 1:
        assert pr < n and o < n, f"rank {r} read {pr} rows, holds {o} particles of {n}"
    owned += o
assert owned == n, f"owned particles sum to {owned}, not {n}"
PY
  echo "np $np: $name: sliced restart = whole-checkpoint restart, byte for byte (fields.csv, $c1)"
}

scenario wave "$WAVE" "$CUBE" 100 1
# The packing plus one particle far along x (id 10000000): the even grid is uneven, the cuts move.
awk 'NR == 7 { print $1 + 1; next } /^EndParticles/ { print "60 7.5 0.5 0.5 10000000 1" } { print }' "$CUBE" \
  >"$W/uneven.geo"
scenario balanced "$WAVE" "$W/uneven.geo" 100 0 --balance count
# The balanced checkpoint on another rank count (np % 4 + 1): its cuts do not fit, the grid starts even and
# the replayed rebuild re-balances, moving particles to ranks that did not read them (asked of the others).
other=$((np % 4 + 1))
for v in sliced whole; do
  d=balanced.$v.np$other extra=()
  mkdir -p "$W/$d"
  cp "$W/balanced/ckpt_000100.h5" "$W/$d/"
  [ $v = whole ] && extra=(--whole-checkpoint)
  run "$d" "$other" "$WAVE" --geometry "$W/uneven.geo" --balance count --steps 100 --checkpoint-every 100 \
    --fields-every 10 --restart "$W/$d/ckpt_000100.h5" "${extra[@]}"
done
same "balanced.sliced.np$other" "balanced.whole.np$other" fields.csv ckpt_000200.h5
[ "$other" -gt 1 ] && { grep -q "^balance: step" "$W/balanced.sliced.np$other.log" || fail "no re-balance on $other ranks"; }
echo "np $np: balanced checkpoint restarted on $other ranks: sliced = whole, byte for byte"
scenario granular "$GRANULAR" "$COLUMN" 100 0
scenario ucs "$UCS" "$UCS_GEOMETRY" 500 1
# The ucs checkpoint has broken bonds with break positions: the restart routed them with their bonds.
/usr/bin/python3 - "$W/ucs/ckpt_000500.h5" <<'PY' || fail "ucs: no broken bond at the checkpoint"
import sys, h5py
with h5py.File(sys.argv[1]) as f:
    broken = int((f["bonds/broken"][...] != 0).sum())
    assert broken > 0 and f["bonds/break_position"].shape[0] == broken, broken
    print(f"ucs: {broken} broken bonds at the checkpoint")
PY
echo "PASS np $np"
