#!/usr/bin/env python3
"""Writes the hostile inputs of issue 43, family 5 ("work that grows faster
than its input"), made by code so that none is committed:

  lights N OUT.glb      a 4 x 4 m room (floor, three walls, grey) lit by N
                        point lights at pseudo-random places 0.5-2.5 m above
                        the floor, 1 W/sr each over N (the same total
                        power whatever N), and a camera looking in;
  shared P V OUT.glb    one mesh of P primitives that all use the same V
                        vertices (POSITION, NORMAL, TEXCOORD_0 accessors shared),
                        each with its own short index list (two triangles of
                        a V-vertex strip): a file of about 32 V + 12 P bytes
                        that a loader which copies the vertices per primitive
                        turns into P x V vertices;
  triangles N OUT.glb   N small triangles: a height field of about N triangles
                        over a 10 x 10 m square (hills 0.8 m high, slopes to
                        54 degrees: about a hundred charts), plus a point light;
                        a fifth argument "soup": N separate triangles that
                        share no edge (one chart each), "fan": a disc of
                        radius 5 m as one fan of N triangles around its
                        centre (one chart outlined by N vertices).

Binary glTF (.glb), standard library only. The pseudo-random numbers are a
fixed linear congruential sequence: the same arguments give the same bytes.

Usage: python3 tools/make_growth_scenes.py lights 100000 lights.glb
"""

import json
import math
import struct
import sys

from make_courtyard import camera_rotation


def lcg(seed):
    state = seed
    while True:
        state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        yield (state >> 11) / float(1 << 53)


class Glb:
    """One buffer, views and accessors appended in order."""

    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def add(self, values, fmt, count, kind, component, target=None, bounds=None):
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        self.data += struct.pack("<" + fmt * (len(values)), *values)
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(self.data) - offset}
        if target:
            view["target"] = target
        self.views.append(view)
        acc = {"bufferView": len(self.views) - 1, "componentType": component,
               "count": count, "type": kind}
        if bounds:
            acc["min"], acc["max"] = bounds
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def positions(self, xyz):
        n = len(xyz) // 3
        lo = [min(xyz[i::3]) for i in range(3)]
        hi = [max(xyz[i::3]) for i in range(3)]
        return self.add(xyz, "f", n, "VEC3", 5126, 34962, (lo, hi))

    def write(self, path, doc):
        doc["asset"] = {"version": "2.0", "generator": "tools/make_growth_scenes.py"}
        doc["buffers"] = [{"byteLength": len(self.data)}]
        doc["bufferViews"] = self.views
        doc["accessors"] = self.accessors
        text = json.dumps(doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        while len(self.data) % 4:
            self.data.append(0)
        total = 12 + 8 + len(text) + 8 + len(self.data)
        with open(path, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, total))
            f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
            f.write(struct.pack("<II", len(self.data), 0x004E4942) + bytes(self.data))


def grey():
    return [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1],
                                                      "metallicFactor": 0, "roughnessFactor": 1}}]


def camera(eye, target):
    return {"name": "camera", "camera": 0, "translation": list(eye),
            "rotation": camera_rotation(eye, target)}


def room(glb):
    """Floor and three walls of a 4 x 4 x 3 m room, facing in: one primitive."""
    quads = [((-2, 0, -2), (0, 0, 4), (4, 0, 0)), ((-2, 0, -2), (4, 0, 0), (0, 3, 0)),
             ((-2, 0, -2), (0, 3, 0), (0, 0, 4)), ((2, 0, -2), (0, 0, 4), (0, 3, 0))]
    xyz, idx = [], []
    for o, a, b in quads:
        base = len(xyz) // 3
        for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
            xyz += [o[i] + u * a[i] + v * b[i] for i in range(3)]
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    pos = glb.positions(xyz)
    ind = glb.add(idx, "I", len(idx), "SCALAR", 5125, 34963)
    return {"attributes": {"POSITION": pos}, "indices": ind, "material": 0}


def lights(n, out):
    glb = Glb()
    prim = room(glb)
    rand = lcg(43)
    lamps, nodes = [], [{"mesh": 0}]
    for i in range(n):
        x, y, z = -1.8 + 3.6 * next(rand), 0.5 + 2.0 * next(rand), -1.8 + 3.6 * next(rand)
        lamps.append({"type": "point", "intensity": 1.0 / n * 4 * math.pi,
                      "color": [1, 1, 1]})
        nodes.append({"translation": [x, y, z],
                      "extensions": {"KHR_lights_punctual": {"light": i}}})
    nodes.append(camera((0, 1.5, 5.5), (0, 1.0, 0)))
    glb.write(out, {"scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
                    "meshes": [{"primitives": [prim]}], "materials": grey(),
                    "cameras": [{"type": "perspective",
                                 "perspective": {"yfov": 0.9, "znear": 0.01}}],
                    "extensionsUsed": ["KHR_lights_punctual"],
                    "extensions": {"KHR_lights_punctual": {"lights": lamps}}})


