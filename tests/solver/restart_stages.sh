#!/bin/sh
# Bit-for-bit restart of a staged run (docs/scenes.md, "Stages"): the whole run with checkpoints every N, and a
# run restarted from its step-R checkpoint (R a multiple of N, inside some stage), must write identical
# fields.csv rows and a byte-identical last checkpoint. The restart replays the changes of the stages begun.
# Usage: restart_stages.sh MPIEXEC BASALT_RUN SCENE GEOMETRY DIR N R LAST NP
set -e
. "$(dirname "$0")/restart_checks.sh"
mpi=$1 run=$2 scene=$3 geo=$4 dir=$5 n=$6 r=$7 last=$8 np=$9
export HWLOC_COMPONENTS=-gl
rm -rf "$dir" && mkdir -p "$dir/b"
"$mpi" -n "$np" "$run" "$scene" --geometry "$geo" --checkpoint-every "$n" --fields-every 10 --output "$dir/a" \
  > "$dir/a.log" 2>&1 || { cat "$dir/a.log"; echo "FAIL: the straight run failed"; exit 1; }
seed_restart "$dir/a" "$dir/b" "$r"
"$mpi" -n "$np" "$run" "$scene" --geometry "$geo" --checkpoint-every "$n" --fields-every 10 --output "$dir/b" \
  --restart "$dir/b" > "$dir/b.log" 2>&1 || { cat "$dir/b.log"; echo "FAIL: the restart failed"; exit 1; }
grep -q "continuing from step $r" "$dir/b.log" || { cat "$dir/b.log"; echo "FAIL: the restart did not continue from step $r"; exit 1; }
grep "^stage" "$dir/b.log"
same_fields "$dir/a" "$dir/b"
f="ckpt_$(printf %06d "$last").h5"
if cmp -s "$dir/a/$f" "$dir/b/$f"; then
  echo "PASS: $f is byte-identical to the uninterrupted run's"
else
  h5diff "$dir/a/$f" "$dir/b/$f" | head -12
  echo "FAIL: $f differs from the uninterrupted run's"
  exit 1
fi
