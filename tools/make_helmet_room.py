#!/usr/bin/env python3
"""Writes helmet-room.gltf beside a copy of the Khronos glTF sample
DamagedHelmet (DamagedHelmet.gltf with its .bin and five 2048^2 JPEG maps;
CC BY-NC 4.0, theblueturtle_, so it is not part of this repository): the
helmet as it is, in a 6 x 4 x 6 m room (off-white, single-sided walls facing
in) lit by one KHR_lights_punctual spot light from above the camera, and a
camera looking at the helmet. The real-asset benchmark
(tools/bench_real_assets.py --helmet, which writes docs/results/real-assets.md)
runs it.

--emissive-only leaves the spot out: the helmet's emissive texture is the only
light (helmet-emissive.gltf), the case of an emissive-texture-lit scene.

Usage: python3 tools/make_helmet_room.py HELMET_DIR/DamagedHelmet.gltf [--emissive-only]
"""

import base64
import json
import os
import struct
import sys


def room_mesh_buffer(half=3.0, floor=-1.2, height=4.0):
    """Positions, normals and indices of the room's six walls, facing in."""
    y0, y1 = floor, floor + height
    faces = [  # (corner, edge u, edge v, inward normal)
        ((-half, y0, -half), (2 * half, 0, 0), (0, 0, 2 * half), (0, 1, 0)),    # floor
        ((-half, y1, -half), (0, 0, 2 * half), (2 * half, 0, 0), (0, -1, 0)),   # ceiling
        ((-half, y0, -half), (0, height, 0), (2 * half, 0, 0), (0, 0, 1)),      # back
        ((-half, y0, half), (2 * half, 0, 0), (0, height, 0), (0, 0, -1)),      # front
        ((-half, y0, -half), (0, 0, 2 * half), (0, height, 0), (1, 0, 0)),      # left
        ((half, y0, -half), (0, height, 0), (0, 0, 2 * half), (-1, 0, 0)),      # right
    ]
    pos, nrm, idx = [], [], []
    for c, u, v, n in faces:
        base = len(pos) // 3
        for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
            pos += [c[k] + a * u[k] + b * v[k] for k in range(3)]
            nrm += list(n)
        # Counter-clockwise seen from inside: (v, u) turns about the inward
        # normal (u x v points out of the room).
        idx += [base, base + 2, base + 1, base, base + 3, base + 2]
    return pos, nrm, idx


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    src = sys.argv[1]
    emissive_only = "--emissive-only" in sys.argv[2:]
    g = json.load(open(src))
    pos, nrm, idx = room_mesh_buffer()
    data = struct.pack(f"<{len(pos)}f", *pos) + struct.pack(f"<{len(nrm)}f", *nrm) + \
        struct.pack(f"<{len(idx)}I", *idx)
    buffer = len(g["buffers"])
    g["buffers"].append({"byteLength": len(data), "uri": "data:application/octet-stream;base64," +
                         base64.b64encode(data).decode()})
    views = len(g["bufferViews"])
    g["bufferViews"] += [
        {"buffer": buffer, "byteOffset": 0, "byteLength": 4 * len(pos)},
        {"buffer": buffer, "byteOffset": 4 * len(pos), "byteLength": 4 * len(nrm)},
        {"buffer": buffer, "byteOffset": 8 * len(pos), "byteLength": 4 * len(idx)},
    ]
    acc = len(g["accessors"])
    g["accessors"] += [
        {"bufferView": views, "componentType": 5126, "count": len(pos) // 3, "type": "VEC3",
         "min": [min(pos[k::3]) for k in range(3)], "max": [max(pos[k::3]) for k in range(3)]},
        {"bufferView": views + 1, "componentType": 5126, "count": len(nrm) // 3, "type": "VEC3"},
        {"bufferView": views + 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
    ]
    material = len(g["materials"])
    g["materials"].append({"name": "room", "pbrMetallicRoughness": {
        "baseColorFactor": [0.75, 0.73, 0.7, 1], "metallicFactor": 0, "roughnessFactor": 0.9}})
    mesh = len(g["meshes"])
    g["meshes"].append({"name": "room", "primitives": [{"attributes": {"POSITION": acc, "NORMAL": acc + 1},
                                                         "indices": acc + 2, "material": material}]})
    nodes = g["nodes"]
    scene_nodes = g["scenes"][g.get("scene", 0)]["nodes"]
    nodes.append({"name": "room", "mesh": mesh})
    scene_nodes.append(len(nodes) - 1)
    g["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.75, "aspectRatio": 4 / 3,
                                                            "znear": 0.05, "zfar": 50}}]
    nodes.append({"name": "camera", "camera": 0, "translation": [0, 0.3, 2.8],
                  "rotation": [-0.0436, 0, 0, 0.999]})
    scene_nodes.append(len(nodes) - 1)
    if not emissive_only:
        g.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": [{
            "type": "spot", "name": "spot", "color": [1, 0.95, 0.9], "intensity": 150,
            "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}]}
        # At (1, 2.5, 2.5), pointing at the helmet: -Z turned down and to the left.
        nodes.append({"name": "spot", "translation": [1.0, 2.5, 2.5],
                      "rotation": [-0.3712, 0.1485, 0.0, 0.9166],
                      "extensions": {"KHR_lights_punctual": {"light": 0}}})
        scene_nodes.append(len(nodes) - 1)
        used = g.setdefault("extensionsUsed", [])
        if "KHR_lights_punctual" not in used:
            used.append("KHR_lights_punctual")
    name = "helmet-emissive.gltf" if emissive_only else "helmet-room.gltf"
    out = os.path.join(os.path.dirname(os.path.abspath(src)), name)
    with open(out, "w") as f:
        json.dump(g, f)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
