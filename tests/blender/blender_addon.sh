#!/usr/bin/env bash
# The Blender add-on as a user installs it (build/lightoctree_blender.zip) in
# Debian's Blender 3.4, headless: the Cornell box's lightmapped glTF (EXR
# pages, then RGBM pages) imported in "baked light only" mode and rendered by
# Cycles from the file's camera, each picture's mean brightness within 3% of
# the project's `render --lighting atlas --mode indirect --supersample 1` (a
# sample at each pixel's centre, as Cycles takes them here; the light fixture's
# pixels left out); the bake imported as a Volume (test_addon.py checks it).
# The pictures stay in WORKDIR (blender-exr.png, blender-rgbm.png, ours.png).
# With MODULE_DIR (where `import lightoctree` is built) the Volume comes with
# its VDL arrows, checked and drawn (blender-arrows.png).
# Usage: blender_addon.sh LIGHTOCTREE SCENE ADDON_ZIP WORKDIR [MODULE_DIR]
set -u
cli=$1 scene=$2 zip=$3 dir=$4 modules=${5:-}
here=$(cd "$(dirname "$0")" && pwd)
size=128
rm -rf "$dir" && mkdir -p "$dir/addon" || exit 1
command -v blender > /dev/null || { echo "FAILED: no blender (tools/setup.sh installs it with the tests)"; exit 1; }
python3 -m zipfile -e "$zip" "$dir/addon" || { echo "FAILED: cannot unpack $zip"; exit 1; }
run() { "$@" --quiet || { echo "FAILED: $*"; exit 1; }; }
run "$cli" bake "$scene" -o "$dir/grid.vdb" --depth 5 --photons 200000
run "$cli" lightmap "$scene" "$dir/grid.vdb" -o "$dir/cornell-exr.glb" --image exr
run "$cli" lightmap "$scene" "$dir/grid.vdb" -o "$dir/cornell-rgbm.glb" --image png
run "$cli" render "$scene" "$dir/grid.vdb" --lighting atlas --mode indirect --supersample 1 --width $size --height $size \
  -o "$dir/ours.png" --exposure 0 --tone-map clamp
run "$cli" reference "$scene" -o "$dir/first-hit.exr" --width $size --height $size --spp 1 \
  --emitter-mask "$dir/emitter-mask.png"
failures=0
for pages in exr rgbm; do
  mkdir -p "$dir/$pages"
  if ! blender -b --factory-startup --python "$here/test_addon.py" -- "$dir/addon" "$dir/cornell-$pages.glb" \
      "$dir/grid.vdb" "$dir/$pages" $size "$modules" > "$dir/blender-$pages.log" 2>&1; then
    grep -E "FAILED|Error|Traceback" "$dir/blender-$pages.log" | head -5
    echo "FAILED: Blender with the $pages pages (log: $dir/blender-$pages.log)"
    failures=$((failures + 1))
    continue
  fi
  grep -E "lightmapped materials|volume |VDL arrows" "$dir/blender-$pages.log"
  cp "$dir/$pages/blender-bake.png" "$dir/blender-$pages.png"
  [ -f "$dir/$pages/blender-arrows.png" ] && cp "$dir/$pages/blender-arrows.png" "$dir/blender-arrows.png"
  "$cli" compare "$dir/blender-$pages.png" "$dir/ours.png" --mask "$dir/emitter-mask.png" \
    --json "$dir/compare-$pages.json" > /dev/null || { echo "FAILED: compare"; failures=$((failures + 1)); continue; }
  verdict=$(python3 - "$dir/compare-$pages.json" "$pages" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
ratio = c["mean_test_luminance"] / c["mean_reference_luminance"]
ok = abs(ratio - 1) <= 0.03
print(f"Blender 3.4 Cycles, {sys.argv[2]} pages: mean brightness {ratio:.4f} of render --lighting atlas "
      f"--mode indirect --supersample 1, the fixture's pixels left out (target 0.97-1.03; rel. RMSE per pixel "
      f"{c['channels']['Y']['rel_rmse']:.4f}): {'ok' if ok else 'FAILED'}")
PY
)
  echo "$verdict"
  case $verdict in *FAILED*) failures=$((failures + 1)) ;; esac
done
[ "$failures" -eq 0 ] && echo "blender add-on: all pictures match" || exit 1
