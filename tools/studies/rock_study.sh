#!/bin/sh
# The rock speed-against-accuracy study of docs/accuracy.md ("Rock: the UCS test"), issue 46: basalt-study on
# scenes/ucs-esys.toml (ESyS-Particle's rot_compress specimen: 3,407 spheres, 10,739 BrittleBeam bonds, platens
# closing at 0.03 mm/ms each) over the whole test, 1.1 ms (22,000 of the scene's steps, past 1.2 x the peak's
# time), dt fraction 0.05 .. 0.8 in double, float and mixed, against a double reference at dt fraction 0.02 and
# 3 perturbed references. Quantities: the peak platen force, the time of the peak (strain at peak = 0.06 t / 20),
# the loading slope at half the peak (the modulus at half peak, in N/ms), the broken bonds at the peak and at 1.2 x
# the peak's time.
#   sh tools/studies/rock_study.sh [BUILD_DIR] [OUT_DIR]   (about 6 min on 2 quiet cores)
# Writes OUT_DIR (default out/study-ucs-esys): table.md, study.json, study.png, setting.toml.
set -e
build=${1:-build}
out=${2:-out/study-ucs-esys}
cd "$(dirname "$0")/../.."
. scripts/mpi-env.sh
f=wall_force_top_wall_z
broken=broken_bonds_tension+broken_bonds_shear+broken_bonds_bending+broken_bonds_torsion
"$build/bin/basalt-study" scenes/ucs-esys.toml --steps 22000 \
  -q "fields.$f:max" -q "fields.$f:argmax" -q "fields.$f:half_max_slope" \
  -q "fields.$broken:at_max($f)" -q "fields.$broken:at_max($f)*1.2" \
  --precision double,float,mixed --dt-fraction 0.05,0.1,0.2,0.4,0.8 \
  --ensemble 3 --budget 1e-2 -o "$out"
