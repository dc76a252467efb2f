#!/bin/bash
# The seed paper's wave-propagation benchmark in LAMMPS (peer code; never a Basalt dependency).
#
#   tools/lammps/wave_benchmark.sh [--geometry FILE.geo] [--steps N] [--ranks R] [--ke]
#                                  [--bond-model table|harmonic] [--skin S] [--output DIR]
#                                  [--generate-side L] [--grid PX,PY,PZ] [--newton on|off]
#                                  [--physics esys|basalt] [--no-contacts] [--type-order spatial|file] [--sort N]
#
# Converts the .geo with geo2data.py, runs in.wave.lmp with `mpirun -np R lmp` inside DIR and
# prints LAMMPS's own loop time ("Loop time of ...": the stepping loop only) as particle-steps/s.
# --ke writes DIR/ke.csv: step,time,kinetic_energy,kinetic_energy_half_step,wall_z
# (kinetic_energy_half_step at step n uses v(n+1/2): compare it with ESyS's e_kin row n+1).
# --physics esys (default): r0 = r1 + r2 and wall force pi r K overlap (scenes/wave-esys.toml);
# --physics basalt: r0 = the initial distance and wall force K overlap (scenes/wave.toml, the benchmark's).
# --bond-model table (default) computes that physics exactly; harmonic adds the contact to compressed
# bonded pairs (not the same physics; timing only). --no-contacts drops the pair style (a check only).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
geometry="${BASALT_REFERENCE_DIR:-$here/../../tests/data}/cube1.geo"
steps=10000
ranks=1
ke=0
bond_model=table
skin=0.04
output=lammps_wave_out
generate_side=0
grid=""
newton=on
physics=esys
contacts=1
type_order=spatial
sort=""

usage() { sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; }
need_value() { [[ $# -ge 2 && -n "$2" ]] || { echo "error: $1 needs a value" >&2; exit 2; }; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --geometry) need_value "$@"; geometry="$2"; shift 2 ;;
    --steps) need_value "$@"; steps="$2"; shift 2 ;;
    --ranks) need_value "$@"; ranks="$2"; shift 2 ;;
    --ke) ke=1; shift ;;
    --bond-model) need_value "$@"; bond_model="$2"; shift 2 ;;
    --skin) need_value "$@"; skin="$2"; shift 2 ;;
    --output) need_value "$@"; output="$2"; shift 2 ;;
    --generate-side) need_value "$@"; generate_side="$2"; shift 2 ;;
    --grid) need_value "$@"; grid="$2"; shift 2 ;;
    --newton) need_value "$@"; newton="$2"; shift 2 ;;
    --physics) need_value "$@"; physics="$2"; shift 2 ;;
    --no-contacts) contacts=0; shift ;;
    --type-order) need_value "$@"; type_order="$2"; shift 2 ;;
    --sort) need_value "$@"; sort="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "error: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$steps" =~ ^[1-9][0-9]*$ ]] || { echo "error: --steps must be a positive integer, got '$steps'" >&2; exit 2; }
[[ "$ranks" =~ ^[1-9][0-9]*$ ]] || { echo "error: --ranks must be a positive integer, got '$ranks'" >&2; exit 2; }
# default rank grid: split x only (the box is padded 50 % above the cube: z cuts unbalance the load)
[[ -n "$grid" ]] || grid="$ranks,1,1"
[[ "$grid" =~ ^[1-9][0-9]*,[1-9][0-9]*,[1-9][0-9]*$ ]] || { echo "error: --grid must be 'px,py,pz', got '$grid'" >&2; exit 2; }
IFS=, read -r px py pz <<< "$grid"
(( px * py * pz == ranks )) || { echo "error: --grid $grid does not multiply to --ranks $ranks" >&2; exit 2; }
[[ "$bond_model" == table || "$bond_model" == harmonic ]] ||
  { echo "error: --bond-model must be table or harmonic, got '$bond_model'" >&2; exit 2; }

