#!/usr/bin/env bash
# Makes the pictures of docs/lightmap.md: the bunny's chart layout and a
# close-up of a chart seam rendered from the atlas with and without seam
# stitching, with the difference. Needs build/ (README) and ../shared/scenes.
set -euo pipefail
cd "$(dirname "$0")/.."
L=build/tools/lightoctree
scene=../shared/scenes/composed/cornell-bunny.glb
out=out/pictures
mkdir -p "$out" docs/images
[ -f "$out/cornell-bunny.vdb" ] || "$L" bake "$scene" -o "$out/cornell-bunny.vdb" --quiet
"$L" lightmap "$scene" "$out/cornell-bunny.vdb" -o "$out/bunny-lightmap.glb" --chart-image --quiet
cp "$out/bunny-lightmap-charts0.png" docs/images/lightmap-bunny-charts.png
# A close-up of the bunny's back, indirect light only, from the atlas.
view=(--lighting atlas --mode indirect --width 240 --height 180 --eye 0.3,0.8,1.3
      --target -0.18,0.58,0.095 --fov 6 --quiet)
for stitch in off on; do
  "$L" render "$scene" "$out/cornell-bunny.vdb" -o "$out/seam-$stitch.exr" --stitch-seams "$stitch" "${view[@]}"
  "$L" render "$scene" "$out/cornell-bunny.vdb" -o "docs/images/lightmap-seam-$stitch.png" \
    --stitch-seams "$stitch" --exposure 1.5 "${view[@]}"
done
"$L" compare "$out/seam-off.exr" "$out/seam-on.exr" --diff docs/images/lightmap-seam-difference.png
