#!/bin/bash
# Two basalt-run builds on one scene, back to back on one core: the A/B check of a change's speed on a
# shared, noisy host (docs/BENCHMARKS.md, "No branch per row"). Each repeat runs A then B (B then A on
# even repeats) with the same steps; the time is the loop's own ("done: N steps in T s"). Prints each
# repeat's ratio B/A and their median, which the host's drift between repeats moves far less than the
# times themselves.
#
#   source scripts/mpi-env.sh
#   bash tools/bench/scene_ab.sh --scene W/bench.toml --steps 300 --repeats 20 OLD/bin/basalt-run NEW/bin/basalt-run
#
# The scene runs in its own folder (its geometry path is relative to it); its output goes to a temporary
# folder. --core picks the core (default 0).
set -euo pipefail
scene="" steps=300 repeats=16 core=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scene) scene="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --repeats) repeats="$2"; shift 2 ;;
    --core) core="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) break ;;
  esac
done
if [[ -z "$scene" || $# -ne 2 ]]; then
  echo "usage: scene_ab.sh --scene SCENE.toml [--steps N] [--repeats R] [--core C] A/basalt-run B/basalt-run" >&2
  exit 2
fi
[[ -f "$scene" ]] || { echo "scene_ab.sh: no scene file $scene" >&2; exit 2; }
A="$(realpath "$1")" B="$(realpath "$2")"
for b in "$A" "$B"; do [[ -x "$b" ]] || { echo "scene_ab.sh: $b is not an executable" >&2; exit 2; }; done
cd "$(dirname "$scene")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
loop_time() {
  local log
  log="$(taskset -c "$core" "$1" "$(basename "$scene")" --steps "$steps" --output "$out/run" --quiet 2>&1)" ||
    { echo "scene_ab.sh: $1 failed:" >&2; echo "$log" >&2; exit 1; }
  sed -n 's/^done: [0-9]* steps in \([0-9.]*\) s.*/\1/p' <<<"$log"
}
ratios=()
for r in $(seq "$repeats"); do
  if (( r % 2 )); then ta="$(loop_time "$A")"; tb="$(loop_time "$B")"; else tb="$(loop_time "$B")"; ta="$(loop_time "$A")"; fi
  q="$(python3 -c "print(f'{$tb / $ta:.3f}')")"
  ratios+=("$q")
  echo "repeat $r: A $ta s, B $tb s, B/A $q"
done
python3 -c "import statistics,sys; v=[float(x) for x in sys.argv[1:]]; print(f'median B/A {statistics.median(v):.3f} over {len(v)} repeats (min {min(v):.3f}, max {max(v):.3f})')" "${ratios[@]}"
