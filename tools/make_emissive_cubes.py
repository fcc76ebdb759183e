#!/usr/bin/env python3
"""Writes data/emissive-cubes.gltf: emissive meshes as the only light, the case
of a scene lit by glowing objects rather than by lamps (neon signs, screens,
the emissive cubes of the glTF sample set).

Contents (metres; +Y up):
  * a 4 x 3 m floor (grey, base colour 0.5) and a back wall 2 m high behind it
    (off-white), a side wall on the left (x = -2, facing +X);
  * three 0.3 m cubes standing on the floor, each of whose faces emits
    (KHR_materials_emissive_strength): a warm white (8 W/(m^2 sr)), a red and a
    blue (each 6);
  * a grey 0.5 m block between them, shadowing the floor and the wall;
  * a panel on the right, in front of the cubes, whose front (+Z, towards the
    camera) has every cube behind its plane: no light reaches it directly,
    only what bounces off the floor;
  * a camera in front, looking at the cubes.

No lamps, no sky: every photon and every light the renderer draws comes from
the 36 emissive triangles. Every face is single-sided and wound outwards.
The file stands alone (base64 data: URI); stdlib only.

Usage: python3 tools/make_emissive_cubes.py [output.gltf]
"""

import os
import sys

from make_courtyard import box_faces, mesh_nodes, write_gltf


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "data", "emissive-cubes.gltf")
    # name, base colour, emission (None: not emissive)
    materials = [("floor", (0.5, 0.5, 0.5), None), ("wall", (0.75, 0.73, 0.7), None),
                 ("block", (0.6, 0.6, 0.6), None), ("warm", (0.8, 0.8, 0.8), ((1.0, 0.85, 0.6), 8.0)),
                 ("red", (0.8, 0.1, 0.1), ((1.0, 0.15, 0.1), 6.0)),
                 ("blue", (0.1, 0.2, 0.8), ((0.15, 0.3, 1.0), 6.0))]
    quads = [(0, ((-2, 0, -1.5), (0, 0, 3), (4, 0, 0))),      # floor, +Y
             (1, ((-2, 0, -1.5), (4, 0, 0), (0, 2, 0))),      # back wall, +Z
             (1, ((-2, 0, -1.5), (0, 2, 0), (0, 0, 3)))]      # left wall, +X
    # The panel: a thin upright slab on the right whose +Z face has every
    # cube behind its plane.
    for face in box_faces((0.9, 0, 1.0), (1.7, 0.9, 1.1)):
        quads.append((1, face))
    for face in box_faces((-0.25, 0, -0.5), (0.25, 0.5, 0.0)):
        if face[0][1] == 0 and face[1][1] == 0 and face[2][1] == 0:
            continue  # the bottom, on the floor: never seen
        quads.append((2, face))
    for material, (x, z) in ((3, (-1.0, -0.6)), (4, (0.7, -0.9)), (5, (-0.2, 0.5))):
        for face in box_faces((x - 0.15, 0, z - 0.15), (x + 0.15, 0.3, z + 0.15)):
            quads.append((material, face))
    parts = mesh_nodes([(m[0], m[1]) for m in materials], quads)
    gltf_materials = []
    for name, color, emission in materials:
        m = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}}
        if emission:
            m["emissiveFactor"] = list(emission[0])
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": emission[1]}}
        gltf_materials.append(m)
    write_gltf(out, "tools/make_emissive_cubes.py", parts, gltf_materials,
               ((0.6, 1.6, 3.2), (-0.1, 0.3, -0.6), 0.8, 0.05), ["KHR_materials_emissive_strength"])

if __name__ == "__main__":
    main()
