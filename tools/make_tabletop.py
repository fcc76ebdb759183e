#!/usr/bin/env python3
"""Writes data/tabletop.gltf: a small object under a spot, and thick glass. The
two classes of scene the public sample sets bring (a toy car a few centimetres
long lit by one spot; a glass block with KHR_materials_volume in front of what
it lets through) at their real scale: every object here is centimetres across,
in a 2 m room, so shadow maps, biases and the gather meet a scene far smaller
than the room around it.

Contents (metres; +Y up):
  * a 2 x 2 m floor (grey, 0.45), a back wall and a left wall (off-white);
  * a cloth mat 50 x 35 cm, 4 mm thick (green-grey), on the floor;
  * a toy car 7.5 cm long on the mat: a red body, a grey cabin, four dark
    wheels (boxes);
  * a clear glass block 6 x 6 x 4 cm beside it (KHR_materials_transmission 1,
    KHR_materials_volume thickness 4 cm, IOR 1.5, roughness 0);
  * a card 4 cm behind the glass, striped red, white and blue, so what the
    glass lets through is seen;
  * one spot light 0.6 m above the mat, aimed at the car and the glass;
  * a camera 35 cm away, looking down at both.

Every face is single-sided and wound outwards. The file stands alone (base64
data: URI); stdlib only.

Usage: python3 tools/make_tabletop.py [output.gltf]
"""

import os
import sys

from make_courtyard import box_faces, camera_rotation, mesh_nodes, write_gltf


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "data", "tabletop.gltf")
    # name, base colour, extra material fields
    glass = {"roughnessFactor": 0.0, "extensions": {
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_volume": {"thicknessFactor": 0.04},
        "KHR_materials_ior": {"ior": 1.5}}}
    materials = [("floor", (0.45, 0.45, 0.45), {}), ("wall", (0.75, 0.73, 0.7), {}),
                 ("cloth", (0.25, 0.35, 0.28), {}), ("body", (0.7, 0.08, 0.05), {}),
                 ("cabin", (0.5, 0.52, 0.55), {}), ("wheel", (0.04, 0.04, 0.04), {}),
                 ("glass", (0.95, 1.0, 0.97), glass), ("stripe-red", (0.7, 0.1, 0.08), {}),
                 ("stripe-white", (0.8, 0.8, 0.78), {}), ("stripe-blue", (0.08, 0.15, 0.6), {})]
    quads = [(0, ((-1, 0, -1), (0, 0, 2), (2, 0, 0))),      # floor, +Y
             (1, ((-1, 0, -1), (2, 0, 0), (0, 1.5, 0))),    # back wall, +Z
             (1, ((-1, 0, -1), (0, 1.5, 0), (0, 0, 2)))]    # left wall, +X

    def box(material, lo, hi, bottom=False):
        for face in box_faces(lo, hi):
            if not bottom and all(abs(p) < 1e-12 for p in (face[1][1], face[2][1])) \
                    and face[0][1] == lo[1]:
                continue  # the bottom, on what it stands on: never seen
            quads.append((material, face))

    mat_top = 0.004
    box(2, (-0.25, 0.0, -0.2), (0.25, mat_top, 0.15))
    # The car: 7.5 cm from x = -0.09 to -0.015.
    box(3, (-0.09, mat_top + 0.008, -0.016), (-0.015, mat_top + 0.026, 0.016), bottom=True)
    box(4, (-0.07, mat_top + 0.026, -0.014), (-0.038, mat_top + 0.04, 0.014))
    for x in (-0.08, -0.04):
        for z0, z1 in ((-0.022, -0.014), (0.014, 0.022)):
            box(5, (x, mat_top, z0), (x + 0.014, mat_top + 0.014, z1))
    # The glass block, closed and half a millimetre above the mat (a volume
    # needs every face), and the striped card behind it (facing +Z).
    box(6, (0.03, mat_top + 0.0005, -0.03), (0.09, mat_top + 0.0605, 0.01), bottom=True)
    for i, material in enumerate((7, 8, 9)):
        x0 = 0.0 + 0.04 * i
        quads.append((material, ((x0, mat_top, -0.07), (0.04, 0, 0), (0, 0.1, 0))))
    parts = mesh_nodes([(m[0], m[1]) for m in materials], quads)
    spot, aim = (0.05, 0.6, 0.25), (0.0, 0.0, -0.02)
    parts[4].append({"name": "spot", "translation": list(spot),
                     "rotation": camera_rotation(spot, aim),
                     "extensions": {"KHR_lights_punctual": {"light": 0}}})
    gltf_materials = []
    for name, color, extra in materials:
        m = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0,
            "roughnessFactor": extra.get("roughnessFactor", 0.8)}}
        if "extensions" in extra:
            m["extensions"] = extra["extensions"]
        gltf_materials.append(m)
    spot_light = {"type": "spot", "name": "spot", "color": [1.0, 0.95, 0.88], "intensity": 3.0,
                  "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}}
    write_gltf(out, "tools/make_tabletop.py", parts, gltf_materials,
               ((0.14, 0.17, 0.3), (0.0, 0.025, -0.02), 0.6, 0.01),
               ["KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_volume",
                "KHR_materials_ior"], lights=[spot_light])

if __name__ == "__main__":
    main()
