#!/usr/bin/env python3
"""bench_real_assets: what a user waits for and how much memory it takes on
textured assets others made, command by command as a user runs them
(`lightoctree bake`, `render`, `lightmap`), and writes the table to
docs/results/real-assets.md.

Scenes: the Cornell box (data/, untextured: the baseline), the textured OBJ
room, the truck under spot lights and the lamp room of five point lights and
an emissive texture (../shared/scenes/real), and, when
--helmet names a folder holding the Khronos sample DamagedHelmet
(DamagedHelmet.gltf, its .bin and five 2048^2 JPEGs; CC BY-NC, so it is not
in this repository), that helmet in a room under a spot light and lit by its
emissive texture alone (tools/make_helmet_room.py writes both beside it).
On a machine with a GPU, `--backend egl --out docs/results/real-assets-egl.md`
fills the same table through EGL.

Per scene: the bake at the defaults (a fixed 1,000,000 photons for the
emissive helmet, to count paths per stored photon); `render` at 320 x 240
(osmesa) with the `--json` report's stages (load, read grid, GL context,
octree, shaders, octree upload, lights, geometry and textures, shadow maps,
first frame); `lightmap` and the .glb's size
against the scene's files. Wall time and peak memory (the process's maximum
resident set, from wait4) of each command. The machine is shared: compare
rows of one run, not runs.

Usage: python3 tools/bench_real_assets.py [--helmet DIR] [--out docs/results/real-assets.md]
"""

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def run(cmd):
    """Runs cmd; returns (wall seconds, peak resident MB)."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - start
    err = proc.stderr.read().decode(errors="replace")
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{err}")
    return wall, usage.ru_maxrss / 1024.0


def stages(report):
    with open(report) as f:
        return {s["name"]: s for s in json.load(f)["stages"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cli", default=os.path.join(ROOT, "build/tools/lightoctree"))
    ap.add_argument("--shared", default=os.path.join(ROOT, "../shared/scenes"))
    ap.add_argument("--helmet", help="folder with DamagedHelmet.gltf and its files")
    ap.add_argument("--work", default=os.path.join(ROOT, "out/bench-real"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/results/real-assets.md"))
    ap.add_argument("--backend", default="osmesa", choices=["osmesa", "egl"],
                    help="render's headless GL: osmesa (llvmpipe) or egl (a GPU; with --out "
                         "docs/results/real-assets-egl.md)")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    cli = args.cli

    scenes = [("Cornell box (no textures)", os.path.join(ROOT, "data/cornell-box.gltf"), None)]
    real = os.path.join(args.shared, "real")
    for label, path in [("Viking room (OBJ, 1024² PNG)", "viking-room/viking_room_lit.obj"),
                        ("Milk truck under spots (2048² PNG)", "milk-truck-spots/truck-under-spots.gltf"),
                        ("Lamp room, five point lights and an emissive texture",
                         "lights-punctual-lamp/LightsPunctualLamp-room.gltf")]:
        if os.path.isfile(os.path.join(real, path)):
            scenes.append((label, os.path.join(real, path), None))
    if args.helmet:
        src = os.path.join(args.helmet, "DamagedHelmet.gltf")
        for extra in ([], ["--emissive-only"]):
            subprocess.run([sys.executable, os.path.join(ROOT, "tools/make_helmet_room.py"), src] + extra,
                           check=True, stdout=subprocess.DEVNULL)
        scenes.append(("DamagedHelmet in a room, spot (five 2048² JPEGs)",
                       os.path.join(args.helmet, "helmet-room.gltf"), None))
        scenes.append(("DamagedHelmet, emissive texture only (1M photons)",
                       os.path.join(args.helmet, "helmet-emissive.gltf"), "1000000"))

    rows = []
    for label, scene, photons in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        vdb = os.path.join(args.work, name + ".vdb")
        bake_json = os.path.join(args.work, name + "-bake.json")
        cmd = [cli, "bake", scene, "-o", vdb, "--json", bake_json, "--quiet"]
        if photons:
            cmd += ["--photons", photons]
        bake_wall, bake_peak = run(cmd)
        with open(bake_json) as f:
            bake = json.load(f)
        bake_stages = {s["name"]: s for s in bake["stages"]}
        traced = [s for s in bake["stages"] if s["name"] == "trace photons"]
        render_json = os.path.join(args.work, name + "-render.json")
        render = [cli, "render", scene, vdb, "-o", os.path.join(args.work, name + ".png"),
                  "--width", "320", "--height", "240", "--backend", args.backend,
                  "--json", render_json, "--quiet"]
        # Twice, the second measured: the driver compiles each shader
        # program the first time it meets it (about a second each on
        # llvmpipe) and caches it on disk for every later run.
        run(render)
        render_wall, render_peak = run(render)
        r = stages(render_json)
        glb = os.path.join(args.work, name + "-lit.glb")
        lightmap_wall, lightmap_peak = run([cli, "lightmap", scene, vdb, "-o", glb, "--quiet",
                                            "--json", os.path.join(args.work, name + "-lightmap.json")])
        with open(os.path.join(args.work, name + "-lightmap.json")) as f:
            lm = json.load(f)
        inputs = sum(os.path.getsize(x["path"] if os.path.isabs(x["path"]) else x["path"])
                     for x in lm["read"] if x["role"].startswith("SCENE") and os.path.isfile(x["path"]))
        pages = sum(x["bytes"] for x in lm["written"] if "-lightmap" in x["path"] or "-direction" in x["path"])
        glb_bytes = os.path.getsize(glb)
        rows.append({
            "scene": label,
            "bake_s": bake_wall, "bake_mb": bake_peak,
            "bake_load_s": bake_stages["load scene"]["seconds"],
            "bake_load_mb": bake_stages["load scene"]["peak_rss_bytes"] / 2**20,
            "photons": bake["counts"].get("stored_photons", 0) if "counts" in bake else 0,
            "paths": bake["counts"].get("emitted_paths", 0) if "counts" in bake else 0,
            "render_s": render_wall, "render_mb": render_peak,
            "load_s": r["load scene"]["seconds"],
            "upload_s": sum(r[k]["seconds"] for k in ("shaders", "octree upload", "lights", "geometry and textures",
                                                      "shadow maps", "prepare lighting") if k in r),
            "textures_mb": (r["geometry and textures"]["rss_bytes"] - r["lights"]["rss_bytes"]) / 2**20,
            "shadows_mb": (r["shadow maps"]["rss_bytes"] - r["geometry and textures"]["rss_bytes"]) / 2**20,
            "frame_s": r["first frame"]["seconds"],
            "lightmap_s": lightmap_wall, "lightmap_mb": lightmap_peak,
            "glb_mb": glb_bytes / 2**20, "inputs_mb": inputs / 2**20, "pages_mb": pages / 2**20,
        })
        print(f"{label}: done", flush=True)

    lines = [
        "# Real assets: load, first frame, memory",
        "",
        "Written by `python3 tools/bench_real_assets.py" + (" --helmet DIR" if args.helmet else "") +
        (" --backend egl" if args.backend == "egl" else "") +
        "` (" + ("a GPU through EGL" if args.backend == "egl" else
                 "this machine: 2 cores, llvmpipe through OSMesa") + ", shared with other work;",
        "compare the rows of one run). Every figure is one run of the command a user types:",
        "wall time and peak resident memory of the process. `render` is 320 × 240 in full mode;",
        "its stages come from its `--json` report (upload: shaders, octree, lights, geometry and",
        "textures (the scene's texels freed as each texture's GPU copy is made), shadow maps, with",
        "what the last two added to the process's memory);",
        "it runs twice and the second run is measured, the driver's shader cache then warm (a",
        "first run compiles each shader program it meets, about a second each on llvmpipe).",
        "The bake runs at the defaults (target noise 0.07), the emissive helmet's at a fixed",
        "1,000,000 photons.",
        "",
        "| scene | bake s | bake MB | bake: load s / MB | photons / paths | render s | render MB | load s | upload s (+MB: textures, shadows) | first frame s | lightmap s / MB | .glb MB (scene files + pages) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for x in rows:
        lines.append(
            f"| {x['scene']} | {x['bake_s']:.2f} | {x['bake_mb']:.0f} | {x['bake_load_s']:.2f} / {x['bake_load_mb']:.0f} | "
            f"{x['photons'] / max(x['paths'], 1):.2f} | "
            f"{x['render_s']:.2f} | {x['render_mb']:.0f} | {x['load_s']:.2f} | "
            f"{x['upload_s']:.2f} (+{x['textures_mb']:.0f}, +{x['shadows_mb']:.0f}) | {x['frame_s']:.2f} | "
            f"{x['lightmap_s']:.1f} / {x['lightmap_mb']:.0f} | {x['glb_mb']:.2f} ({x['inputs_mb']:.2f} + {x['pages_mb']:.2f}) |")
    lines.append("")
    text = "\n".join(lines)
    print(text)
    if os.path.exists(args.out):
        with open(args.out) as f:
            old = f.read()
        marker = "<!-- table end -->"
        rest = old.split(marker, 1)[1] if marker in old else ""
    else:
        rest = "\n"
    with open(args.out, "w") as f:
        f.write(text + "<!-- table end -->" + rest)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
