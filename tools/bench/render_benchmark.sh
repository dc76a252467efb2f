#!/usr/bin/env bash
# Times `basalt-view render` on cube1.geo tiled to ~1.1 M particles (and the 8,948-particle cube as
# the baseline measured in the same run), for both sphere mappers, REPEATS times each; prints the
# median wall time. Usage: tools/bench/render_benchmark.sh [BUILD_DIR] [REPEATS]
# The machine is shared: read the ratios, and repeat.
set -euo pipefail
# One Xvfb for every run, so that its start-up is not timed: run this script itself under xvfb-run.
if [ -z "${DISPLAY:-}" ]; then
  exec xvfb-run -a -s "-screen 0 1920x1200x24" "$0" "$@"
fi
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
repeats="${2:-3}"
view="$build/bin/basalt-view"
tile="$build/tools/bench/basalt-tile-frame"
geo="${BASALT_REFERENCE_DIR:-$root/tests/data}/cube1.geo"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

"$tile" "$geo" 1 "$work/tile1.vtp" >/dev/null
"$tile" "$geo" 5 "$work/tile5.vtp" >/dev/null

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

run_all() {
  printf "%-7s %-15s %9s %9s %9s %9s  %s\n" frame mode drawn "wall [s]" "read [s]" "draw [s]" "(median of $repeats)"
  for frame in tile1 tile5; do
    for mode in imposter imposter-all glyph glyph-all; do
      mapper="${mode%-all}"
      extra=""
      [ "$mode" != "$mapper" ] && extra="--all"
      walls=() ; reads=() ; draws=()
      for ((r = 0; r < repeats; r++)); do
        start=$(date +%s.%N)
        line=$("$view" render "$work/$frame.vtp" -o "$work/$frame-$mode.png" --color speed --cut x --mapper "$mapper" $extra)
        end=$(date +%s.%N)
        walls+=("$(echo "$end - $start" | bc -l)")
        reads+=("$(echo "$line" | sed -E 's/.*read ([0-9.]+) s.*/\1/')")
        draws+=("$(echo "$line" | sed -E 's/.*draw ([0-9.]+) s.*/\1/')")
      done
      drawn=$(echo "$line" | sed -E 's/.* ([0-9]+) drawn.*/\1/')
      printf "%-7s %-15s %9s %9.2f %9.2f %9.2f\n" "$frame" "$mode" "$drawn" \
        "$(printf '%s\n' "${walls[@]}" | median)" "$(printf '%s\n' "${reads[@]}" | median)" \
        "$(printf '%s\n' "${draws[@]}" | median)"
    done
  done
}

run_all
echo "particles: tile1 = $(grep -ao 'NumberOfPoints="[0-9]*' "$work/tile1.vtp" | head -1 | cut -d'"' -f2), tile5 = $(grep -ao 'NumberOfPoints="[0-9]*' "$work/tile5.vtp" | head -1 | cut -d'"' -f2)"
