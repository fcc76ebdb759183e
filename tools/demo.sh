#!/usr/bin/env bash
# The main job on a fresh machine: set up, build, bake the bundled Cornell box.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
mkdir -p out
./build/tools/lightoctree bake data/cornell-box.gltf -o out/cornell-box.vdb \
  --stats-json out/cornell-box.stats.json
echo "Baked VDL grid: out/cornell-box.vdb (per-stage figures: out/cornell-box.stats.json)"
