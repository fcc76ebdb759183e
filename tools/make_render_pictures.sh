#!/usr/bin/env bash
# Makes the pictures of docs/render.md "The material room": the project's
# textured test scene drawn by the GL renderer (octree and atlas lighting) and
# by the path tracer, and the false-colour difference. Needs build/ (README).
set -euo pipefail
cd "$(dirname "$0")/.."
L=build/tools/lightoctree
scene=data/material-room.gltf
out=out/pictures
mkdir -p "$out" docs/images
python3 tools/make_material_room.py "$out/material-room.gltf" >/dev/null
cmp -s "$out/material-room.gltf" "$scene" || echo "note: data/material-room.gltf differs from the generator's output"
"$L" bake "$scene" -o "$out/material-room.vdb" --quiet
"$L" render "$scene" "$out/material-room.vdb" -o "$out/gl.exr" --width 480 --height 360 --quiet
"$L" render "$scene" "$out/material-room.vdb" -o docs/images/material-room-gl.png --width 480 --height 360 --quiet
"$L" render "$scene" "$out/material-room.vdb" -o docs/images/material-room-atlas.png --width 480 --height 360 --lighting atlas --quiet
"$L" reference "$scene" -o "$out/reference.exr" --width 480 --height 360 --spp "${SPP:-512}" --quiet
"$L" reference "$scene" -o docs/images/material-room-reference.png --width 480 --height 360 --spp "${SPP:-512}" --quiet
"$L" compare "$out/gl.exr" "$out/reference.exr" --bin 4 --diff docs/images/material-room-difference.png
