#!/usr/bin/env bash
# Installs the dependencies (tools/setup.sh), configures and builds everything
# into build/. Used by both README commands.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
# With the distributed bake on OpenMPI (docs/scale.md).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DLO_WITH_MPI=ON >/dev/null
cmake --build build --parallel "$(nproc)"
