#!/usr/bin/env bash
# Installs the Debian 12 packages Light Octree builds and tests with.
# Idempotent: packages already present are skipped, so a second run is a no-op.
# Needs root (or sudo) only when something is missing.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake g++ make pkg-config ninja-build
  # scene loading: glTF 2.0 and OBJ/MTL, image decoding for textures
  libtinygltf-dev nlohmann-json3-dev libtinyobjloader-dev libstb-dev
  # photon tracing and parallelism
  libembree-dev libtbb-dev
  # sparse grids and .vdb files (OpenVDB's CMake module needs boost-iostreams)
  libopenvdb-dev libboost-iostreams-dev libblosc-dev libopenvdb-tools
  # kd-tree baseline of the gather benchmark, CLI, tests
  libnanoflann-dev libcli11-dev libgtest-dev
  # lightmap UVs: the sparse LSCM solve (header-only; stb_rect_pack comes with libstb-dev)
  libeigen3-dev
  # images and GL rendering (OSMesa headless, EGL, GLFW window), math
  libopenexr-dev libglm-dev libglfw3-dev libosmesa6-dev libegl-dev libgl-dev python3-glad
  # plots of the parameter sweep (lightoctree sweep)
  gnuplot-nox
  # a virtual display for the `lightoctree view` window tests (xvfb-run)
  xvfb xauth
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
