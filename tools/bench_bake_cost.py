#!/usr/bin/env python3
"""bench_bake_cost: what a default bake costs on open and closed scenes, and
what the noise figure of the light seen (`--target-light seen`, the default)
saves against the figure of the indirect light alone (`--target-light
indirect`, the default before it); writes docs/results/bake-cost.md.

Scenes: the Cornell box (closed); the courtyard under a sun and a sky
(data/, open); the truck under its spots (../shared/scenes/real, a small
object under spot lights); data/emissive-cubes.gltf's three glowing cubes and
block with no floor or walls (made here: an object lit only by its own
emission, most of it leaving into the void); the Cornell box, and the shared
lamp room, each lit only by a spot under its floor (made here: a light that
reaches nothing); the enclosed game level (../shared) at depth 6 and 8; with
--helmet DIR, the Khronos sample DamagedHelmet alone (DIR/DamagedHelmet.gltf,
CC BY-NC, so not in this repository), lit only by its emissive texture. Per
scene and figure, one `lightoctree bake` at the defaults: wall time and peak
memory (the process's maximum resident set, from wait4), stored photons,
paths per stored photon, the noise figure and why the bake stopped
(`--stats-json`); then the picture: `render` 320 x 240 at the defaults
against `reference --part full` (tools/bench_public_scenes.py's cached
512-spp reference where there is one, else 256 spp made here), `compare
--bin 4 --clip-percentile 99`, RGB relative RMSE. The machine is shared:
compare rows of one run, not runs.

Usage: python3 tools/bench_bake_cost.py [--helmet DIR] [--out docs/results/bake-cost.md]
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def run(cmd):
    """Runs cmd; returns (exit code, wall seconds, peak resident MB, stderr)."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    err = proc.stderr.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    return os.waitstatus_to_exitcode(status), time.monotonic() - start, usage.ru_maxrss / 1024.0, err


def must(cmd):
    """Runs cmd and stops the benchmark, saying why, when it fails."""
    code, _, _, err = run(cmd)
    if code != 0:
        sys.exit(f"failed ({code}): {' '.join(cmd)}\n{err[-2000:]}")