[[ "$newton" == on || "$newton" == off ]] || { echo "error: --newton must be on or off, got '$newton'" >&2; exit 2; }
case "$physics" in
  esys) rest_length=sum_of_radii; wall=pi_r ;;
  basalt) rest_length=initial_distance; wall=plain ;;
  *) echo "error: --physics must be esys or basalt, got '$physics'" >&2; exit 2 ;;
esac

# LAMMPS's atom sorting (every N steps; 0 = never) would undo the spatial order geo2data.py wrote
[[ -n "$sort" ]] || { [[ "$type_order" == spatial ]] && sort=0 || sort=1000; }
[[ "$sort" =~ ^[0-9]+$ ]] || { echo "error: --sort must be a number of steps, got '$sort'" >&2; exit 2; }

for exe in lmp mpirun; do
  if ! command -v "$exe" > /dev/null; then
    echo "LAMMPS is not available: '$exe' not on PATH (Debian package lammps). Nothing was run." >&2
    exit 3
  fi
done

if [[ ! -e "$geometry" && "$generate_side" != 0 ]]; then
  echo "$geometry missing: generating a ${generate_side} mm GenGeo cube (slow)"
  /usr/bin/python3 "$here/../bench/gengeo_cube.py" --side "$generate_side" --output "$geometry"
fi
mkdir -p "$output" || { echo "error: cannot create output directory $output" >&2; exit 2; }
output="$(cd "$output" && pwd)"

start=$(date +%s.%N)
/usr/bin/python3 "$here/geo2data.py" "$geometry" "$output" --bond-model "$bond_model" --rest-length "$rest_length" \
  --type-order "$type_order"
echo "conversion: $(echo "$(date +%s.%N) - $start" | bc) s"

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
rm -f "$output/ke.dat"
(cd "$output" && mpirun -np "$ranks" lmp -in "$here/in.wave.lmp" -log "$output/log.lammps" -echo none -screen none \
  -var dir "$output" -var steps "$steps" -var ke "$ke" -var skin "$skin" -var newton "$newton" -var wall "$wall" -var contacts "$contacts" -var sort "$sort" -var px "$px" -var py "$py" -var pz "$pz") ||
  { echo "error: LAMMPS failed; see $output/log.lammps" >&2; tail -5 "$output/log.lammps" >&2; exit 1; }

loop=$(grep -m1 '^Loop time of' "$output/log.lammps")
read -r seconds procs nsteps natoms < <(echo "$loop" | awk '{print $4, $6, $9, $12}')
rate=$(echo "$natoms * $nsteps / $seconds" | bc -l)
printf 'LAMMPS %s, %s rank(s), %s atoms, %s steps, physics %s, bonds %s, contacts %s, skin %s, newton %s: loop %.3f s, %.3f M particle-steps/s\n' \
  "$(basename "$geometry")" "$procs" "$natoms" "$nsteps" "$physics" "$bond_model" "$contacts" "$skin" "$newton" "$seconds" \
  "$(echo "$rate / 1000000" | bc -l)"
printf '{"geometry": "%s", "particles": %s, "steps": %s, "ranks": %s, "physics": "%s", "bond_model": "%s", "contacts": %s, "skin": %s, "newton": "%s", "loop_s": %s, "particle_steps_per_s": %.0f}\n' \
  "$geometry" "$natoms" "$nsteps" "$procs" "$physics" "$bond_model" "$contacts" "$skin" "$newton" "$seconds" "$rate" > "$output/timing.json"

if [[ "$ke" == 1 ]]; then
  awk 'BEGIN { print "step,time,kinetic_energy,kinetic_energy_half_step,wall_z" }
       !/^#/ { printf "%d,%.6g,%s,%s,%s\n", $1, $1 * dt, $2, $3, $4 }' dt=1e-3 "$output/ke.dat" > "$output/ke.csv.tmp"
  mv "$output/ke.csv.tmp" "$output/ke.csv"
  echo "kinetic energy series: $output/ke.csv"
fi
