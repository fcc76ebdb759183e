#!/usr/bin/env bash
# The irradiance error near edges (the accuracy issue's "pixels within one voxel of an
# edge"): for the Cornell box, bunny and dragon, bakes with the gather's accuracy options
# all off (the gather before them), the defaults, and the defaults with SH of order 1,
# renders their irradiance at the sweep's images (160 x 120, 64 rays per pixel) and
# compares them with the sweep's 8192-spp reference, over every pixel and over the
# edge mask of `reference --part edge-mask` (first hits within one depth-6 voxel of an
# edge). Writes docs/results/edge-error.md. Needs the sweep's references
# (docs/results/SCENE/cache/reference-irradiance.exr: run `lightoctree sweep` first).
set -euo pipefail
cd "$(dirname "$0")/.."
L=build/tools/lightoctree
scenes=../shared/scenes/composed
out=out/edge-error
mkdir -p "$out"
report=docs/results/edge-error.md

# Y relative RMSE of `compare` (its luminance row), in percent.
yRmse() { "$L" compare "$@" --ignore-background | awk '$1 == "Y" { printf "%.1f", 100 * $2 }'; }

{
  echo "# Irradiance error near edges"
  echo
  echo "Measured by \`tools/measure_edge_error.sh\` on $(date -u +%Y-%m-%d). Irradiance at the"
  echo "first hit (\`render --mode irradiance\`, 160 x 120, 64 rays per pixel) against the"
  echo "sweep's 8192-spp path-traced reference: luminance relative RMSE per pixel over every"
  echo "pixel that sees the scene, and over the *edge mask*, the pixels whose first hit lies"
  echo "within one depth-6 voxel of an edge (\`reference --part edge-mask\`: a wall joint, an"
  echo "object on the floor, an outer edge, a tight curve). Bakes at depth 6, 600k photons,"
  echo "k = 300; *gather before* = \`--layers off --gather-occlusion off --edge-correction off"
  echo "--smoothing off\`."
  echo
  echo "| scene | edge pixels | gather before: all / edges | defaults: all / edges | defaults, sh1: all / edges | edge error, before / defaults |"
  echo "|---|---:|---:|---:|---:|---:|"
} > "$report.tmp"

for s in cornell-box cornell-bunny cornell-dragon; do
  scene="$scenes/$s.glb"
  ref="docs/results/$s/cache/reference-irradiance.exr"
  if [ ! -f "$scene" ] || [ ! -f "$ref" ]; then
    echo "skipping $s: $scene or $ref missing (run lightoctree sweep $scene --out docs/results/$s)" >&2
    continue
  fi
  edges=$("$L" reference "$scene" --part edge-mask --width 160 --height 120 --spp 16 \
            -o "$out/$s-mask.exr" | sed -n 's/.*: \([0-9.]*%\) of the pixels/\1/p')
  declare -A all edge
  for setting in before defaults sh1; do
    case $setting in
      before) flags="--layers off --gather-occlusion off --edge-correction off --smoothing off" ;;
      defaults) flags="" ;;
      sh1) flags="--representation sh1" ;;
    esac
    # shellcheck disable=SC2086
    "$L" bake "$scene" -o "$out/$s-$setting.vdb" $flags --quiet
    "$L" render "$scene" "$out/$s-$setting.vdb" --mode irradiance --width 160 --height 120 \
      -o "$out/$s-$setting.exr" --quiet
    all[$setting]=$(yRmse "$out/$s-$setting.exr" "$ref")
    edge[$setting]=$(yRmse "$out/$s-$setting.exr" "$ref" --mask "$out/$s-mask.exr")
  done
  ratio=$(awk -v a="${edge[before]}" -v b="${edge[defaults]}" 'BEGIN { printf "%.2f", a / b }')
  echo "| $s | $edges | ${all[before]}% / ${edge[before]}% | ${all[defaults]}% / ${edge[defaults]}% | ${all[sh1]}% / ${edge[sh1]}% | ${ratio}x |" >> "$report.tmp"
  unset all edge
done

{
  echo
  echo "*edge pixels*: share of the image in the mask (including background pixels near the"
  echo "scene's silhouette, which \`--ignore-background\` then leaves out). The accuracy issue's"
  echo "target is the edge error at least halved (ratio >= 2x)."
} >> "$report.tmp"
mv "$report.tmp" "$report"
cat "$report"
