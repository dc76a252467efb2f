#!/usr/bin/env bash
# Restart cost, sliced against whole-checkpoint (docs/BENCHMARKS.md "Restart"): the wall time of a one-step
# restart of the wave scene on a 60 mm cube (the slowest rank's, /usr/bin/time -v: the whole process, reading
# included), the start-up basalt-run prints (from the split into compute ranks to the first step: it leaves
# out the whole-checkpoint path's reading, done before) and every rank's peak RSS, at 2 and 4 compute ranks
# (--io-ranks 0), sliced (the default) and --whole-checkpoint interleaved.
#   bash tools/bench/restart_bench.sh [--build build] [--work /tmp/s2] [--repeats 2] [--np "2 4"]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
source "$root/scripts/mpi-env.sh"
build=$root/build work=/tmp/s2 repeats=2 nps="2 4"
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --np) nps=$2; shift 2 ;;
    *) echo "restart_bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
run=$build/bin/basalt-run
mkdir -p "$work"
cube=$work/cube60.h5
if [ ! -f "$cube" ]; then
  echo "packing $cube"
  "$build/bin/basalt-pack" box --size 60,60,60 --rmin 0.2 --rmax 1.0 --exponent 2.2 --fill -o "$cube"
fi
ckpt=$work/ckpt60/ckpt_000020.h5
if [ ! -f "$ckpt" ]; then
  echo "writing $ckpt"
  mpirun -np 2 "$run" "$root/scenes/wave.toml" --geometry "$cube" --steps 20 --checkpoint-every 20 \
    --fields-every 0 --output "$work/ckpt60" --quiet
fi
echo "$(date -u '+%Y-%m-%d %H:%M UTC'); load average $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores"
echo "checkpoint: $ckpt ($(du -m "$ckpt" | cut -f1) MB)"
printf '%-3s %-7s %-6s %8s %12s %28s\n' np mode repeat "wall s" "start-up s" "peak RSS per rank MB"
for np in $nps; do
  for ((k = 1; k <= repeats; ++k)); do
    for mode in sliced whole; do
      extra=()
      [ "$mode" = whole ] && extra=(--whole-checkpoint)
      log=$work/restart.$mode.np$np.$k.log
      cmd=(mpirun -np "$np" /usr/bin/time -v "$run" "$root/scenes/wave.toml" --restart "$ckpt" --steps 1
        --checkpoint-every 0 --fields-every 0 --frames-every 0 --io-ranks 0 --quiet --output "$work/out.$mode"
        "${extra[@]}")
      [ "$np$k$mode" = "21sliced" ] && echo "command: ${cmd[*]}"
      "${cmd[@]}" >"$log" 2>&1 || { cat "$log"; exit 1; }
      startup=$(sed -n 's/.*start-up \([0-9.]*\) s.*/\1/p' "$log")
      rss=$(sed -n 's/.*Maximum resident set size (kbytes): \([0-9]*\)/\1/p' "$log" | sort -n |
        awk '{printf "%s%d", (NR > 1 ? " " : ""), $1 / 1024}')
      wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): \(.*\)/\1/p' "$log" |
        awk -F: '{s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; if (s > m) m = s} END {printf "%.1f", m}')
      printf '%-3s %-7s %-6s %8s %12s %28s\n' "$np" "$mode" "$k" "$wall" "$startup" "$rss"
    done
  done
done
