#!/usr/bin/env python3
"""A diffuse sphere that was not in the bake, placed at five points of the
Cornell box, drawn by `render --mode full` (its light from the bake's
free-space light) and by the path tracer with the sphere in the scene.

For each position it measures, over the sphere's pixels only (the mask of
`reference --part added-mask`: the 4x4 bins whose every pixel sees the
sphere), the relative RMSE of the binned luminance and the ratio of the mean
luminances (`lightoctree compare --bin 4 --mask`), and the colour bleeding:
the sphere's redness, (R - G) / (R + G), on its half that faces the red wall
against the half that faces the green one. Ours is rendered with
`--supersample 4`: the path tracer integrates over each pixel's area, and
the bins at the sphere's edge hold pixels it only partly covers.

With --table it also measures ours against a second judge: the path tracer
with `--added-only-receive`, the sphere lit by the scene as baked, neither
shadowing nor lighting it. On the sphere's own pixels that is the light
`render --add` gives it (the baked light is not changed by what is added);
the gap between the two judges is the sphere's own shadow and bounce on the
scene.

Usage:
  measure_moving_sphere.py LIGHTOCTREE SCENE SPHERE WORKDIR [--size N] [--spp N]
                           [--check] [--table FILE] [--pictures DIR] [--bake-flag=FLAG ...]
                           [--render-flag=FLAG ...]

--check exits 1 unless every position is within its bound (POSITIONS: 10%, or
the figure measured with a margin where the 10% target is missed; RMSE and
mean) and the
wall positions bleed their wall's colour onto the side that faces it.
--table writes the figures as a Markdown table; --pictures writes, per
position, our image beside the path tracer's (PNG, for docs/render.md).
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import zlib

# Where the sphere goes (x, y, z in the box's units; radius 0.2), which
# wall's colour the test expects on the side facing it, and the bound
# --check holds the relative RMSE and the mean's error to: the 10%
# where it is met; where it is missed, the figure measured when the
# feature landed with a margin, so that a regression still fails
# (docs/results/free-space.md says which).
POSITIONS = [
    ("centre", "0,1,0", None, 0.10),
    ("near the red wall", "-0.72,1,0", "red", 0.10),
    ("near the green wall", "0.72,1,0", "green", 0.10),
    ("under the light", "0,1.65,0", None, 0.20),
    ("in the tall box's shadow", "-0.8,0.21,-0.3", None, 0.10),
]
TARGET = 0.10
RADIUS = 0.2


def run(*args):
    subprocess.run([str(a) for a in args], check=True, stdout=subprocess.DEVNULL)


def read_png(path):
    """8-bit RGB or RGBA, grey or grey+alpha, non-interlaced PNG: (w, h, rows of RGB tuples)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and interlace == 0, path
            channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        if channels >= 3:
            rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        else:
            rows.append([(line[x * channels],) * 3 for x in range(width)])
    return width, height, rows


def write_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(v for px in row for v in px) for row in rows)
    chunk = lambda kind, body: (struct.pack(">I", len(body)) + kind + body +
                                struct.pack(">I", zlib.crc32(kind + body) & 0xffffffff))
    with open(path, "wb") as out:
        out.write(b"\x89PNG\r\n\x1a\n")
        out.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        out.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        out.write(chunk(b"IEND", b""))


