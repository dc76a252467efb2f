#!/bin/sh
# basalt-run's per-rank timing summary shows a rank that does all the work: a .geo packing with one particle
# added far away along x, so that the even 2-rank grid (run.balance = "none") leaves rank 1 one particle and
# rank 0 all the others. The summary must name rank 0 the slowest (close to 2x the ranks' mean compute
# time: the other rank computes next to nothing) and rank 1 the one that waits most; its max column must be
# the "time per step" line's (the max over the ranks); and a 1-rank run prints no such lines. The phases are
# wall-clock times: on a loaded machine a preempted rank's phase grows (ctest runs this test alone).
# Usage: rank_spread.sh MPIEXEC BASALT_RUN SCENE GEO DIR STEPS
set -e
mpi=$1 run=$2 scene=$3 geo=$4 dir=$5 n=$6
rm -rf "$dir" && mkdir -p "$dir"
awk 'NR == 7 { print $1 + 1; next } /^EndParticles/ { print "60 7.5 0.5 0.5 10000000 1" } { print }' "$geo" > "$dir/uneven.geo"
"$mpi" -n 2 "$run" "$scene" --geometry "$dir/uneven.geo" --dims 2,1,1 --steps "$n" --output "$dir/np2" > "$dir/np2.log"
grep "^time per step\|^slowest rank" "$dir/np2.log"
line=$(grep "^slowest rank:" "$dir/np2.log") || { cat "$dir/np2.log"; echo "FAIL: no slowest-rank line at 2 ranks"; exit 1; }
echo "$line" | awk '{
  if ($3 != 0) { print "FAIL: rank 0 holds all particles but one, the slowest named is " $3; exit 1 }
  x = $9; sub(/x$/, "", x)
  if (x + 0 < 1.2) { print "FAIL: rank 0 computes " x "x the mean, expected close to 2 (1.3 and more with a core taken by another job)"; exit 1 }
  if ($14 != 1) { print "FAIL: rank 1 waits for rank 0 every step, the one named is " $14; exit 1 }
}'
forces_max=$(sed -n 's/^time per step: forces \([0-9.]*\) ms.*/\1/p' "$dir/np2.log")
spread_max=$(sed -n 's/^time per step by rank (min \/ mean \/ max): forces [0-9.]* \/ [0-9.]* \/ \([0-9.]*\) ms.*/\1/p' "$dir/np2.log")
[ -n "$forces_max" ] && [ "$forces_max" = "$spread_max" ] ||
  { echo "FAIL: forces max by rank '$spread_max' is not the time per step line's '$forces_max'"; exit 1; }
"$mpi" -n 1 "$run" "$scene" --geometry "$dir/uneven.geo" --steps 10 --output "$dir/np1" > "$dir/np1.log"
if grep -q "^time per step by rank\|^slowest rank" "$dir/np1.log"; then
  echo "FAIL: a 1-rank run printed the per-rank lines"; exit 1
fi
echo "PASS: the per-rank summary names rank 0 (all the work) the slowest and rank 1 the waiting one"
