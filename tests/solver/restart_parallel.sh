#!/bin/sh
# Bit-for-bit restart on several ranks (issue #11): a run of 2N steps with checkpoints every N, and a run
# restarted from its step-N checkpoint on the same ranks, must write identical fields.csv rows and a
# byte-identical step-2N checkpoint (h5diff names the datasets when they differ). Pairs between two ranks
# are listed on both, each with its own contact history; the checkpoint must give each rank its own back.
# Usage: restart_parallel.sh MPIEXEC BASALT_RUN SCENE GEOMETRY DIR N NP [basalt-run options...]
#   NP = processes (compute ranks + --io-ranks); e.g. NP 3 with --io-ranks 1 for 2 compute ranks.
set -e
. "$(dirname "$0")/restart_checks.sh"
mpi=$1 run=$2 scene=$3 geo=$4 dir=$5 n=$6 np=$7
shift 7
export HWLOC_COMPONENTS=-gl
rm -rf "$dir" && mkdir -p "$dir/b"
"$mpi" -n "$np" "$run" "$scene" --geometry "$geo" --steps $((2 * n)) --checkpoint-every "$n" --fields-every 10 \
  --output "$dir/a" --quiet "$@" > "$dir/a.log" 2>&1 || { cat "$dir/a.log"; echo "FAIL: the straight run failed"; exit 1; }
seed_restart "$dir/a" "$dir/b" "$n"
"$mpi" -n "$np" "$run" "$scene" --geometry "$geo" --steps "$n" --checkpoint-every "$n" --fields-every 10 \
  --output "$dir/b" --restart "$dir/b" --quiet "$@" > "$dir/b.log" 2>&1 || { cat "$dir/b.log"; echo "FAIL: the restart failed"; exit 1; }
grep -q "continuing from step $n" "$dir/b.log" || { cat "$dir/b.log"; echo "FAIL: the restart did not continue from step $n"; exit 1; }
if grep -q "warning: the checkpoint" "$dir/b.log"; then cat "$dir/b.log"; echo "FAIL: the restart warned that it cannot continue bit for bit"; exit 1; fi
last="ckpt_$(printf %06d $((2 * n))).h5"
status=0
if cmp -s "$dir/a/fields.csv" "$dir/b/fields.csv"; then
  echo "PASS: the restarted run's $(wc -l < "$dir/b/fields.csv") rows equal the uninterrupted run's"
else
  diff "$dir/a/fields.csv" "$dir/b/fields.csv" | head -5
  echo "FAIL: the restarted run's fields.csv differs"
  status=1
fi
if cmp -s "$dir/a/$last" "$dir/b/$last"; then
  echo "PASS: $last is byte-identical to the uninterrupted run's"
else
  h5diff "$dir/a/$last" "$dir/b/$last" | head -12
  echo "FAIL: $last differs from the uninterrupted run's"
  status=1
fi
exit $status
