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
echo "stale bakes: checked"
