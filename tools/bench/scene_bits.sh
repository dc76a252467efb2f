#!/bin/bash
# Bit-for-bit check of a change: the same scenes with two basalt-run builds (A = before, B = after), at
# np 1 and 2, each writing its field series and a last checkpoint; every fields.csv must be byte-identical
# and every checkpoint's particle and contact datasets equal (h5diff, exact). Prints one line per case and
# exits 1 on the first difference it reports.
#
#   source scripts/mpi-env.sh
#   bash tools/bench/scene_bits.sh [--steps N] A/bin B/bin
#
# Scenes: wave and wave-esys on the GenGeo cube (tests/data/cube1.geo), granular-esys and ucs-esys on their
# ESyS inputs (docs/data), the column collapse and the hopper on packings made here; N steps each (default
# 2000; the scenes' own step counts take minutes).
set -euo pipefail
steps=2000
while [[ $# -gt 0 ]]; do
  case "$1" in
    --steps) steps="$2"; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) break ;;
  esac
done
if [[ $# -ne 2 ]]; then
  echo "usage: scene_bits.sh [--steps N] A/bin B/bin" >&2
  exit 2
fi
A="$(realpath "$1")" B="$(realpath "$2")"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cube="$root/tests/data/cube1.geo"
# The column collapse and the hopper ship no geometry: packed here as their scenes say (the packer is
# deterministic; B's packer for both sides).
"$B/basalt-pack" box --size 10,8,10 --rmin 0.4 --rmax 0.6 --no-bonds --seed 1 -o "$work/column.h5" >/dev/null
"$B/basalt-pack" cylinder --radius 19.3 --height 15 --origin 0,0,0 --rmin 0.5 --rmax 0.7 --no-bonds --seed 1 \
  -o "$work/hopper.h5" >/dev/null
cases=(
  "wave|$root/scenes/wave.toml|--geometry $cube"
  "column-collapse|$root/scenes/column-collapse.toml|--geometry $work/column.h5"
  "hopper|$root/scenes/hopper.toml|--geometry $work/hopper.h5"
  "wave-esys|$root/scenes/wave-esys.toml|--geometry $cube"
  "granular-esys|$root/scenes/granular-esys.toml|"
  "ucs-esys|$root/scenes/ucs-esys.toml|"
)
status=0
for c in "${cases[@]}"; do
  IFS='|' read -r name scene extra <<<"$c"
  for np in 1 2; do
    for side in A B; do
      bin="$A"
      [[ $side == B ]] && bin="$B"
      out="$work/$name-np$np-$side"
      # shellcheck disable=SC2086
      mpirun -np "$np" "$bin/basalt-run" "$scene" $extra --steps "$steps" --checkpoint-every "$steps" \
        --output "$out" --quiet >"$out.log" 2>&1 || { echo "$name np $np $side failed:"; cat "$out.log"; exit 1; }
    done
    a="$work/$name-np$np-A" b="$work/$name-np$np-B"
    ckpt="$(cd "$a" && ls ckpt_*.h5 | tail -n 1)"
    if ! cmp -s "$a/fields.csv" "$b/fields.csv"; then
      echo "$name np $np: fields.csv DIFFERS"
      status=1
    elif ! h5diff -q "$a/$ckpt" "$b/$ckpt" /particles /particles >/dev/null 2>&1; then
      echo "$name np $np: $ckpt /particles DIFFERS"
      status=1
    else
      echo "$name np $np: same bits ($steps steps: fields.csv, $ckpt /particles)"
    fi
  done
done
exit $status
