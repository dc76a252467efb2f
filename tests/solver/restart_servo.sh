#!/bin/sh
# Bit-for-bit restart of a servo wall (its point, velocity and point at the last rebuild are state in the
# checkpoint): a run of 2N steps with a checkpoint at N, and a run restarted from it, must write identical
# fields.csv rows (wall position and force to the last bit). Writes the 4 x 4 x 6 box of touching spheres
# (radius 0.5, x and y jittered by up to 0.01) that servo_box.toml names.
# Usage: restart_servo.sh BASALT_RUN SCENE DIR N [MPIRUN NP]
set -e
. "$(dirname "$0")/restart_checks.sh"
run=$1 scene=$2 dir=$3 n=$4
launch=""
[ -n "$5" ] && launch="$5 -np $6"
rm -rf "$dir" && mkdir -p "$dir"
awk 'BEGIN {
  print "LSMGeometry 1.2"; print "BoundingBox 0 0 0 4 4 6"; print "PeriodicBoundaries 0 0 0"; print "Dimension 3D"
  print "BeginParticles"; print "Simple"; print 96
  id = 1
  for (k = 0; k < 6; k++) for (j = 0; j < 4; j++) for (i = 0; i < 4; i++) {
    jx = 0.01 * sin(12.9898 * id); jy = 0.01 * sin(78.233 * id)
    printf "%.17g %.17g %.17g 0.5 %d %d\n", 0.5 + i + jx, 0.5 + j + jy, 0.5 + k, id, (k == 5 ? 2 : 0); id++
  }
  print "EndParticles"; print "BeginConnect"; print 0; print "EndConnect" }' > "$dir/servo_box.geo"
$launch "$run" "$scene" --geometry "$dir/servo_box.geo" --steps $((2 * n)) --checkpoint-every "$n" --fields-every 10 --output "$dir/a" --quiet >/dev/null
seed_restart "$dir/a" "$dir/b" "$n"
$launch "$run" "$scene" --geometry "$dir/servo_box.geo" --steps "$n" --checkpoint-every "$n" --fields-every 10 --output "$dir/b" --restart "$dir/b" --quiet >/dev/null
z0=$(sed -n 2p "$dir/a/fields.csv" | cut -d, -f5) z1=$(tail -n 1 "$dir/a/fields.csv" | cut -d, -f5)
echo "servo wall z: $z0 at step 10, $z1 at step $((2 * n))"
if [ "$z0" = "$z1" ]; then echo "FAIL: the servo wall did not move"; exit 1; fi
same_fields "$dir/a" "$dir/b"