def bleeding(image_png, mask_png):
    """Redness (R - G) / (R + G) of the sphere's left and right halves in the image."""
    w, h, img = read_png(image_png)
    _, _, mask = read_png(mask_png)
    pixels = [(x, y) for y in range(h) for x in range(w) if mask[y][x][0] == 255]
    if not pixels:
        return None, None
    cx = sum(x for x, _ in pixels) / len(pixels)
    halves = {"left": [0.0, 0.0], "right": [0.0, 0.0]}
    for x, y in pixels:
        r, g, _ = img[y][x]
        side = halves["left" if x < cx else "right"]
        side[0] += r
        side[1] += g
    redness = lambda s: (s[0] - s[1]) / max(s[0] + s[1], 1e-9)
    return redness(halves["left"]), redness(halves["right"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("lightoctree")
    ap.add_argument("scene")
    ap.add_argument("sphere")
    ap.add_argument("workdir")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--table")
    ap.add_argument("--pictures")
    ap.add_argument("--bake-flag", action="append", default=[],
                    help="a flag for the bake, e.g. --bake-flag=--free-space-order=1 (repeatable)")
    ap.add_argument("--render-flag", action="append", default=[],
                    help="a flag for render, e.g. --render-flag=--free-space-tolerance=0 (repeatable)")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    cli = a.lightoctree
    grid = os.path.join(a.workdir, "grid.vdb")
    run(cli, "bake", a.scene, "-o", grid, "--quiet", *a.bake_flag)
    size = ["--width", a.size, "--height", a.size]
    rows, failed = [], []
    for k, (name, at, wall, bound) in enumerate(POSITIONS):
        place = ["--add", a.sphere, "--at", f"{at},0,{RADIUS}"]
        f = lambda ext, tag: os.path.join(a.workdir, f"{k}-{tag}.{ext}")
        render = [*size, *place, "--supersample", 4, "--quiet", *a.render_flag]
        run(cli, "render", a.scene, grid, "-o", f("exr", "render"), *render)
        run(cli, "render", a.scene, grid, "-o", f("png", "render"), *render)
        run(cli, "reference", a.scene, "-o", f("exr", "reference"), *size, "--spp", a.spp, *place,
            "--quiet")
        run(cli, "reference", a.scene, "-o", f("png", "mask"), "--part", "added-mask", *size,
            "--spp", 16, *place, "--quiet")
        run(cli, "compare", f("exr", "render"), f("exr", "reference"), "--mask", f("png", "mask"),
            "--bin", 4, "--json", f("json", "compare"), "--quiet")
        c = json.load(open(f("json", "compare")))
        rmse = c["channels"]["Y"]["rel_rmse"]
        mean = c["mean_test_luminance"] / c["mean_reference_luminance"]
        receive = None
        if a.table:
            run(cli, "reference", a.scene, "-o", f("exr", "receive"), *size, "--spp", a.spp,
                *place, "--added-only-receive", "--quiet")
            run(cli, "compare", f("exr", "render"), f("exr", "receive"), "--mask",
                f("png", "mask"), "--bin", 4, "--json", f("json", "receive"), "--quiet")
            r = json.load(open(f("json", "receive")))
            receive = (r["channels"]["Y"]["rel_rmse"],
                       r["mean_test_luminance"] / r["mean_reference_luminance"])
        left, right = bleeding(f("png", "render"), f("png", "mask"))
        met = rmse <= TARGET and abs(mean - 1) <= TARGET
        ok = rmse <= bound and abs(mean - 1) <= bound
        if wall == "red":
            ok = ok and left > right
        if wall == "green":
            ok = ok and right < left
        if not ok:
            failed.append(name)
        rows.append((name, at, c["compared_pixels"], rmse, mean, left, right, met, receive))
        if a.pictures:
            os.makedirs(a.pictures, exist_ok=True)
            run(cli, "reference", a.scene, "-o", f("png", "reference"), *size, "--spp", a.spp,
                *place, "--quiet")
            w, h, ours = read_png(f("png", "render"))
            _, _, truth = read_png(f("png", "reference"))
            gap = [(255, 255, 255)] * 4
            write_png(os.path.join(a.pictures, f"moving-sphere-{k}.png"), 2 * w + 4, h,
                      [ours[y] + gap + truth[y] for y in range(h)])
    lines = [
        "| position | --at | 4x4 bins | rel. RMSE (Y) | mean (ours / path tracer) | "
        "redness left / right | target 10% | sphere only receiving: rel. RMSE, mean |",
        "|---|---|---:|---:|---:|---:|---|---:|",
    ]
    for name, at, bins, rmse, mean, left, right, ok, receive in rows:
        second = f"{100 * receive[0]:.1f}%, {receive[1]:.3f}" if receive else "-"
        lines.append(f"| {name} | {at} | {bins} | {100 * rmse:.1f}% | {mean:.3f} | "
                     f"{left:+.3f} / {right:+.3f} | {'met' if ok else 'missed'} | {second} |")
    table = "\n".join(lines)
    print(table)
    if a.table:
        with open(a.table, "w") as out:
            out.write("# A sphere that was not baked, lit by the free-space light\n\n"
                      f"`python3 tools/measure_moving_sphere.py build/tools/lightoctree SCENE "
                      f"data/models/sphere.obj WORKDIR --size {a.size} --spp {a.spp}"
                      + "".join(f" --bake-flag={f}" for f in a.bake_flag)
                      + "".join(f" --render-flag={f}" for f in a.render_flag)
                      + "` on the Cornell box, baked at the defaults but for the flags named. A diffuse sphere (albedo 0.8, radius 0.2) "
                      "added with `--add data/models/sphere.obj --at X,Y,Z,0,0.2`: `render "
                      "--mode full --supersample 4` against `reference` (" + str(a.spp) +
                      " paths per pixel) of the scene with the sphere, over the 4x4 bins whose "
                      "every pixel sees the sphere (`compare --bin 4 --mask`, mask from "
                      "`reference --part added-mask`), luminance. Redness is (R - G) / (R + G) "
                      "of our image's sphere pixels, left half (towards the red wall) and right "
                      "half. The last column measures ours against `reference "
                      "--added-only-receive`: the sphere lit by the scene as baked, which it "
                      "neither shadows nor lights; on the sphere's own pixels, the light "
                      "`render --add` gives it.\n\n")
            out.write(table + "\n")
    if failed:
        print("moving sphere: FAILED at " + ", ".join(failed))
        return 1 if a.check else 0
    print("moving sphere: checked (every position within its bound, the walls' colours on "
          "their sides)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
