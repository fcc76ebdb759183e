#!/usr/bin/env bash
# Bakes the Cornell box, bunny, dragon and the material room at the defaults (the paper's
# settings) into out/bench-bakes/ and runs build/tools/bench_render on them,
# which writes docs/results/render.md. Extra arguments go to bench_render
# (e.g. --backend egl --out docs/results/render-egl.md on a GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
bakes=out/bench-bakes
scenes=../shared/scenes/composed
mkdir -p "$bakes"
build/tools/lightoctree bake data/cornell-box.gltf -o "$bakes/cornell-box.vdb" --quiet
build/tools/lightoctree bake data/material-room.gltf -o "$bakes/material-room.vdb" --quiet
for s in cornell-bunny cornell-dragon; do
  if [ -f "$scenes/$s.glb" ]; then
    build/tools/lightoctree bake "$scenes/$s.glb" -o "$bakes/$s.vdb" --quiet
  fi
done
exec build/tools/bench_render --bakes "$bakes" "$@"
