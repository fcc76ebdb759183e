#!/usr/bin/env bash
# Installs the Debian 12 packages Light Octree builds and tests with, and the
# Khronos glTF validator (npm) into .cache/npm.
# Idempotent: what is already present is skipped, so a second run is a no-op.
# Needs root (or sudo) only when something is missing.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake g++ make pkg-config ninja-build
  # libFuzzer targets of the readers (tools/fuzz.sh): clang and its fuzzer runtime
  clang libclang-rt-14-dev
  # scene loading: glTF 2.0 and OBJ/MTL, image decoding for textures
  libtinygltf-dev nlohmann-json3-dev libtinyobjloader-dev libstb-dev
  # photon tracing and parallelism
  libembree-dev libtbb-dev
  # sparse grids and .vdb files (OpenVDB's CMake module needs boost-iostreams)
  libopenvdb-dev libboost-iostreams-dev libblosc-dev libopenvdb-tools
  # the bake on several processes (mpirun -np N lightoctree bake, -DLO_WITH_MPI=ON)
  openmpi-bin libopenmpi-dev
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
  # `import lightoctree` (python/): pybind11 and Python's headers; pytest runs its tests
  pybind11-dev python3-dev python3-numpy python3-pytest
  # `pip install .` of the module into a virtual environment (test python.pip_install)
  python3-pip python3-venv python3-setuptools python3-wheel
  # a decimal-comma locale that the Python module's test sets (localedef)
  locales
  # Node.js runs the Khronos glTF validator on the `lightoctree lightmap`
  # exports (tests gltf.validate_*); npm, which installs the validator, is
  # handled below
  nodejs
)
# What only the test suite needs (tools/test.sh sets LO_SETUP_TESTS=1): Blender,
# whose Cycles judges the path tracer (tools/cycles_reference.py, test
# cycles.lights_in_project_units), and NumPy for its glTF importer.
# Chromium draws the three.js module's pictures (tests/web/, test web.three_lightmap).
if [ "${LO_SETUP_TESTS:-0}" = "1" ]; then
  PACKAGES+=(blender chromium)
fi

# npm packages, pinned, installed into the project-local folder the tests
# read (git ignores .cache/): the Khronos glTF validator (the lightmap
# exports), three.js and puppeteer-core (the three.js module in Chromium).
NPM_PACKAGES=(gltf-validator@2.0.0-dev.3.10 three@0.187.0 puppeteer-core@24.43.1)
NPM_PREFIX="$(cd "$(dirname "$0")/.." && pwd)/.cache/npm"

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
updated=0
apt_install() {
  if [ $updated -eq 0 ]; then
    $SUDO apt-get update -qq
    updated=1
  fi
  $SUDO apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
else
  echo "setup: installing ${#missing[@]} package(s): ${missing[*]}"
  apt_install "${missing[@]}"
fi

# Debian's nodejs comes without npm (Debian's npm package); a NodeSource
# nodejs ships its own npm and conflicts with Debian's, so npm is installed
# only where the command is missing.
if ! command -v npm >/dev/null 2>&1; then
  echo "setup: installing npm"
  apt_install npm
fi

npm_missing=()
for spec in "${NPM_PACKAGES[@]}"; do
  name="${spec%@*}" version="${spec##*@}"
  installed="$(sed -n 's/^ *"version": *"\([^"]*\)".*/\1/p' \
    "$NPM_PREFIX/node_modules/$name/package.json" 2>/dev/null | head -1 || true)"
  [ "$installed" = "$version" ] || npm_missing+=("$spec")
done
if [ ${#npm_missing[@]} -eq 0 ]; then
  echo "setup: npm packages present in .cache/npm (${NPM_PACKAGES[*]})"
else
  echo "setup: installing ${NPM_PACKAGES[*]} into .cache/npm"
  mkdir -p "$NPM_PREFIX"
  # All at once: npm removes what a --no-save install does not name.
  npm install --prefix "$NPM_PREFIX" --no-audit --no-fund --no-save --loglevel=error \
    "${NPM_PACKAGES[@]}" >/dev/null
fi
echo "setup: done"