def cellar_scene(work):
    """The Cornell box with its ceiling light off and a spot under its floor,
    aimed down: no light reaches a surface that holds any."""
    with open(os.path.join(ROOT, "data/cornell-box.gltf")) as f:
        doc = json.load(f)
    for m in doc["materials"]:
        if "emissiveFactor" in m:
            m["emissiveFactor"] = [0, 0, 0]
    for b in doc["buffers"]:
        if not b["uri"].startswith("data:"):
            b["uri"] = os.path.join(ROOT, "data", b["uri"])
    doc.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
    doc.setdefault("extensions", {})["KHR_lights_punctual"] = {
        "lights": [{"name": "cellar", "type": "spot", "intensity": 50.0, "spot": {"outerConeAngle": 0.5}}]}
    turn = math.sqrt(0.5)
    doc["nodes"].append({"name": "cellar", "translation": [0.27, -0.3, 0.27],
                         "rotation": [-turn, 0, 0, turn],  # -Z (a spot's axis) to -Y
                         "extensions": {"KHR_lights_punctual": {"light": 0}}})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    path = os.path.join(work, "cellar.gltf")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def lone_cubes_scene(work):
    """data/emissive-cubes.gltf without its floor and walls: the glowing
    cubes and the grey block between them, alone in the void."""
    with open(os.path.join(ROOT, "data/emissive-cubes.gltf")) as f:
        doc = json.load(f)
    keep = {"block", "warm", "red", "blue", "camera"}
    doc["scenes"][0]["nodes"] = [i for i, n in enumerate(doc["nodes"]) if n.get("name") in keep]
    path = os.path.join(work, "lone-cubes.gltf")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def lamp_cellar_scene(shared, work):
    """The shared lamp room with its five lights and its bulb's glow off and a
    spot under its floor (y = 0), aimed down."""
    folder = os.path.join(shared, "real/lights-punctual-lamp")
    with open(os.path.join(folder, "LightsPunctualLamp-room.gltf")) as f:
        doc = json.load(f)
    lit = {i for i, n in enumerate(doc["nodes"]) if "KHR_lights_punctual" in n.get("extensions", {})}
    doc["scenes"][0]["nodes"] = [i for i in doc["scenes"][0]["nodes"] if i not in lit]
    for m in doc["materials"]:  # the bulb's glow off too
        m.pop("emissiveTexture", None)
        m.pop("emissiveFactor", None)
    # The scene's files beside the new one (a scene may not reach outside
    # its own folder).
    work = os.path.join(work, "lamp-cellar")
    os.makedirs(work, exist_ok=True)
    for item in doc.get("buffers", []) + doc.get("images", []):
        if "uri" in item and not item["uri"].startswith("data:"):
            shutil.copyfile(os.path.join(folder, item["uri"]), os.path.join(work, item["uri"]))
    lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
    lights.append({"name": "cellar", "type": "spot", "intensity": 200.0, "spot": {"outerConeAngle": 0.5}})
    turn = math.sqrt(0.5)
    doc["nodes"].append({"name": "cellar", "translation": [0.0, -0.5, 0.0],
                         "rotation": [-turn, 0, 0, turn],  # -Z (a spot's axis) to -Y
                         "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    path = os.path.join(work, "lamp-cellar.gltf")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def picture_error(cli, scene, grid, key, work):
    """The bake's picture against the path tracer: RGB relative RMSE of
    `render` 320 x 240 against a full reference (bench_public_scenes.py's
    cached one for `key` when present), 4x4 bins, clipped at the 99th
    percentile."""
    size = ["--width", "320", "--height", "240"]
    ref = os.path.join(ROOT, "out/bench-public", key or "-", "ref-512.exr")
    if not key or not os.path.exists(ref):
        ref = os.path.join(work, os.path.basename(scene) + "-ref-256.exr")
        if not os.path.exists(ref):
            must([cli, "reference", scene, "-o", ref, "--part", "full", "--spp", "256"] + size)
    image = os.path.join(work, "picture.exr")
    must([cli, "render", scene, grid, "-o", image] + size)
    figures = os.path.join(work, "compare.json")
    must([cli, "compare", image, ref, "--bin", "4", "--clip-percentile", "99", "--json", figures, "-q"])
    with open(figures) as f:
        return json.load(f)["channels"]["RGB"]["rel_rmse"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cli", default=os.path.join(ROOT, "build/tools/lightoctree"))
    ap.add_argument("--shared", default=os.path.join(ROOT, "../shared/scenes"))
    ap.add_argument("--work", default=os.path.join(ROOT, "out/bench-bake-cost"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/results/bake-cost.md"))
    ap.add_argument("--helmet", help="folder with the Khronos sample DamagedHelmet.gltf and its files")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    real = os.path.join(args.shared, "real")
    # name, file, depth, the key of bench_public_scenes.py's cached reference
    scenes = [
        ("Cornell box (closed)", os.path.join(ROOT, "data/cornell-box.gltf"), 6, "cornell-box"),
        ("courtyard, sun and sky (open)", os.path.join(ROOT, "data/courtyard.gltf"), 6, "courtyard"),
        ("truck under spots (small object)", os.path.join(real, "milk-truck-spots/truck-under-spots.gltf"), 6,
         "truck-spots"),
        ("emissive cubes alone, no walls (open, lit by its own emission)", lone_cubes_scene(args.work), 6, None),
        ("Cornell box, only a spot under the floor", cellar_scene(args.work), 6, None),
        ("shared lamp room, only a spot under the floor", lamp_cellar_scene(args.shared, args.work), 6, None),
        ("game level (enclosed)", os.path.join(real, "zdm2-sauerbraten/zdm2-godot-lights.glb"), 6, "game-level"),
        ("game level (enclosed)", os.path.join(real, "zdm2-sauerbraten/zdm2-godot-lights.glb"), 8, "game-level"),
    ]
    if args.helmet:
        helmet = os.path.join(args.helmet, "DamagedHelmet.gltf")
        if not os.path.exists(helmet):
            sys.exit(f"--helmet: no DamagedHelmet.gltf in {args.helmet}")
        scenes.insert(4, ("DamagedHelmet alone (open, lit by its own emissive texture)", helmet, 6, None))
    rows = []
    for name, path, depth, key in scenes:
        # The helmet alone under the indirect figure traces for many minutes
        # (its indirect light is a sliver of what it emits): its default row only.
        for light in ("seen",) if path.endswith("DamagedHelmet.gltf") else ("seen", "indirect"):
            stats = os.path.join(args.work, "stats.json")
            if os.path.exists(stats):
                os.remove(stats)
            cmd = [args.cli, "bake", path, "-o", os.path.join(args.work, "grid.vdb"), "--depth", str(depth),
                   "--target-light", light, "--stats-json", stats, "--quiet"]
            code, wall, peak, err = run(cmd)
            row = {"scene": name, "depth": depth, "light": light, "seconds": wall, "peak": peak}
            if code == 0:
                with open(stats) as f:
                    s = json.load(f)
                c = s["counts"]
                row.update(photons=c["stored_photons"], paths=c["emitted_paths"],
                           noise=s["noise"]["quantile"], stop=s["target"]["stop"],
                           warning=err.strip().splitlines()[-1] if err.strip() else "",
                           picture=picture_error(args.cli, path, os.path.join(args.work, "grid.vdb"), key,
                                                 args.work))
            else:
                row.update(error=err.strip().splitlines()[-1] if err.strip() else f"exit {code}")
            rows.append(row)
            print(f"{name}, depth {depth}, {light}: {wall:.2f} s, {peak:.0f} MB", flush=True)

    base = next(r["seconds"] for r in rows if r["scene"].startswith("Cornell box (closed)") and r["light"] == "seen")
    lines = [
        "# What a default bake costs, open and closed",
        "",
        "Made by `python3 tools/bench_bake_cost.py` (one run; the machine is shared, so compare",
        "rows of this table, not runs): `lightoctree bake SCENE --depth D --target-light seen|indirect`,",
        "every other setting at its default (`--target-error 0.07`). *Seen* is the default: the noise",
        "figure divides each voxel's indirect noise by its direct plus indirect light; *indirect* divides",
        "by the indirect light alone, the figure before `--target-light` (docs/accuracy.md). Time and",
        "peak memory are the whole command's; paths per photon = paths traced / photons stored;",
        "picture = `render` 320 x 240 at the defaults against `reference --part full` (512 spp where",
        "tools/bench_public_scenes.py cached one, else 256 spp), 4x4-binned RGB relative RMSE, each",
        "channel clipped at the reference's 99th percentile, all pixels.",
        "",
        "| scene | depth | figure | time | vs Cornell | peak memory | photons | paths per photon | noise | stop | picture |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            stop = "refused: " + r["error"].replace("|", "/")
            lines.append(f"| {r['scene']} | {r['depth']} | {r['light']} | {r['seconds']:.2f} s | "
                         f"{r['seconds'] / base:.1f}x | {r['peak']:.0f} MB | - | - | - | {stop} | - |")
            continue
        ppp = r["paths"] / max(r["photons"], 1)
        lines.append(f"| {r['scene']} | {r['depth']} | {r['light']} | {r['seconds']:.2f} s | "
                     f"{r['seconds'] / base:.1f}x | {r['peak']:.0f} MB | {r['photons']:,} | {ppp:.1f} | "
                     f"{100 * r['noise']:.1f}% | {r['stop']} | {100 * r['picture']:.1f}% |")
    lines += ["", f"CPU: {os.cpu_count()} threads. Command line: `{' '.join(sys.argv)}`.", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
