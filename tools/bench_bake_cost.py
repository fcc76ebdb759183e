#!/usr/bin/env python3
"""bench_bake_cost: what a default bake costs on open and closed scenes, and
what the noise figure of the light seen (`--target-light seen`, the default)
saves against the figure of the indirect light alone (`--target-light
indirect`, the default before it); writes docs/results/bake-cost.md.

Scenes: the Cornell box (closed); the courtyard under a sun and a sky
(data/, open); the truck under its spots (../shared/scenes/real, a small
object under spot lights); the Cornell box lit only by a spot under its
floor (made here: a light that reaches nothing); the enclosed game level
(../shared) at depth 6 and 8. Per scene and figure, one `lightoctree bake`
at the defaults: wall time and peak memory (the process's maximum resident
set, from wait4), stored photons, paths per stored photon, the noise figure
and why the bake stopped (`--stats-json`). The machine is shared: compare
rows of one run, not runs.

Usage: python3 tools/bench_bake_cost.py [--out docs/results/bake-cost.md]
"""

import argparse
import json
import math
import os
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cli", default=os.path.join(ROOT, "build/tools/lightoctree"))
    ap.add_argument("--shared", default=os.path.join(ROOT, "../shared/scenes"))
    ap.add_argument("--work", default=os.path.join(ROOT, "out/bench-bake-cost"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/results/bake-cost.md"))
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    real = os.path.join(args.shared, "real")
    scenes = [
        ("Cornell box (closed)", os.path.join(ROOT, "data/cornell-box.gltf"), 6),
        ("courtyard, sun and sky (open)", os.path.join(ROOT, "data/courtyard.gltf"), 6),
        ("truck under spots (small object)", os.path.join(real, "milk-truck-spots/truck-under-spots.gltf"), 6),
        ("Cornell box, only a spot under the floor", cellar_scene(args.work), 6),
        ("game level (enclosed)", os.path.join(real, "zdm2-sauerbraten/zdm2-godot-lights.glb"), 6),
        ("game level (enclosed)", os.path.join(real, "zdm2-sauerbraten/zdm2-godot-lights.glb"), 8),
    ]
    rows = []
    for name, path, depth in scenes:
        for light in ("seen", "indirect"):
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
                           warning=err.strip().splitlines()[-1] if err.strip() else "")
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
        "peak memory are the whole command's; paths per photon = paths traced / photons stored.",
        "",
        "| scene | depth | figure | time | vs Cornell | peak memory | photons | paths per photon | noise | stop |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            stop = "refused: " + r["error"].replace("|", "/")
            lines.append(f"| {r['scene']} | {r['depth']} | {r['light']} | {r['seconds']:.2f} s | "
                         f"{r['seconds'] / base:.1f}x | {r['peak']:.0f} MB | - | - | - | {stop} |")
            continue
        ppp = r["paths"] / max(r["photons"], 1)
        lines.append(f"| {r['scene']} | {r['depth']} | {r['light']} | {r['seconds']:.2f} s | "
                     f"{r['seconds'] / base:.1f}x | {r['peak']:.0f} MB | {r['photons']:,} | {ppp:.1f} | "
                     f"{100 * r['noise']:.1f}% | {r['stop']} |")
    lines += ["", f"CPU: {os.cpu_count()} threads. Command line: `{' '.join(sys.argv)}`.", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
