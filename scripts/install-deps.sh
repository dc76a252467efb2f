#!/usr/bin/env bash
# Installs what Basalt needs on Debian 12 (build, tests, demo). Safe to run twice:
# it only calls apt-get when a package is missing. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  libopenmpi-dev openmpi-bin
  libhdf5-openmpi-dev hdf5-tools
  libcgal-dev libeigen3-dev libgmp-dev libmpfr-dev
  libvtk9-dev
  libgtest-dev libgmock-dev
  libtomlplusplus-dev libcli11-dev libfmt-dev
  xvfb xauth
  python3-h5py python3-matplotlib python3-numpy
  pybind11-dev python3-dev python3-pytest
)

installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

# Beside Debian's ParaView: python3-paraview conflicts with python3-vtk9, which libvtk9-dev needs, so apt
# would only answer "pkgProblemResolver::Resolve generated breaks". Then install everything else and build
# without VTK (CMake turns BASALT_WITH_VTK off by itself when VTK is not found); the user chooses.
# (tests/scripts/install_deps_check.sh runs this with a fake dpkg-query and apt-get.)
without_vtk=0
if installed python3-paraview && ! installed libvtk9-dev; then
  without_vtk=1
  cat >&2 <<'TEXT'
install-deps: ParaView's Python module (python3-paraview) is installed. Debian 12 cannot install it beside
  VTK's (python3-vtk9), which libvtk9-dev -- VTK's development files, for Basalt's pictures -- depends on:
  apt would stop with "pkgProblemResolver::Resolve generated breaks". Two ways on:
   1. Keep ParaView: Basalt builds without VTK (BASALT_WITH_VTK=OFF, chosen by itself). basalt-pack,
      basalt-run, checkpoints and field series work; open a run's ckpt_series.xmf in your ParaView. VTK
      frames (--frames-every), in-situ pictures (--render-every) and basalt-view are left out.
   2. Have basalt-view's pictures: remove ParaView's Python module (apt-get remove python3-paraview; the
      paraview program stays, without its Python shell) and run this script again: it installs libvtk9-dev,
      and the next build has VTK.
install-deps: going on with 1: installing everything but libvtk9-dev; the build will have no VTK.
TEXT
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if [ "$without_vtk" = 1 ] && [ "$p" = libvtk9-dev ]; then continue; fi
  if ! installed "$p"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  if [ "$without_vtk" = 1 ]; then
    echo "install-deps: all packages present but libvtk9-dev (left out beside ParaView, above)"
  else
    echo "install-deps: all ${#PACKAGES[@]} packages present"
  fi
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
