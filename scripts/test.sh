#!/usr/bin/env bash
# Installs what is missing, builds Basalt (warnings as errors) and runs every test.
# Usage: scripts/test.sh [ctest args...]   e.g. scripts/test.sh -L unit
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$here/scripts/install-deps.sh"
source "$here/scripts/mpi-env.sh"
build="${BASALT_BUILD_DIR:-$here/build}"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DBASALT_WERROR=ON
cmake --build "$build" -j "$(nproc)"
# `import basalt` in any new shell (docs/python.md); the tests themselves set PYTHONPATH.
"$here/scripts/python-path.sh" "$build" || echo "test: the Python package is not on python3's path (above)"
cd "$build"
ctest --output-on-failure --timeout 600 -j "$(nproc)" "$@"
