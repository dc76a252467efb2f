#!/bin/sh
# The rock speed-against-accuracy study of docs/accuracy.md ("Rock: the UCS test"), issue 46: basalt-study on
# scenes/ucs-esys.toml (ESyS-Particle's rot_compress specimen: 3,407 spheres, 10,739 BrittleBeam bonds, platens
# closing at 0.03 mm/ms each) over the whole test, 1.1 ms (22,000 of the scene's steps, past 1.2 x the peak's
# time), against a double reference at dt fraction 0.02 and 3 perturbed references. Quantities: the peak platen
# force, the time of the peak (strain at peak = 0.06 t / 20), the loading slope at half the peak (the modulus at
# half peak, in N/ms), the broken bonds at the peak and at 1.2 x the peak's time. Three studies:
#   OUT_DIR/dt        dt fraction 0.05 .. 0.8 and basalt-run's presets, double (ESyS's arccosine angles cannot
#                     run in float: docs/stability.md);
#   OUT_DIR/atan2     the same scene with angles = "atan2" (which float can run), double, float and mixed at
#                     dt fractions 0.05 and 0.2;
#   OUT_DIR/loading   the scene's step, loading rate x 0.5, 2, 4, 8 and damping x 0.1, 10; OUT_DIR/loading-slow
#                     rate x 0.125, 0.25, 0.5 at the scene's damping (quasi-static
#                     convergence: where the peak stops changing within the ensemble's spread).
#   sh tools/studies/rock_study.sh [BUILD_DIR] [OUT_DIR]   (about 25 min on 2 shared cores)
# Each writes table.md, study.json, study.png, setting.toml.
set -e
build=${1:-build}
out=${2:-out/study-ucs-esys}
cd "$(dirname "$0")/../.."
. scripts/mpi-env.sh
f=wall_force_top_wall_z
broken=broken_bonds_tension+broken_bonds_shear+broken_bonds_bending+broken_bonds_torsion
study() {
  "$build/bin/basalt-study" "$@" --steps 22000 \
    -q "fields.$f:max" -q "fields.$f:argmax" -q "fields.$f:half_max_slope" \
    -q "fields.$broken:at_max($f)" -q "fields.$broken:at_max($f)*1.2" --ensemble 3 --budget 1e-2
}
study scenes/ucs-esys.toml --dt-fraction 0.05,0.1,0.2,0.4,0.8 --presets -o "$out/dt"
mkdir -p "$out"
sed -e "s|^file = \"../docs/data/esys-ucs/box.geo\"|file = \"$PWD/docs/data/esys-ucs/box.geo\"|" \
    -e 's|^criterion = "esys"|criterion = "esys"\nangles = "atan2"|' scenes/ucs-esys.toml > "$out/ucs-esys-atan2.toml"
grep -q '^angles = "atan2"' "$out/ucs-esys-atan2.toml"
study "$out/ucs-esys-atan2.toml" --precision double,float,mixed --dt-fraction 0.05,0.2 -o "$out/atan2"
study scenes/ucs-esys.toml --dt-fraction 0.0548 --rate 0.5,1,2,4,8 --damping 0.1,1,10 -o "$out/loading"
# Quasi-static convergence: slower loadings than the scene's (OUT_DIR/loading-slow).
study scenes/ucs-esys.toml --dt-fraction 0.0548 --rate 0.125,0.25,0.5 -o "$out/loading-slow"
