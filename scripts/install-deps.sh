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
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
