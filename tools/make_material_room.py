#!/usr/bin/env python3
"""Writes data/material-room.gltf: a closed room that exercises the glTF
material set the renderer, the bake and the path tracer share.

Contents (metres; +Y up, the camera looks down -Z):
  * a 2 x 2 x 2 room, walls facing inward: white back wall and ceiling, red
    left wall, green right wall, a wall behind the camera;
  * the floor: a checker base colour texture (sRGB PNG, 8 x 8 cells, repeated
    twice by KHR_texture_transform);
  * a normal-mapped panel on the back wall (horizontal ridges, a data PNG);
  * a leaf card: a double-sided quad with alphaMode MASK (an ellipse in the
    alpha channel of its base colour texture);
  * a glass sphere (KHR_materials_transmission 1, roughness 0, ior 1.5, and
    KHR_materials_volume with the sphere's diameter as thickness: a solid
    ball that refracts, not a thin-walled bubble);
  * a gold sphere (metallic 1, roughness 0.25);
  * a square ceiling light (emissive, front side down) and the camera.

Every image is a PNG written here with zlib (stdlib only), embedded as a
base64 data: URI, so the file stands alone.

Usage: python3 tools/make_material_room.py [output.gltf]
"""

import base64
import json
import math
import os
import struct
import sys
import zlib


def png(width, height, rows, channels):
    """PNG bytes of 8-bit rows (lists of ints), grey/RGB/RGBA by channels."""
    colour_type = {1: 0, 3: 2, 4: 6}[channels]
    raw = b"".join(b"\x00" + bytes(row) for row in rows)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) +
            chunk(b"IEND", b""))


