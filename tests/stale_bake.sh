#!/usr/bin/env bash
# The scene a .vdb was baked from (docs/vdb-contract.md, source_scene_*): its
# path and content hash are in the file; render, lightmap and view say when
# the scene they are given is no longer the one baked, and only then (a
# renamed copy of the same bytes is the same scene).
# Usage: stale_bake.sh LIGHTOCTREE SCENE WORKDIR
set -u
cli=$1 scene=$2 dir=$3
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
cp "$scene" baked.gltf && cp "$scene" renamed.gltf || exit 1
"$cli" bake baked.gltf -o grid.vdb --depth 3 --photons 20000 --quiet || { echo "FAILED: bake"; exit 1; }
meta=$("$cli" inspect grid.vdb)
echo "$meta" | grep -E "source_scene_(path|hash)"
echo "$meta" | grep -q "source_scene_path  $PWD/baked.gltf" || echo "FAILED: no absolute source_scene_path"
echo "$meta" | grep -qE "source_scene_hash  fnv1a64:[0-9a-f]{16}$" || echo "FAILED: no source_scene_hash"
warned() { "$cli" "$@" 2>&1 >/dev/null | grep -c "bake again if the scene changed"; }
[ "$(warned render renamed.gltf grid.vdb -o a.png --width 16 --height 12 --quiet)" = 0 ] ||
  echo "FAILED: a renamed copy of the same scene was taken for another"
printf ' ' >> renamed.gltf  # one byte more: another scene as far as anyone can tell
[ "$(warned render renamed.gltf grid.vdb -o b.png --width 16 --height 12 --quiet)" = 1 ] ||
  echo "FAILED: render did not warn of a changed scene"
[ "$(warned lightmap renamed.gltf grid.vdb -o lm.glb --quiet)" = 1 ] ||
  echo "FAILED: lightmap did not warn of a changed scene"
# A scene path with terminal escapes, recorded as source_scene_path: inspect
# and the warning print them escaped (\x1b), never the raw bytes that
# recolour or retitle the terminal.
odd=$(printf 'esc-\033[31m-\033]0;owned\007')
mkdir "$odd" && cp "$scene" "$odd/s.gltf" || exit 1
"$cli" bake "$odd/s.gltf" -o esc.vdb --depth 3 --photons 20000 --quiet ||
  echo "FAILED: bake from a folder named with escapes"
escaped='esc-\x1b[31m-\x1b]0;owned\x07/s.gltf'
inspected=$("$cli" inspect esc.vdb 2>&1 | grep source_scene_path)
printf ' ' >> "$odd/s.gltf"
rendered=$("$cli" render "$odd/s.gltf" esc.vdb -o esc.png --width 16 --height 12 --quiet \
  2>&1 >/dev/null)
for shown in "$inspected" "$rendered"; do
  printf '%s' "$shown" | grep -qF "$escaped" ||
    echo "FAILED: the path with escapes is not shown escaped: $(printf '%q' "$shown")"
  printf '%s' "$shown" | grep -q "$(printf '[\033\007]')" &&
    echo "FAILED: a control character of the metadata was printed raw: $(printf '%q' "$shown")"
done
echo "stale bakes: checked"
