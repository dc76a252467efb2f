#!/bin/sh
# Bit-for-bit restart of a granular run (rotation, friction history, ESyS damping): a run of 2N steps
# with a checkpoint at N, and a run restarted from that checkpoint, must write identical fields.csv rows.
# Usage: restart_granular.sh BASALT_RUN SCENE GEOMETRY DIR N
set -e
. "$(dirname "$0")/restart_checks.sh"
run=$1 scene=$2 geo=$3 dir=$4 n=$5
rm -rf "$dir" && mkdir -p "$dir"
"$run" "$scene" --geometry "$geo" --steps $((2 * n)) --checkpoint-every "$n" --fields-every 10 --output "$dir/a" --quiet >/dev/null
seed_restart "$dir/a" "$dir/b" "$n"
"$run" "$scene" --geometry "$geo" --steps "$n" --checkpoint-every "$n" --fields-every 10 --output "$dir/b" --restart "$dir/b" --quiet >/dev/null
# Where the broken bonds broke (/bonds/break_position, for pictures of cracks) survives the restart: the
# final checkpoints list the same broken bonds at the same positions, those restored from the checkpoint
# as well as those that broke after it.
last="ckpt_$(printf %06d $((2 * n))).h5"
if h5ls "$dir/a/$last/bonds/break_position" >/dev/null 2>&1; then
  for ds in /bonds/broken /bonds/break_position; do
    if ! h5diff "$dir/a/$last" "$dir/b/$last" "$ds" >/dev/null 2>&1; then
      echo "FAIL: $ds of $last differs after the restart"
      exit 1
    fi
  done
  echo "PASS: $last's /bonds/broken and /bonds/break_position equal the uninterrupted run's"
fi
same_fields "$dir/a" "$dir/b"
