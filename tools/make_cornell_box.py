#!/usr/bin/env python3
"""Writes data/cornell-box.gltf: the Cornell box from the published measurements.

Source: Cornell University Program of Computer Graphics, "Cornell Box Data"
(vertices in millimetres). See data/README.md for the colour conversions.

Conversion to glTF conventions:
  * mm -> m.
  * 180 degree rotation about +Y (x' = -x, z' = -z), then x centred on 0, so the
    camera (at z = -800 mm in the data, looking +z) ends up at z' = +0.8 m
    looking down -Z, with the red wall on the left of the image. A rotation has
    determinant +1: no mirroring, winding is kept.
  * Every triangle is oriented explicitly from its normal: walls, floor and
    ceiling face the room's interior, block faces face out of their block, the
    light faces down.

Usage: python3 tools/make_cornell_box.py [output.gltf]   (stdlib only)
"""

import base64
import json
import math
import os
import struct
import sys

# --- The published geometry (mm). Quads, vertex order as published. ---------
ROOM = {
    "floor": [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)],
    "ceiling": [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)],
    "back_wall": [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)],
    "right_wall_green": [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)],
    "left_wall_red": [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)],
}
LIGHT_Y = 548.8 - 0.5  # 0.5 mm below the ceiling so it does not coincide with it
LIGHT = [(343, LIGHT_Y, 227), (343, LIGHT_Y, 332), (213, LIGHT_Y, 332), (213, LIGHT_Y, 227)]
SHORT_TOP = [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)]
TALL_TOP = [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)]
CAMERA_MM = (278, 273, -800)
FOCAL_MM, FILM_MM = 35.0, 25.0

# --- Materials: RGB of the measured spectra (data/README.md). --------------
WHITE = (0.725, 0.71, 0.68)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)
LIGHT_ALBEDO = (0.78, 0.78, 0.78)
LIGHT_RADIANCE = (17.0, 12.0, 4.0)  # W/(m^2 sr), RGB of the measured light
EMISSIVE_STRENGTH = 17.0


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def normalize(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a)


def to_gltf(p):
    """mm, Cornell frame -> m, glTF frame (rotation about Y, x centred)."""
    x, y, z = p
    return ((278.0 - x) / 1000.0, y / 1000.0, -z / 1000.0)


def block_sides(top):
    """The 4 vertical sides of a block from its top quad, down to y = 0."""
    sides = []
    for i in range(4):
        a, b = top[i], top[(i + 1) % 4]
        sides.append([a, b, (b[0], 0, b[2]), (a[0], 0, a[2])])
    return sides


def centroid(points):
    return tuple(sum(c) / len(points) for c in zip(*points))


def oriented_triangles(quad, want):
    """Splits a quad (0,1,2)+(0,2,3) and orients each triangle so that its
    normal n satisfies want(n, triangle) > 0."""
    tris = []
    for t in ((quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])):
        n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
        if want(n, t) < 0:
            t = (t[0], t[2], t[1])
        tris.append(t)
    return tris


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.normpath(os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "data", "cornell-box.gltf"))

    room_pts = [to_gltf(p) for q in ROOM.values() for p in q]
    room_center = centroid(room_pts)

    def inward(n, t):  # face the room's interior
        return dot(n, sub(room_center, centroid(t)))

    def outward_of(center):
        return lambda n, t: dot(n, sub(centroid(t), center))

    def down(n, t):
        return -n[1]

    # (node/mesh name, material index, list of oriented triangles)
    parts = []
    materials_of = {"left_wall_red": 1, "right_wall_green": 2}
    for name, quad in ROOM.items():
        q = [to_gltf(p) for p in quad]
        parts.append((name, materials_of.get(name, 0), oriented_triangles(q, inward)))
    parts.append(("light", 3, oriented_triangles([to_gltf(p) for p in LIGHT], down)))
    for name, top in (("short_block", SHORT_TOP), ("tall_block", TALL_TOP)):
        quads = [top] + block_sides(top)
        quads = [[to_gltf(p) for p in q] for q in quads]
        center = centroid([p for q in quads for p in q])
        tris = []
        for q in quads:
            tris += oriented_triangles(q, outward_of(center))
        parts.append((name, 0, tris))

    # One buffer: per part, POSITION (vec3 f32) + NORMAL (vec3 f32) for 3
    # unshared vertices per triangle (flat normals), then uint16 indices.
    blob = bytearray()
    buffer_views, accessors, meshes, nodes = [], [], [], []

    def add_view(data, target):
        while len(blob) % 4:
            blob.append(0)
        buffer_views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                             "target": target})
        blob.extend(data)
        return len(buffer_views) - 1

    for name, material, tris in parts:
        pos, nrm = [], []
        for t in tris:
            n = normalize(cross(sub(t[1], t[0]), sub(t[2], t[0])))
            for p in t:
                pos.append(p)
                nrm.append(n)
        count = len(pos)
        pos_view = add_view(b"".join(struct.pack("<3f", *p) for p in pos), 34962)
        nrm_view = add_view(b"".join(struct.pack("<3f", *n) for n in nrm), 34962)
        idx_view = add_view(struct.pack("<%dH" % count, *range(count)), 34963)
        lo = [min(p[i] for p in pos) for i in range(3)]
        hi = [max(p[i] for p in pos) for i in range(3)]
        # min/max must bound the float32 values the reader sees.
        f32 = lambda x: struct.unpack("<f", struct.pack("<f", x))[0]
        accessors.append({"bufferView": pos_view, "componentType": 5126, "count": count,
                          "type": "VEC3", "min": [f32(x) for x in lo],
                          "max": [f32(x) for x in hi]})
        accessors.append({"bufferView": nrm_view, "componentType": 5126, "count": count,
                          "type": "VEC3"})
        accessors.append({"bufferView": idx_view, "componentType": 5123, "count": count,
                          "type": "SCALAR"})
        a = len(accessors)
        meshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": a - 3, "NORMAL": a - 2}, "indices": a - 1,
            "material": material, "mode": 4}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})
    while len(blob) % 4:
        blob.append(0)

    yfov = 2.0 * math.atan(0.5 * FILM_MM / FOCAL_MM)
    nodes.append({"name": "cornell_camera", "camera": 0,
                  "translation": list(to_gltf(CAMERA_MM))})

    def diffuse(name, rgb):
        return {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(rgb) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}

    light = diffuse("light", LIGHT_ALBEDO)
    # emissiveFactor * strength == LIGHT_RADIANCE exactly (12/17, 4/17 ~ 0.706, 0.235).
    light["emissiveFactor"] = [c / EMISSIVE_STRENGTH for c in LIGHT_RADIANCE]
    light["extensions"] = {"KHR_materials_emissive_strength": {
        "emissiveStrength": EMISSIVE_STRENGTH}}

    gltf = {
        "asset": {"version": "2.0", "generator": "lightoctree make_cornell_box.py",
                  "copyright": "Geometry and colours after Cornell University Program of "
                               "Computer Graphics, Cornell Box Data"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"name": "cornell-box", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [diffuse("white", WHITE), diffuse("red", RED), diffuse("green", GREEN),
                      light],
        "cameras": [{"name": "cornell_camera", "type": "perspective", "perspective": {
            "yfov": yfov, "aspectRatio": 1.0, "znear": 0.01}}],
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(bytes(blob)).decode("ascii")}],
    }
    with open(out + ".tmp", "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")
    os.replace(out + ".tmp", out)
    print("wrote %s: %d triangles" % (out, sum(len(p[2]) for p in parts)))


if __name__ == "__main__":
    main()