def checker_png():
    # 64 x 64 texels, 8 x 8 cells: sRGB 230 (light) and 60 (dark).
    rows = []
    for y in range(64):
        row = []
        for x in range(64):
            v = 230 if ((x // 8) + (y // 8)) % 2 == 0 else 60
            row += [v, v, v]
        rows.append(row)
    return png(64, 64, rows, 3)


def ridges_png():
    # Tangent-space normals of horizontal ridges: n = normalize(0, -h'(v), 1)
    # with h(v) = 0.04 sin(2 pi 6 v) (one texture = 1 panel height).
    rows = []
    for y in range(64):
        v = (y + 0.5) / 64.0
        slope = 0.04 * 2 * math.pi * 6 * math.cos(2 * math.pi * 6 * v) * 4.0
        n = (0.0, -slope, 1.0)
        length = math.sqrt(sum(c * c for c in n))
        n = [c / length for c in n]
        texel = [int(round((c * 0.5 + 0.5) * 255)) for c in n]
        rows.append(texel * 8)
    return png(8, 64, rows, 3)


def leaf_png():
    # A leaf: an ellipse of alpha 255 in a transparent square, green veins.
    size = 64
    rows = []
    for y in range(size):
        row = []
        for x in range(size):
            u = (x + 0.5) / size * 2 - 1
            v = (y + 0.5) / size * 2 - 1
            inside = (u / 0.55) ** 2 + (v / 0.95) ** 2 <= 1.0
            vein = abs(u) < 0.04
            colour = [200, 230, 120] if vein else [90, 170, 60]
            row += colour + [255 if inside else 0]
        rows.append(row)
    return png(size, size, rows, 4)


class Builder:
    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []
        self.meshes = []
        self.nodes = []

    def _view(self, blob, target):
        while len(self.data) % 4:
            self.data.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob),
                           "target": target})
        self.data += blob
        return len(self.views) - 1

    def _floats(self, values, width, kind, bounds=False):
        blob = struct.pack("<%df" % len(values), *values)
        acc = {"bufferView": self._view(blob, 34962), "componentType": 5126,
               "count": len(values) // width, "type": kind}
        if bounds:
            acc["min"] = [min(values[i::width]) for i in range(width)]
            acc["max"] = [max(values[i::width]) for i in range(width)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def mesh(self, name, positions, normals, uvs, indices, material):
        idx = struct.pack("<%dH" % len(indices), *indices)
        self.accessors.append({"bufferView": self._view(idx, 34963), "componentType": 5123,
                               "count": len(indices), "type": "SCALAR"})
        index = len(self.accessors) - 1
        attributes = {"POSITION": self._floats(positions, 3, "VEC3", bounds=True),
                      "NORMAL": self._floats(normals, 3, "VEC3")}
        if uvs is not None:
            attributes["TEXCOORD_0"] = self._floats(uvs, 2, "VEC2")
        self.meshes.append({"name": name, "primitives": [
            {"attributes": attributes, "indices": index, "material": material}]})
        self.nodes.append({"name": name, "mesh": len(self.meshes) - 1})


def quad(corner, edge_u, edge_v, normal):
    """Two triangles over corner + s edge_u + t edge_v, wound to face `normal`;
    UV (s, t) with v down the image (glTF: (0, 0) top left)."""
    c = corner
    p = [c, [c[i] + edge_u[i] for i in range(3)],
         [c[i] + edge_u[i] + edge_v[i] for i in range(3)], [c[i] + edge_v[i] for i in range(3)]]
    cross = [edge_u[1] * edge_v[2] - edge_u[2] * edge_v[1],
             edge_u[2] * edge_v[0] - edge_u[0] * edge_v[2],
             edge_u[0] * edge_v[1] - edge_u[1] * edge_v[0]]
    flip = sum(cross[i] * normal[i] for i in range(3)) < 0
    tris = [0, 1, 2, 0, 2, 3] if not flip else [0, 2, 1, 0, 3, 2]
    positions = [x for q in p for x in q]
    normals = list(normal) * 4
    uvs = [0, 1, 1, 1, 1, 0, 0, 0]
    return positions, normals, uvs, tris


def sphere(center, radius, segments=32, rings=16):
    positions, normals, uvs, indices = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
            positions += [center[i] + radius * n[i] for i in range(3)]
            normals += n
            uvs += [s / segments, r / rings]
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a, b = r * row + s, (r + 1) * row + s
            if r != 0:
                indices += [a, b, a + 1]
            if r != rings - 1:
                indices += [a + 1, b, b + 1]
    return positions, normals, uvs, indices


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "data", "material-room.gltf")
    b = Builder()
    materials = []

    def material(name, **kw):
        m = {"name": name, "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 1.0}}
        pbr = m["pbrMetallicRoughness"]
        for key in ("baseColorFactor", "metallicFactor", "roughnessFactor", "baseColorTexture"):
            if key in kw:
                pbr[key] = kw.pop(key)
        m.update(kw)
        materials.append(m)
        return len(materials) - 1

    white = material("white", baseColorFactor=[0.75, 0.75, 0.72, 1])
    red = material("red", baseColorFactor=[0.63, 0.065, 0.05, 1])
    green = material("green", baseColorFactor=[0.14, 0.45, 0.091, 1])
    floor = material("checker floor", baseColorFactor=[1, 1, 1, 1],
                     baseColorTexture={"index": 0, "extensions": {"KHR_texture_transform": {
                         "scale": [2, 2]}}})
    panel = material("ridged panel", baseColorFactor=[0.45, 0.6, 0.8, 1],
                     normalTexture={"index": 1, "scale": 1.0})
    leaf = material("leaf card", baseColorFactor=[1, 1, 1, 1], baseColorTexture={"index": 2},
                    alphaMode="MASK", alphaCutoff=0.5, doubleSided=True)
    glass = material("glass", baseColorFactor=[1, 1, 1, 1], roughnessFactor=0.0,
                     extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                 "KHR_materials_ior": {"ior": 1.5},
                                 "KHR_materials_volume": {"thicknessFactor": 0.6}})
    gold = material("gold", baseColorFactor=[1.0, 0.77, 0.34, 1], metallicFactor=1.0,
                    roughnessFactor=0.25)
    lamp = material("lamp", baseColorFactor=[0.8, 0.8, 0.8, 1], emissiveFactor=[1, 1, 1],
                    extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 10.0}})

    def add_quad(name, corner, eu, ev, normal, mat):
        b.mesh(name, *quad(corner, eu, ev, normal), mat)

    add_quad("floor", [-1, 0, -1], [2, 0, 0], [0, 0, 2], [0, 1, 0], floor)
    add_quad("ceiling", [-1, 2, -1], [2, 0, 0], [0, 0, 2], [0, -1, 0], white)
    add_quad("back wall", [-1, 0, -1], [2, 0, 0], [0, 2, 0], [0, 0, 1], white)
    add_quad("front wall", [-1, 0, 1], [2, 0, 0], [0, 2, 0], [0, 0, -1], white)
    add_quad("left wall", [-1, 0, -1], [0, 0, 2], [0, 2, 0], [1, 0, 0], red)
    add_quad("right wall", [1, 0, -1], [0, 0, 2], [0, 2, 0], [-1, 0, 0], green)
    add_quad("lamp", [-0.3, 1.995, -0.3], [0.6, 0, 0], [0, 0, 0.6], [0, -1, 0], lamp)
    # The ridged panel: 1.2 x 0.8 on the back wall, its UV v running down.
    add_quad("panel", [-0.6, 0.9, -0.995], [1.2, 0, 0], [0, 0.8, 0], [0, 0, 1], panel)
    add_quad("leaf", [-0.85, 0.0, -0.45], [0.5, 0, 0], [0, 0.7, 0], [0, 0, 1], leaf)
    b.mesh("glass sphere", *sphere([0.45, 0.3, -0.25], 0.3), glass)
    b.mesh("gold sphere", *sphere([-0.2, 0.25, -0.15], 0.25), gold)

    # Camera: inside the room by the front wall, looking at the back wall.
    eye, target = [0.0, 1.35, 0.95], [0.05, 0.35, -0.7]
    f = [target[i] - eye[i] for i in range(3)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    # Rotation about +X taking -Z to f (no roll).
    angle = math.atan2(f[1], -f[2])
    q = [math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2)]
    b.nodes.append({"name": "room_camera", "camera": 0, "translation": eye, "rotation": q})

    images = [checker_png(), ridges_png(), leaf_png()]
    gltf = {
        "asset": {"version": "2.0", "generator": "tools/make_material_room.py"},
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_transmission",
                           "KHR_materials_ior", "KHR_materials_emissive_strength",
                           "KHR_materials_volume"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(b.nodes)))}],
        "nodes": b.nodes,
        "meshes": b.meshes,
        "materials": materials,
        "textures": [{"source": i, "sampler": 0} for i in range(len(images))],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(im).decode("ascii")}
                   for im in images],
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": 1.0, "aspectRatio": 4.0 / 3.0, "znear": 0.01}}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.data),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(bytes(b.data)).decode("ascii")}],
    }
    with open(out, "w") as fh:
        json.dump(gltf, fh, indent=1)
        fh.write("\n")
    print("wrote", os.path.normpath(out))


if __name__ == "__main__":
    main()
