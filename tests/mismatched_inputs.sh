#!/usr/bin/env bash
# Inputs made from another scene (issue 43, family 7; docs/robustness.md):
# a photon map, or a .vdb given to convert --scene, carries the content hash
# of the scene it was made from (metadata source_scene_hash), and a command
# given another scene with it says so; the same scene says nothing.
# Usage: mismatched_inputs.sh CLI SCENE OUT_DIR
set -u
cli=$1 scene=$2 out=$3
rm -rf "$out"
mkdir -p "$out"
failed=0
fail() { echo "FAILED: $*"; failed=1; }
other=$(dirname "$scene")/emissive-cubes.gltf

"$cli" bake "$scene" -o "$out/a.vdb" --photon-map "$out/a-photons.vdb" --depth 3 --photons 3000 \
  --knn 20 --quiet || fail "the bake failed"
"$cli" bake "$other" -o "$out/b.vdb" --photon-map "$out/b-photons.vdb" --depth 3 --photons 3000 \
  --knn 20 --quiet || fail "the other bake failed"

# The photon map of the other scene: named, the conversion still runs.
err=$("$cli" convert "$out/a.vdb" -o "$out/mixed.vdb" --scene "$scene" \
  --photon-map "$out/b-photons.vdb" --quiet 2>&1)
rc=$?
if ! grep -q -- "warning: --photon-map '.*b-photons.vdb' was made from a scene with content hash" <<<"$err"; then
  fail "a photon map of another scene was taken without a word (exit $rc): $err"
fi
# A .vdb of another scene given to convert --scene: named too.
err=$("$cli" convert "$out/b.vdb" -o "$out/mixed2.vdb" --scene "$scene" --depth 4 --quiet 2>&1)
if ! grep -q -- "warning: IN '.*b.vdb' was made from a scene with content hash" <<<"$err"; then
  fail "a .vdb of another scene was taken by convert --scene without a word: $err"
fi
# The matching scene: no warning.
err=$("$cli" convert "$out/a.vdb" -o "$out/same.vdb" --scene "$scene" \
  --photon-map "$out/a-photons.vdb" --quiet 2>&1)
rc=$?
if [ "$rc" -ne 0 ] || grep -q "another scene" <<<"$err"; then
  fail "the matching photon map: exit $rc: $err"
fi

[ "$failed" -eq 0 ] && echo "mismatched inputs: every one named"
