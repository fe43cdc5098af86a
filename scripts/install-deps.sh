#!/usr/bin/env bash
# Installs the Debian 12 packages Repose builds and tests with, only those missing.
# Safe to run repeatedly; needs root (or sudo) only when something is missing.
set -euo pipefail

PACKAGES=(
  cmake ninja-build ccache g++ pkg-config zlib1g-dev
  libeigen3-dev libsuitesparse-dev libcgal-dev
  libnifti2-dev libteem-dev libgdcm-dev libdcmtk-dev libhdf5-dev
  libvtk9-dev libvtk9-qt-dev qtbase5-dev
  nlohmann-json3-dev libgtest-dev libbenchmark-dev
  python3-dev pybind11-dev
  python3-numpy python3-nibabel python3-pytest python3-matplotlib python3-jsonschema
  python3-scipy python3-vtk9
  xvfb xauth libxml2-utils dicom3tools
  plastimatch time
  openems python3-openems libopenems-dev python3-h5py
  libopenmpi-dev openmpi-bin
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
