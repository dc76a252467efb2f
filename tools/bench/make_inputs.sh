#!/usr/bin/env bash
# Makes the geometries the benchmarks read (docs/BENCHMARKS.md), from a clean clone, with basalt-pack.
#
#   tools/bench/make_inputs.sh [DIR] [--gengeo]      (DIR default: bench-inputs, git-ignored)
#
#   DIR/cube30.geo   30 mm cube, basalt-pack's dense mode, seed 7 (.geo, so ESyS-Particle reads it too)
#   DIR/cube60.h5    60 mm cube, basalt-pack's GenGeo-like mode, seed 7 (590,156 particles, ~35 s)
#   DIR/cube30-gengeo.geo   with --gengeo only: the 30 mm cube packed by GenGeo (python3-gengeo, the
#                    recipe of the paper's cube1.geo, tools/bench/gengeo_cube.py; tens of minutes)
#
# A file that exists is kept (delete it to make it again); the same seed gives the same file.
# BASALT_PACK names the packer (default: build/bin/basalt-pack of this checkout; build it first).
# The 15 mm cube1.geo is the paper's reference GenGeo cube: it is kept in the repository
# (tests/data/cube1.geo; BASALT_REFERENCE_DIR points elsewhere), not made by this script.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
dir="$root/bench-inputs"
gengeo=0
for arg in "$@"; do
  case "$arg" in
    --gengeo) gengeo=1 ;;
    -h | --help)
      sed -n '2,15p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    -*)
      echo "make_inputs: unknown option $arg" >&2
      exit 2
      ;;
    *) dir="$arg" ;;
  esac
done
pack="${BASALT_PACK:-$root/build/bin/basalt-pack}"
if [ ! -x "$pack" ]; then
  echo "make_inputs: $pack not found: build first (cmake --build build), or set BASALT_PACK" >&2
  exit 1
fi
mkdir -p "$dir"

make_one() { # file, then basalt-pack's arguments
  local file="$1"
  shift
  if [ -e "$file" ]; then
    echo "make_inputs: $file exists, kept"
    return
  fi
  echo "make_inputs: $file"
  "$pack" "$@" -o "$file"
}

# Dense mode (basalt-pack's default): the 30 mm cube of the output and frame-time benchmarks.
make_one "$dir/cube30.geo" box --size 30,30,30 --rmin 0.2 --rmax 1.0 --seed 7
# GenGeo-like mode (docs/packer.md): GenGeo itself took ~2 min for the 30 mm cube already.
make_one "$dir/cube60.h5" box --size 60,60,60 --rmin 0.2 --rmax 1.0 --exponent 2.2 --fill --seed 7

if [ "$gengeo" = 1 ]; then
  if [ -e "$dir/cube30-gengeo.geo" ]; then
    echo "make_inputs: $dir/cube30-gengeo.geo exists, kept"
  else
    echo "make_inputs: $dir/cube30-gengeo.geo (GenGeo, tens of minutes)"
    /usr/bin/python3 "$root/tools/bench/gengeo_cube.py" --side 30 --output "$dir/cube30-gengeo.geo"
  fi
fi
