#!/usr/bin/env bash
# The main job on a fresh machine: set up, build, bake the bundled Cornell box
# and render it headless (OSMesa, no display needed).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
mkdir -p out
./build/tools/lightoctree bake data/cornell-box.gltf -o out/cornell-box.vdb \
  --stats-json out/cornell-box.stats.json
./build/tools/lightoctree render data/cornell-box.gltf out/cornell-box.vdb \
  -o out/cornell-box.png --width 600 --height 600
echo
echo "Baked VDL grid:  out/cornell-box.vdb (per-stage figures: out/cornell-box.stats.json)"
echo "Rendered image:  out/cornell-box.png"
