#!/usr/bin/env python3
"""bench_growth: work that grew faster than its input (issue 43, family 5),
measured at growing inputs; writes docs/results/growth.md.

Inputs made by tools/make_growth_scenes.py in a temporary folder:
  * N point lights in a room: `reference` (16 x 16, 4 spp) wall time and
    rays traced, and `lightmap --content full` (its direct light) time;
  * P primitives sharing one vertex buffer of 100,000 vertices: file size and
    the peak memory of loading it (`reference` of 8 x 8 pixels at 1 spp);
  * N small triangles (a height field, a soup of separate triangles, and a
    fan around one vertex): the lightmap's UV step ("UVs" of `lightmap
    --json`) and its charts.
Wall time and peak memory (the process's maximum resident set, from wait4).
The machine is shared: compare the rows of one run, and the growth along a
column (near-linear: 10x the input, about 10x the time), not runs.

Usage: python3 tools/bench_growth.py [--cli build/tools/lightoctree]
                                     [--out docs/results/growth.md] [--quick]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

from bench_bake_cost import run

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
MAKE = os.path.join(ROOT, "tools", "make_growth_scenes.py")


def make(work, kind, *numbers, shape=None):
    """tools/make_growth_scenes.py KIND NUMBERS... OUT [SHAPE], OUT a .glb in
    `work` named after its arguments; returns OUT."""
    words = [kind, *map(str, numbers)]
    extra = [shape] if shape else []
    path = os.path.join(work, "-".join(words + extra) + ".glb")
    subprocess.run([sys.executable, MAKE, *words, path, *extra], check=True)
    return path


def command(cli, work, *args):
    """`cli args --json` (exits on failure): (its report, wall seconds, peak MB)."""
    report = os.path.join(work, "report.json")
    code, seconds, peak, err = run([cli, *args, "--json", report])
    if code != 0:
        sys.exit(f"{' '.join(args)}: exit {code}: {err}")
    with open(report) as f:
        return json.load(f), seconds, peak


def stage_seconds(report, name):
    return next((stage["seconds"] for stage in report["stages"] if stage["name"] == name),
                float("nan"))


def bake(cli, work, scene, photons):
    vdb = os.path.join(work, "grid.vdb")
    code, _, _, err = run([cli, "bake", scene, "-o", vdb, "--photons", str(photons), "--depth", "4"])
    if code != 0:
        sys.exit(f"bake {scene}: {err}")
    return vdb


def lights_table(cli, work, counts):
    rows = ["| lights | `reference` s | of it, path tracing s | rays | `lightmap --content full` s "
            "| of it, direct light s |", "|---:|---:|---:|---:|---:|---:|"]
    for n in counts:
        scene = make(work, "lights", n)
        ref, seconds, _ = command(cli, work, "reference", scene, "-o", os.path.join(work, "r.exr"),
                                  "--width", "16", "--height", "16", "--spp", "4")
        vdb = bake(cli, work, scene, 50000)
        lm, lm_seconds, _ = command(cli, work, "lightmap", scene, vdb, "-o",
                                    os.path.join(work, "lm.glb"), "--content", "full")
        rows.append(f"| {n:,} | {seconds:.2f} | {stage_seconds(ref, 'path trace'):.2f} | "
                    f"{ref['figures']['rays']:,} | {lm_seconds:.2f} | "
                    f"{stage_seconds(lm, 'atlas: evaluate'):.2f} |")
    return rows


def shared_table(cli, work, counts, vertices):
    rows = ["| primitives | file | peak memory MB | seconds |", "|---:|---:|---:|---:|"]
    for p in counts:
        scene = make(work, "shared", p, vertices)
        _, seconds, peak = command(cli, work, "reference", scene, "-o", os.path.join(work, "s.exr"),
                                   "--width", "8", "--height", "8", "--spp", "1")
        rows.append(f"| {p:,} | {os.path.getsize(scene) / 1e6:.1f} MB | {peak:.0f} | {seconds:.2f} |")
    return rows


def charts_table(cli, work, counts, kinds):
    rows = ["| triangles | kind | charts | pages | UVs s | `lightmap` s |", "|---:|---|---:|---:|---:|---:|"]
    for n in counts:
        # The height field's bake serves all three: a fan or a soup under one
        # light keeps no photon (no surface sees another), and tracing a fan's
        # slivers, each spanning the disc's radius, is slow in any BVH.
        vdb = bake(cli, work, make(work, "triangles", n, shape="field"), 20000)
        for kind in kinds:
            scene = make(work, "triangles", n, shape=kind)
            lm, seconds, _ = command(cli, work, "lightmap", scene, vdb, "-o",
                                     os.path.join(work, "t.glb"))
            figures = lm["figures"]
            rows.append(f"| {n:,} | {kind} | {figures['charts']:,} | {figures['pages']} | "
                        f"{stage_seconds(lm, 'UVs'):.2f} | {seconds:.2f} |")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default=os.path.join(ROOT, "build", "tools", "lightoctree"))
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "growth.md"))
    parser.add_argument("--quick", action="store_true", help="the smaller inputs only")
    args = parser.parse_args()
    big = not args.quick
    with tempfile.TemporaryDirectory() as work:
        lights = lights_table(args.cli, work, [10, 1000, 100000] if big else [10, 1000])
        shared = shared_table(args.cli, work, [100, 1000, 10000] if big else [100, 1000], 100000)
        charts = charts_table(args.cli, work, [10000, 100000, 1000000] if big else [10000, 100000],
                              ["field", "soup", "fan"])
    text = ["# Work that grows with its input (issue 43, family 5)", "",
            "`python3 tools/bench_growth.py` (inputs by tools/make_growth_scenes.py; one run, "
            "on a shared machine: compare rows, not runs). docs/robustness.md, \"Work that "
            "grows with the input\", says what each row is about.", "",
            "## Point lights", "",
            "A 4 x 4 m room lit by N point lights of 1/N W/sr each. `reference` 16 x 16 at 4 spp; "
            "`lightmap --content full` at its defaults (64 direct samples per texel) from a bake of "
            "50,000 photons at depth 4. Seconds include loading the scene (20 MB of glTF for "
            "10^5 lights).", ""] + lights + [
            "", "## Primitives that share a vertex buffer", "",
            "One mesh of P primitives over the same 100,000 vertices (POSITION, NORMAL, "
            "TEXCOORD_0), each two triangles of its own: peak memory of `reference` at 8 x 8 "
            "pixels, 1 spp.", ""] + shared + [
            "", "## The lightmap's charts", "",
            "`lightmap` at its defaults (automatic charts, a quarter-voxel texel, the smallest "
            "page that holds them) from a bake of 20,000 photons at depth 4: the UV step's "
            "seconds (`--json`, \"UVs\") and the whole command's.", ""] + charts + [""]
    with open(args.out, "w") as f:
        f.write("\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