def shared(primitives, vertices, out):
    """A strip of `vertices` vertices along x (two rows), every primitive two
    triangles of it: the file holds the vertices once."""
    glb = Glb()
    cols = vertices // 2
    xyz, nrm, uv = [], [], []
    for c in range(cols):
        for r in range(2):
            xyz += [c * 10.0 / cols, 0.0, r * 0.5]
            nrm += [0.0, 1.0, 0.0]
            uv += [c / cols, float(r)]
    pos = glb.positions(xyz)
    nor = glb.add(nrm, "f", len(nrm) // 3, "VEC3", 5126, 34962)
    tex = glb.add(uv, "f", len(uv) // 2, "VEC2", 5126, 34962)
    idx = []
    for p in range(primitives):
        c = p % (cols - 1)
        a, b, d, e = 2 * c, 2 * c + 1, 2 * c + 2, 2 * c + 3
        idx += [a, b, d, d, b, e]
    whole = glb.add(idx, "I", len(idx), "SCALAR", 5125, 34963)
    # Each primitive's indices: a view of 6 indices into the one index array.
    offset = glb.views[glb.accessors[whole]["bufferView"]]["byteOffset"]
    prims = []
    for p in range(primitives):
        glb.views.append({"buffer": 0, "byteOffset": offset + 24 * p, "byteLength": 24})
        glb.accessors.append({"bufferView": len(glb.views) - 1, "componentType": 5125,
                              "count": 6, "type": "SCALAR"})
        prims.append({"attributes": {"POSITION": pos, "NORMAL": nor, "TEXCOORD_0": tex},
                      "indices": len(glb.accessors) - 1, "material": 0})
    glb.write(out, {"scene": 0, "scenes": [{"nodes": [0, 1]}],
                    "nodes": [{"mesh": 0}, {"translation": [5, 2, 0.25],
                                            "extensions": {"KHR_lights_punctual": {"light": 0}}}],
                    "meshes": [{"primitives": prims}], "materials": grey(),
                    "extensionsUsed": ["KHR_lights_punctual"],
                    "extensions": {"KHR_lights_punctual": {"lights": [
                        {"type": "point", "intensity": 20.0, "color": [1, 1, 1]}]}}})


def triangles(n, out, kind="field"):
    glb = Glb()
    rand = lcg(5)
    xyz, idx = [], []
    if kind == "fan":
        xyz = [5.0, 0.0, 5.0]
        for i in range(n):
            a = 2 * math.pi * i / n
            xyz += [5 + 5 * math.cos(a), 0.0, 5 - 5 * math.sin(a)]
        for i in range(n):
            idx += [0, 1 + i, 1 + (i + 1) % n]
    elif kind == "soup":
        side = max(1, math.isqrt(n))
        step = 10.0 / side
        for i in range(n):
            x, z = (i % side) * step, (i // side) * step
            y = 0.05 * next(rand)
            base = len(xyz) // 3
            xyz += [x, y, z, x + 0.4 * step, y, z + 0.8 * step, x + 0.8 * step, y, z]
            idx += [base, base + 1, base + 2]
    else:
        side = max(1, math.isqrt(n // 2))
        step = 10.0 / side
        for j in range(side + 1):
            for i in range(side + 1):
                x, z = i * step, j * step
                xyz += [x, 0.8 * math.sin(1.7 * x) * math.cos(1.1 * z) + 0.002 * next(rand), z]
        for j in range(side):
            for i in range(side):
                a = j * (side + 1) + i
                idx += [a, a + side + 1, a + 1, a + 1, a + side + 1, a + side + 2]
    pos = glb.positions(xyz)
    ind = glb.add(idx, "I", len(idx), "SCALAR", 5125, 34963)
    glb.write(out, {"scene": 0, "scenes": [{"nodes": [0, 1]}],
                    "nodes": [{"mesh": 0}, {"translation": [5, 3, 5],
                                            "extensions": {"KHR_lights_punctual": {"light": 0}}}],
                    "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": ind,
                                                "material": 0}]}],
                    "materials": grey(),
                    "extensionsUsed": ["KHR_lights_punctual"],
                    "extensions": {"KHR_lights_punctual": {"lights": [
                        {"type": "point", "intensity": 50.0, "color": [1, 1, 1]}]}}})


def main(argv):
    if len(argv) >= 4 and argv[1] == "lights":
        lights(int(argv[2]), argv[3])
    elif len(argv) >= 5 and argv[1] == "shared":
        shared(int(argv[2]), int(argv[3]), argv[4])
    elif len(argv) >= 4 and argv[1] == "triangles":
        triangles(int(argv[2]), argv[3], argv[4] if len(argv) > 4 else "field")
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
