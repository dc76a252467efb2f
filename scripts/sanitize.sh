#!/usr/bin/env bash
# Builds Basalt with AddressSanitizer and UndefinedBehaviorSanitizer in a separate folder and runs the
# test suite there (README, "Developer builds"). Any ctest arguments pass through, e.g.
#   bash scripts/sanitize.sh -L unit        bash scripts/sanitize.sh -R 'solver_scene|io_'
# Environment: BASALT_SANITIZE (default address,undefined), BASALT_SANITIZE_BUILD_DIR (default
# build-sanitize), BASALT_SANITIZE_TARGETS (space-separated build targets, default: all; then pass
# ctest arguments that select only their tests), BASALT_JOBS (default: nproc).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$here/scripts/mpi-env.sh"
build="${BASALT_SANITIZE_BUILD_DIR:-$here/build-sanitize}"
sanitizers="${BASALT_SANITIZE:-address,undefined}"
jobs="${BASALT_JOBS:-$(nproc)}"
# -O1 -g1: optimised enough for the tests' timeouts, line numbers in the reports; compiling with
# -O2 -g took twice the CPU time (docs/reliability.md, "Sanitizers"). -march=native off: the
# sanitizer build is for finding faults, not for speed.
flags="-O1 -g1 -DNDEBUG"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBASALT_WERROR=ON -DBASALT_NATIVE=OFF \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$flags" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$flags" \
      -DBASALT_SANITIZE="$sanitizers"
targets=()
for t in ${BASALT_SANITIZE_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$build" -j "$jobs" "${targets[@]}"
# Open MPI and HDF5 keep allocations until exit that LeakSanitizer would report as leaks: leak detection
# stays off (AddressSanitizer still catches overflows, use after free, double free). Undefined behaviour
# stops the process with a report (-fno-sanitize-recover), so the test that hit it fails.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
cd "$build"
ctest --output-on-failure --timeout 1200 -j "$jobs" "$@"
