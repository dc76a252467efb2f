#!/bin/sh
# Bit-for-bit restart in mixed precision (run.precision = "mixed": float offsets from the geometry's
# centre, compensated drift): the wave scene on cube1 shifted by OFFSET (geometry and wall), a run of 2N
# steps with a checkpoint at N, and a run restarted from it, must write identical fields.csv rows. The
# checkpoint holds absolute positions (origin + offset, float64) and the exact float offsets and drift
# remainders as particle fields; its precision attribute is "mixed", and a restart in float is refused.
# Usage: restart_mixed.sh BASALT_RUN WAVE_SCENE CUBE_GEO DIR N OFFSET [MPIRUN NP]
set -e
. "$(dirname "$0")/restart_checks.sh"
run=$1 scene=$2 geo=$3 dir=$4 n=$5 d=$6
launch=""
[ -n "$7" ] && launch="$7 -np $8"
rm -rf "$dir" && mkdir -p "$dir"
awk -v d="$d" '
  /^BoundingBox/ { printf "BoundingBox %.17g %.17g %.17g %.17g %.17g %.17g\n", $2 + d, $3 + d, $4 + d, $5 + d, $6 + d, $7 + d; next }
  /^Simple/ { print; getline; n = $1; print; for (k = 0; k < n; k++) { getline; $1 = sprintf("%.17g", $1 + d); $2 = sprintf("%.17g", $2 + d); $3 = sprintf("%.17g", $3 + d); print } next }
  { print }' "$geo" > "$dir/cube.geo"
sed "s/point = \[0.0, 0.0, 0.0\]/point = [$d, $d, $d]/" "$scene" > "$dir/wave.toml"
$launch "$run" "$dir/wave.toml" --geometry "$dir/cube.geo" --precision mixed --steps $((2 * n)) --checkpoint-every "$n" --fields-every 10 --output "$dir/a" --quiet >/dev/null
mkdir -p "$dir/b"
ckpt="ckpt_$(printf %06d "$n").h5"
cp "$dir/a/$ckpt" "$dir/b/"
if ! h5dump -a /precision "$dir/b/$ckpt" 2>/dev/null | grep -q '"mixed"'; then
  echo "FAIL: the checkpoint's precision attribute is not \"mixed\""
  exit 1
fi
# Positions and the wall are absolute in the checkpoint (origin + float offset), not in the run's frame.
x=$(h5dump -m '%.17g' -d /particles/position -s '0,0' -c '1,1' "$dir/b/$ckpt" | sed -n 's/.*(0,0): *\([-0-9.e+]*\).*/\1/p')
w=$(h5dump -m '%.17g' -d /walls/base/position "$dir/b/$ckpt" | sed -n 's/.*(0): *\([-0-9.e+]*\).*/\1/p')
if ! awk -v x="$x" -v w="$w" -v d="$d" 'BEGIN { exit !(x > d - 1 && x < d + 16 && w == d) }'; then
  echo "FAIL: the checkpoint's first position ($x) or wall x ($w) is not absolute (offset $d)"
  exit 1
fi
if $launch "$run" "$dir/wave.toml" --geometry "$dir/cube.geo" --precision float --steps 10 --output "$dir/c" --restart "$dir/b" --quiet >"$dir/refused.txt" 2>&1; then
  echo "FAIL: a restart of a mixed checkpoint in float was not refused"
  exit 1
fi
grep -q "written by a run in mixed precision; restarting it in float is refused" "$dir/refused.txt" || {
  cat "$dir/refused.txt"; echo "FAIL: the refusal does not name both precisions"; exit 1; }
head -n $((n / 10 + 1)) "$dir/a/fields.csv" > "$dir/b/fields.csv"
$launch "$run" "$dir/wave.toml" --geometry "$dir/cube.geo" --precision mixed --steps "$n" --checkpoint-every "$n" --fields-every 10 --output "$dir/b" --restart "$dir/b" --quiet >/dev/null
same_fields "$dir/a" "$dir/b"
