#!/usr/bin/env bash
# Inputs made from another scene (issue 43, family 7; docs/robustness.md):
# a photon map, or a .vdb given to convert --scene, carries the content hash
# of the scene it was made from (metadata source_scene_hash), and a command
# given another scene with it says so; the same scene says nothing. A photon
# map records the sky it was traced under (sky_hash) as the grid does.
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

if grep -q "another sky" <<<"$err"; then
  fail "photons of the grid's own sky were called another sky: $err"
fi

# A photon map traced under another sky (--sky 3,3,3; a.vdb has none): named,
# and the re-gathered grid records the photons' sky, the light it holds, so
# that render's sky check is not misled (it recorded the input's "none").
"$cli" bake "$scene" -o "$out/s.vdb" --photon-map "$out/s-photons.vdb" --depth 3 --photons 3000 \
  --knn 20 --sky 3,3,3 --quiet || fail "the bake under a sky failed"
err=$("$cli" convert "$out/a.vdb" -o "$out/sky.vdb" --scene "$scene" \
  --photon-map "$out/s-photons.vdb" --quiet 2>&1)
rc=$?
if [ "$rc" -ne 0 ] || ! grep -q -- "warning: --photon-map '.*s-photons.vdb' was traced under another sky" <<<"$err"; then
  fail "a photon map of another sky was taken without a word (exit $rc): $err"
fi
skyOf() { "$cli" inspect "$1" | awk '$1 == "sky_hash" {print $2}'; }
baked=$(skyOf "$out/s.vdb") regathered=$(skyOf "$out/sky.vdb") plain=$(skyOf "$out/a.vdb")
if [ -z "$baked" ] || [ "$baked" = none ] || [ "$regathered" != "$baked" ] || [ "$plain" != none ]; then
  fail "the re-gathered grid records sky '$regathered', its photons' sky is '$baked' (the input's '$plain')"
fi
err=$("$cli" render "$scene" "$out/sky.vdb" -o "$out/sky.exr" --width 8 --height 8 --quiet 2>&1)
if ! grep -q "baked under another sky" <<<"$err"; then
  fail "render without the photons' sky said nothing: $err"
fi

# A photon map traced with --include-direct, re-gathered into a grid baked
# without it: named, and the output records include_direct 1, so that render
# does not add the direct light a second time (it recorded the input's 0).
"$cli" bake "$scene" -o "$out/d.vdb" --photon-map "$out/d-photons.vdb" --depth 3 --photons 3000 \
  --knn 20 --include-direct --quiet || fail "the bake with --include-direct failed"
err=$("$cli" convert "$out/a.vdb" -o "$out/direct.vdb" --scene "$scene" \
  --photon-map "$out/d-photons.vdb" --quiet 2>&1)
rc=$?
if [ "$rc" -ne 0 ] || ! grep -q -- "was traced with --include-direct" <<<"$err"; then
  fail "a photon map with the direct light was taken without a word (exit $rc): $err"
fi
directOf() { "$cli" inspect "$1" | awk '$1 == "include_direct" {print $2}'; }
if [ "$(directOf "$out/direct.vdb")" != 1 ] || [ "$(directOf "$out/a.vdb")" != 0 ]; then
  fail "the re-gathered grid records include_direct '$(directOf "$out/direct.vdb")', its photons hold the direct light"
fi

[ "$failed" -eq 0 ] && echo "mismatched inputs: every one named"
