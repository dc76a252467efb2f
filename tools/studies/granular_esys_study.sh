#!/bin/sh
# The ESyS granular column's speed-against-accuracy study (docs/accuracy.md, "Granular: the ESyS column"),
# issue 46: basalt-study on scenes/granular-esys.toml (2,884 rotating spheres released against a back wall under
# gravity, ESyS's RotFriction contacts and damping) over the scene's 20,000 steps (t = 0 .. 20), against a double
# reference at dt fraction 0.02 and 3 perturbed references. Quantities: the peak kinetic energy and its time, the
# deposit's front (99th percentile of x) and mean x, its height (99th percentile of z). Two studies:
#   OUT_DIR/stiffness   contact stiffness x 1, 0.1, 0.01, 0.001 at dt fractions 0.05, 0.2, 0.8 (double);
#   OUT_DIR/precision   double, float, mixed at the scene's step (0.0386 of the critical step) and at 0.2, and
#                       basalt-run's presets.
#   sh tools/studies/granular_esys_study.sh [BUILD_DIR] [OUT_DIR]   (about 10 min on 2 quiet cores)
set -e
build=${1:-build}
out=${2:-out/study-granular-esys}
cd "$(dirname "$0")/../.."
. scripts/mpi-env.sh
study() {
  "$build/bin/basalt-study" scenes/granular-esys.toml "$@" \
    -q fields.kinetic_energy:max -q fields.kinetic_energy:argmax -q checkpoint.position.x:p99 \
    -q checkpoint.position.x:mean -q checkpoint.position.z:p99 --ensemble 3 --budget 1e-2
}
study --stiffness 1,0.1,0.01,0.001 --dt-fraction 0.05,0.2,0.8 -o "$out/stiffness"
study --precision double,float,mixed --dt-fraction 0.0386,0.2 --presets -o "$out/precision"
