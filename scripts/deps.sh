#!/usr/bin/env bash
# Installs the Debian 12 packages tetrasand needs, only those missing. As root it runs apt-get itself;
# otherwise it prints the exact command to run and exits 1. Sourced or run by scripts/demo.sh and
# scripts/test.sh; safe to run again.
set -euo pipefail

# What each package is for: README.md, section "Dependencies".
PACKAGES=(
  cmake g++ make pkg-config git ca-certificates xz-utils
  libeigen3-dev libtbb-dev libassimp-dev libcgal-dev libgmp-dev libmpfr-dev
  libopenvdb-dev libopenvdb-tools libnanovdb-dev libnanovdb-tools libboost-iostreams-dev libimath-dev libblosc-dev zlib1g-dev
  libegl-dev libegl-mesa0 libgl1-mesa-dri libopengl-dev libglew-dev glslang-tools
  libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libfmt-dev libstb-dev libssl-dev
  libgtest-dev googletest
  libcgal-demo assimp-testmodels
  lammps python3
  python3-vtk9 python3-jsonschema
  pybind11-dev python3-dev python3-numpy
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PACKAGES[@]} Debian packages present"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "deps: missing Debian packages: ${missing[*]}" >&2
  echo "deps: run as root:" >&2
  echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
  exit 1
fi

echo "deps: installing ${missing[*]}"
# Package lists on a fresh machine may be stale or empty.
apt-get update
DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
