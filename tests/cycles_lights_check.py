#!/usr/bin/env python3
"""Checks that tools/cycles_reference.py lights a scene in the project's units:
a Lambert floor under a point light and under a glTF spot (a wide penumbra)
of 1 W/sr, 1 m above it, seen from above, against the analytic mean radiance
(1/pi E, E = I cos / d^2, times glTF's spot falloff). Cycles is the judge of
the path tracer (docs/accuracy.md); a judge in the wrong units judges wrongly.

Usage: cycles_lights_check.py BLENDER SCRIPT OUT_DIR
"""

import base64
import json
import math
import os
import re
import struct
import subprocess
import sys


def scene(kind):
    positions = [-5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5]
    indices = [0, 2, 1, 0, 3, 2]
    data = struct.pack("<12f", *positions) + struct.pack("<6I", *indices)
    light = {"name": "L", "type": kind, "intensity": 1.0}
    if kind == "spot":
        light["spot"] = {"innerConeAngle": 0.2, "outerConeAngle": 0.45}
    down = [-math.sqrt(0.5), 0, 0, math.sqrt(0.5)]  # -Z turned to -Y
    return {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"mesh": 0},
                  {"name": "L", "translation": [0, 1, 0], "rotation": down,
                   "extensions": {"KHR_lights_punctual": {"light": 0}}},
                  {"name": "camera", "camera": 0, "translation": [0, 3, 0], "rotation": down}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.3, "znear": 0.01}}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light]}},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"name": "white", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1}}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [-5, 0, -5], "max": [5, 0, 5]},
                      {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}],
    }


def analytic(kind, n=32):
    """Mean radiance over the n x n pixels of the camera above the floor."""
    t = math.tan(0.15)
    total = 0.0
    for j in range(n):
        for i in range(n):
            x = ((i + 0.5) / n * 2 - 1) * t * 3
            z = ((j + 0.5) / n * 2 - 1) * t * 3
            d2 = x * x + z * z + 1
            cosine = 1 / math.sqrt(d2)
            falloff = 1.0
            if kind == "spot":
                a = (cosine - math.cos(0.45)) / (math.cos(0.2) - math.cos(0.45))
                falloff = min(max(a, 0.0), 1.0) ** 2
            total += falloff * cosine / d2 / math.pi
    return total / (n * n)


def main():
    blender, script, out = sys.argv[1:4]
    if not os.access(blender, os.X_OK):
        sys.exit("Blender not found ('%s'): bash tools/test.sh installs it (Debian's blender "
                 "and python3-numpy)" % blender)
    os.makedirs(out, exist_ok=True)
    failed = False
    for kind in ("point", "spot"):
        path = os.path.join(out, kind + ".gltf")
        with open(path, "w") as f:
            json.dump(scene(kind), f)
        # Blender's Python is the system's: a Python manager's folders in PATH
        # (pyenv) would hand it another interpreter's modules (no numpy).
        env = dict(os.environ)
        env["PATH"] = os.pathsep.join(
            d for d in env.get("PATH", "").split(os.pathsep) if ".pyenv" not in d)
        result = subprocess.run(
            [blender, "-b", "--factory-startup", "-P", script, "--", path,
             os.path.join(out, kind + ".exr"), "--width", "32", "--height", "32", "--spp", "64",
             "--material", "lambert"], capture_output=True, text=True, env=env)
        match = re.search(r"mean RGB ([0-9.e+-]+)", result.stdout)
        if result.returncode != 0 or not match:
            print(result.stdout[-2000:], result.stderr[-2000:])
            sys.exit("%s: Blender failed (exit %d)" % (kind, result.returncode))
        got, expected = float(match.group(1)), analytic(kind)
        ok = abs(got - expected) <= 0.01 * expected
        failed |= not ok
        print("%s light: Cycles mean %.5f, analytic %.5f (%+.2f%%) %s" %
              (kind, got, expected, 100 * (got / expected - 1), "ok" if ok else "FAILED"))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
