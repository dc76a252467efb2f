#!/bin/sh
# Bit-for-bit restart of a balanced run (run.balance = "count") on 2 ranks: a .geo packing with one
# particle added far away along x (so the even grid is uneven and the first rebuild moves the cuts, bonds
# and all), run 2N steps with a checkpoint at N, and restarted from that checkpoint: identical fields.csv
# rows. The checkpoint must carry the cuts (attribute decomposition_cuts), and the restart must take them
# (no re-balance in its replay of the last rebuild).
# With MODE = pairs (run.balance = "pairs": the first rebuild balances by count, later ones by the lists'
# work) a re-balance after the checkpoint must come at the same step in both runs.
# Usage: restart_balanced.sh MPIEXEC BASALT_RUN SCENE GEO DIR N [MODE]
set -e
. "$(dirname "$0")/restart_checks.sh"
mpi=$1 run=$2 scene=$3 geo=$4 dir=$5 n=$6 mode=${7:-count}
rm -rf "$dir" && mkdir -p "$dir/a" "$dir/b"
# The packing's particles plus one resting on the base at x = 60 (id 10000000).
awk 'NR == 7 { print $1 + 1; next } /^EndParticles/ { print "60 7.5 0.5 0.5 10000000 1" } { print }' "$geo" > "$dir/uneven.geo"
"$mpi" -n 2 "$run" "$scene" --geometry "$dir/uneven.geo" --balance "$mode" --steps $((2 * n)) --checkpoint-every "$n" \
  --fields-every 10 --output "$dir/a" --quiet > "$dir/a.log"
grep -q "^balance: step 0: max/mean particles per rank" "$dir/a.log" || { cat "$dir/a.log"; echo "FAIL: no re-balance at start"; exit 1; }
grep "^balance:" "$dir/a.log"
seed_restart "$dir/a" "$dir/b" "$n"
"$mpi" -n 2 "$run" "$scene" --geometry "$dir/uneven.geo" --balance "$mode" --steps "$n" --checkpoint-every "$n" \
  --fields-every 10 --output "$dir/b" --restart "$dir/b" --quiet > "$dir/b.log"
grep "^balance:" "$dir/b.log"
# The restart takes the checkpoint's cuts: it starts balanced and its replay of the last rebuild does not
# re-balance (without the stored cuts the grid would start even, 2.0, and re-balance there).
after() { awk -v n="$n" '/^balance: step/ { s = $3; sub(":", "", s); if (s + 0 > n) print }' "$1"; }
if [ "$(after "$dir/a.log")" != "$(grep "^balance: step" "$dir/b.log" || true)" ]; then
  echo "FAIL: the restart re-balanced where the uninterrupted run did not: the checkpoint's cuts were not taken"; exit 1
fi
grep -q "^balance: max/mean particles per rank 1.0[0-9]* at start" "$dir/b.log" || { echo "FAIL: the restart did not start balanced"; exit 1; }
same_fields "$dir/a" "$dir/b" "the restarted balanced run"
