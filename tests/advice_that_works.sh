#!/usr/bin/env bash
# Refusals that give advice name the user's flags, and the advice works
# (docs/robustness.md; a hostile list, issue 43: `lightmap --atlas 64` named
# an internal field, and too many lights in `render` advised lowering
# --emitter-lights, which did not help). Each refused run exits 1 and writes
# nothing; the run that follows the advice it printed succeeds.
# Usage: advice_that_works.sh CLI CORNELL OUT_DIR (the Cornell bake,
# cornell.vdb, beside OUT_DIR: ctest's cli.bake_cornell)
set -u
cli=$1 scene=$2 out=$3
vdb=$(dirname "$out")/cornell.vdb
rm -rf "$out"
mkdir -p "$out"
failed=0 checked=0

# refused NAME REGEX ARGS...: exit 1, REGEX in the message, no file OUT/NAME.
refused() {
  local name=$1 regex=$2
  shift 2
  "$cli" "$@" >"$out/said.txt" 2>&1
  local rc=$?
  checked=$((checked + 1))
  if [ $rc -ne 1 ] || ! grep -Eq -- "$regex" "$out/said.txt" || [ -e "$out/$name" ]; then
    echo "FAILED: $* (exit $rc, expected 1 and /$regex/, nothing written):"
    cat "$out/said.txt"
    failed=$((failed + 1))
  fi
}
# works NAME ARGS...: exit 0 and OUT/NAME written.
works() {
  local name=$1
  shift
  "$cli" "$@" --quiet >"$out/ran.txt" 2>&1
  local rc=$?
  if [ $rc -ne 0 ] || [ ! -s "$out/$name" ]; then
    echo "FAILED: the advice did not work: $* (exit $rc, $out/$name):"
    cat "$out/ran.txt"
    failed=$((failed + 1))
  fi
}

# A page too small for a triangle at the default texel size (a quarter voxel).
refused lit.glb "triangle [0-9]+ of .*cornell-box.gltf alone spans [0-9]+ texels at a texel size of [0-9.e-]+ scene units \(--texel-size; the default is a quarter voxel\), more than a page of --atlas 64 holds with its gutter of 2 texels: use --texel-size [0-9.e-]+ or larger, or --atlas [0-9]+ or larger" \
  lightmap "$scene" "$vdb" -o "$out/lit.glb" --atlas 64
texel=$(sed -n 's/.*use --texel-size \([0-9.e-]*\) or larger.*/\1/p' "$out/said.txt")
atlas=$(sed -n 's/.*or --atlas \([0-9]*\) or larger.*/\1/p' "$out/said.txt")
works lit.glb lightmap "$scene" "$vdb" -o "$out/lit.glb" --atlas 64 --texel-size "$texel"
rm -f "$out"/lit*
works lit.glb lightmap "$scene" "$vdb" -o "$out/lit.glb" --atlas "$atlas"
rm -f "$out"/lit*
# A texel size far too small: the texel size that works, no --atlas (beyond 16384).
refused lit.glb "use --texel-size [0-9.e-]+ or larger$" \
  lightmap "$scene" "$vdb" -o "$out/lit.glb" --texel-size 1e-15

# The Cornell box with N point lights besides its ceiling light (an area light).
with_lights() {
  python3 - "$scene" "$1" "$out/lights-$1.gltf" <<'EOF'
import json, sys
scene, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
g = json.load(open(scene))
lights = [{"type": "point", "intensity": 0.01, "color": [1, 1, 1]} for _ in range(n)]
g.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": lights}
g.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
first = len(g["nodes"])
for i in range(n):
    g["nodes"].append({"translation": [0.1 * (i % 5) - 0.2, 0.5, 0.1 * (i // 5) - 0.2],
                       "extensions": {"KHR_lights_punctual": {"light": i}}})
g["scenes"][g.get("scene", 0)]["nodes"] += list(range(first, first + n))
json.dump(g, open(out, "w"))
EOF
}
with_lights 33
with_lights 32
# More punctual lights than the renderer draws: no flag helps, the scene must.
refused a.png "lights-33.gltf has 33 punctual lights; the GL renderer draws at most 32 lights: keep at most 32 in the scene file" \
  render "$out/lights-33.gltf" "$vdb" -o "$out/a.png" --width 32 --height 24
works a.png render "$out/lights-32.gltf" "$vdb" -o "$out/a.png" --width 32 --height 24 \
  --area-lights off --emitter-lights 0
rm -f "$out/a.png"
# 32 punctual lights and the ceiling as an area light: --area-lights off with
# no emitter lights; --area-lights off alone adds --emitter-lights' 8.
refused b.png "lights-32.gltf has 32 punctual lights and [0-9]+ area lights \(emissive triangles\), more than the 32 lights the GL renderer draws: use --area-lights off with --emitter-lights 0$" \
  render "$out/lights-32.gltf" "$vdb" -o "$out/b.png" --width 32 --height 24
refused b.png "has 32 punctual lights and 8 emitter lights, more than the 32 lights the GL renderer draws: use --emitter-lights 0$" \
  render "$out/lights-32.gltf" "$vdb" -o "$out/b.png" --width 32 --height 24 --area-lights off
works b.png render "$out/lights-32.gltf" "$vdb" -o "$out/b.png" --width 32 --height 24 \
  --area-lights off --emitter-lights 0

if [ $failed -eq 0 ]; then
  echo "advice: $checked refusals name their flags and their advice works"
fi
exit $failed
