#!/usr/bin/env bash
# Builds Basalt without VTK (-DBASALT_WITH_VTK=OFF, as beside Debian's ParaView: README, "Without VTK / beside
# ParaView") in its own folder, warnings as errors, checks that no compile or link line of it names VTK, and
# runs its tests. Any ctest arguments pass through, e.g.
#   bash scripts/novtk.sh                    (every test of that build)
#   bash scripts/novtk.sh -R '^io_e2e\.'     (some)
# Environment: BASALT_NOVTK_BUILD_DIR (default build-novtk), BASALT_JOBS (default: nproc).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$here/scripts/mpi-env.sh"
build="${BASALT_NOVTK_BUILD_DIR:-$here/build-novtk}"
jobs="${BASALT_JOBS:-$(nproc)}"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DBASALT_WERROR=ON -DBASALT_WITH_VTK=OFF
cmake --build "$build" -j "$jobs"
# Nothing may include or link VTK: its headers (vtk-9.1) or libraries (libvtk*) in no compile or link line.
mapfile -t lines < <(find "$build" -name flags.make -o -name link.txt)
if grep -l -i -e 'vtk-9' -e 'libvtk' "${lines[@]}" "$build/compile_commands.json"; then
  echo "novtk: the build without VTK includes or links VTK (files above)" >&2
  exit 1
fi
cd "$build"
ctest --output-on-failure --timeout 600 -j "$jobs" "$@"
