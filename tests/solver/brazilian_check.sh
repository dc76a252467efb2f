#!/bin/sh
# The Brazilian test end to end (scenes/brazilian.toml): a bonded disc packed by basalt-pack, squeezed
# across its diameter past the peak load. Checks that the load peaks (and drops) within the run, that
# tools/brazilian_strength.py reports a tensile strength, and that the disc splits where the theory says:
# the bonds broken by the peak lie along the loaded diameter (|y| < D/8 for at least 70 % of them, where
# only about a third of all bonds lie).
# Usage: brazilian_check.sh BASALT_PACK BASALT_RUN SOURCE_DIR DIR
set -e
pack=$1 run=$2 src=$3 dir=$4
rm -rf "$dir" && mkdir -p "$dir"
"$pack" cylinder --radius 5 --height 3 --origin 0,0,0 --rmin 0.15 --rmax 0.6 --seed 3 -o "$dir/disc.h5" >/dev/null
"$run" "$src/scenes/brazilian.toml" --geometry "$dir/disc.h5" --steps 5000 --checkpoint-every 3000 \
  --output "$dir/out" --quiet 2>/dev/null
/usr/bin/python3 "$src/tools/brazilian_strength.py" "$dir/out" --diameter 10 --thickness 3 --speed 0.05 | tee "$dir/strength.txt"
/usr/bin/python3 - "$dir" <<'PY'
import csv, sys
import h5py, numpy as np
d = sys.argv[1]
rows = list(csv.DictReader(open(f"{d}/out/fields.csv")))
load = np.array([0.5 * (float(r["wall_force_right_platen_x"]) - float(r["wall_force_left_platen_x"])) for r in rows])
k = int(load.argmax())
if not (0 < k < len(load) - 1 and load[-1] < 0.8 * load[k]):
    sys.exit(f"FAIL: no peak load within the run (peak {load[k]:g} at row {k} of {len(load)}, last {load[-1]:g})")
strength = open(f"{d}/strength.txt").read()
sigma = float(strength.split("sigma_t = 2 F / (pi D t) = ")[1].split()[0])
if not abs(sigma - 2 * load[k] / (np.pi * 10 * 3)) <= 1e-5 * sigma:  # printed to 6 significant digits
    sys.exit(f"FAIL: sigma_t {sigma} is not 2 F / (pi D t) of the peak load {load[k]}")
with h5py.File(f"{d}/out/ckpt_003000.h5", "r") as h:
    ids = h["particles/id"][...]
    pos = h["particles/position"][...]
    at = {int(i): j for j, i in enumerate(ids)}
    pairs = h["bonds/pairs"][...]
    broken = h["bonds/broken"][...].astype(bool)
y = np.abs(np.array([(pos[at[a], 1] + pos[at[b], 1]) / 2 for a, b in pairs]))
near = (y[broken] < 1.25).mean()
every = (y < 1.25).mean()
print(f"{broken.sum()} bonds broken at step 3000; {near:.2f} of them within |y| < D/8, {every:.2f} of all bonds")
if not (broken.sum() >= 10 and near >= 0.7 and every <= 0.45):
    sys.exit("FAIL: the breaks do not lie along the loaded diameter")
print("PASS")
PY
