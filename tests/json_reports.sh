#!/usr/bin/env bash
# `--json FILE` of every command that writes files (README.md, "Scripting"):
# each report is valid JSON naming the command, what it read and every file
# it wrote with its size on disk, and the figures it printed.
# Usage: json_reports.sh LIGHTOCTREE SCENE WORKDIR
set -u
cli=$1 scene=$2 dir=$3
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
run() { "$@" --quiet || { echo "FAILED: $*"; exit 1; }; }
run "$cli" bake "$scene" -o grid.vdb --depth 4 --photons 20000 --json bake.json
run "$cli" render "$scene" grid.vdb -o render.png --width 64 --height 48 --json render.json
run "$cli" lightmap "$scene" grid.vdb -o lm.gltf --image png --preview-unlit --json lightmap.json
run "$cli" convert grid.vdb -o coarse.vdb --depth 3 --json convert.json
run "$cli" reference "$scene" -o ref.exr --width 32 --height 24 --spp 2 --emitter-mask mask.png --json reference.json
"$cli" compare ref.exr ref.exr --json compare.json > /dev/null || { echo "FAILED: compare"; exit 1; }
python3 - <<'PY' || exit 1
import json, os
def load(name):
    with open(name) as f:
        return json.load(f)
bake = load("bake.json")
assert bake["output"] == "grid.vdb" and bake["counts"]["vdb_bytes"] == os.path.getsize("grid.vdb"), bake["counts"]
checks = {
    "render": (["render.png"], lambda f: f["image"]["width"] == 64 and f["image"]["mean_luminance"] > 0),
    "lightmap": (["lm-lightmap0.png", "lm-direction0.png", "lm.bin", "lm.gltf", "lm-preview.glb"],
                 lambda f: f["pages"] == 1 and f["rgbm_range"] > 0 and f["encoding"] == "rgbm-png"
                 and f["page_files"] == ["lm-lightmap0.png"]
                 and f["direction_files"] == ["lm-direction0.png"]),
    "convert": (["coarse.vdb"], lambda f: f["depth"] == {"in": 4, "out": 3} and f["voxels"]["out"] > 0),
    "reference": (["ref.exr", "mask.png"], lambda f: f["samples_per_pixel"] == 2 and f["rays"] > 0),
}
for command, (files, figures) in checks.items():
    report = load(command + ".json")
    assert report["command"] == command, report["command"]
    written = [w["path"] for w in report["written"]]
    assert sorted(written) == sorted(files), (command, written)
    for w in report["written"]:
        assert w["bytes"] == os.path.getsize(w["path"]), (command, w)
    assert any(r["role"] == "SCENE" for r in report["read"]) or command == "convert", report["read"]
    assert figures(report["figures"]), (command, report["figures"])
    assert report["stages"] and all(s["seconds"] >= 0 for s in report["stages"]), (command, report["stages"])
    print(command + ": " + ", ".join(written))
assert load("compare.json")["channels"]["Y"]["rel_rmse"] == 0
print("json reports: all commands report what they wrote")
PY
