#!/usr/bin/env python3
"""Writes data/courtyard.gltf: an open scene under a sun and a sky, the case
that interiors never test (photons must be aimed at the scene, and the sides
the sun does not reach are lit by the sky alone).

Contents (metres; +Y up):
  * a 40 x 40 m ground (grey, base colour 0.3);
  * five blocks around an open courtyard: four buildings 6-12 m tall
    (off-white, light brick red, light blue, sand) and a low wall, with gaps
    between them so the sun and the sky reach the courtyard floor;
  * a sun: a KHR_lights_punctual directional light, 3 W/m^2, 40 degrees
    above the horizon;
  * a sky: the scene's extras.lightoctree_sky, radiance (0.12, 0.16, 0.22)
    W/(m^2 sr) (docs/scene.md, "Sky");
  * a camera above one corner looking into the courtyard.

Every face is single-sided and wound outwards. The file stands alone (the
buffer is a base64 data: URI); stdlib only.

Beside it, data/courtyard-sky.hdr: a 64 x 32 equirectangular sky (Radiance
RGBE) for `--sky-image` (docs/scene.md, "Sky"): blue overhead, paler and
brighter towards the horizon, brightest around the sun's azimuth.

Usage: python3 tools/make_courtyard.py [output.gltf]
"""

import base64
import json
import math
import os
import struct
import sys


def box_faces(lo, hi):
    """The 6 outward faces of an axis-aligned box: (corner, edge u, edge v) with
    u x v pointing out of the box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return [
        ((x0, y1, z0), (0, 0, dz), (dx, 0, 0)),   # top, +Y
        ((x0, y0, z0), (dx, 0, 0), (0, 0, dz)),   # bottom, -Y
        ((x1, y0, z0), (0, dy, 0), (0, 0, dz)),   # +X
        ((x0, y0, z0), (0, 0, dz), (0, dy, 0)),   # -X
        ((x0, y0, z1), (dx, 0, 0), (0, dy, 0)),   # +Z
        ((x0, y0, z0), (0, dy, 0), (dx, 0, 0)),   # -Z
    ]


def write_sky_hdr(path, width=64, height=32, sun_azimuth=225.0):
    """An equirectangular sky as Radiance RGBE, flat scanlines: row 0 at the
    zenith, column u at azimuth 2 pi (u - 1/2) from -Z towards +X (as the
    loader reads it); the lower half black (unused)."""
    rows = []
    for y in range(height):
        theta = math.pi * (y + 0.5) / height
        row = bytearray()
        for x in range(width):
            phi = 2 * math.pi * ((x + 0.5) / width - 0.5)
            if theta >= math.pi / 2:
                rgb = (0.0, 0.0, 0.0)
            else:
                horizon = (theta / (math.pi / 2)) ** 2  # 0 overhead, 1 at the horizon
                # Brighter towards the sun's azimuth (travel azimuth 225: the
                # sun itself stands at 45 degrees).
                towards = 0.5 + 0.5 * math.cos(phi - math.radians(sun_azimuth - 180.0))
                glow = 1.0 + 0.8 * towards * horizon
                rgb = tuple(glow * (a + (b - a) * horizon) for a, b in
                            ((0.06, 0.16), (0.10, 0.18), (0.22, 0.22)))
            v = max(rgb)
            if v < 1e-32:
                row += bytes(4)
            else:
                m, e = math.frexp(v)
                scale = m * 256.0 / v
                row += bytes([min(255, int(c * scale)) for c in rgb] + [e + 128])
        rows.append(bytes(row))
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
        for row in rows:
            f.write(row)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def mesh_nodes(materials, quads):
    """One mesh and node per material from (material, (corner, u, v)) quads:
    (buffer bytes, bufferViews, accessors, meshes, nodes)."""
    data = bytearray()
    views, accessors, meshes, nodes = [], [], [], []
    for material in range(len(materials)):
        mine = [q for m, q in quads if m == material]
        if not mine:
            continue
        positions, normals, indices = [], [], []
        for corner, u, v in mine:
            n = cross(u, v)
            length = math.sqrt(sum(c * c for c in n))
            n = tuple(c / length for c in n)
            base = len(positions)
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                positions.append(tuple(corner[i] + a * u[i] + b * v[i] for i in range(3)))
                normals.append(n)
            indices += [base, base + 1, base + 2, base, base + 2, base + 3]
        attributes = {}
        for name, values in (("POSITION", positions), ("NORMAL", normals)):
            offset = len(data)
            for p in values:
                data += struct.pack("<3f", *p)
            views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
            accessor = {"bufferView": len(views) - 1, "componentType": 5126,
                        "count": len(values), "type": "VEC3"}
            if name == "POSITION":
                accessor["min"] = [min(p[i] for p in values) for i in range(3)]
                accessor["max"] = [max(p[i] for p in values) for i in range(3)]
            accessors.append(accessor)
            attributes[name] = len(accessors) - 1
        offset = len(data)
        for i in indices:
            data += struct.pack("<I", i)
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data) - offset})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125,
                          "count": len(indices), "type": "SCALAR"})
        meshes.append({"name": materials[material][0], "primitives": [
            {"attributes": attributes, "indices": len(accessors) - 1, "material": material}]})
        nodes.append({"name": materials[material][0], "mesh": len(meshes) - 1})
    return data, views, accessors, meshes, nodes


def sun_rotation(elevation_degrees, azimuth_degrees):
    """The quaternion turning a light's -Z (the way it travels) to the light
    of a sun `elevation_degrees` above the horizon, travelling towards the
    azimuth `azimuth_degrees`, measured from -Z towards -X (0: due -Z)."""
    elevation, azimuth = math.radians(elevation_degrees), math.radians(azimuth_degrees)
    travel = (-math.cos(elevation) * math.sin(azimuth), -math.sin(elevation),
              -math.cos(elevation) * math.cos(azimuth))
    # Rotation taking -Z to `travel`: about the axis (-Z) x travel.
    z = (0.0, 0.0, -1.0)
    axis = cross(z, travel)
    s = math.sqrt(sum(c * c for c in axis))
    angle = math.atan2(s, sum(z[i] * travel[i] for i in range(3)))
    return [c / s * math.sin(angle / 2) for c in axis] + [math.cos(angle / 2)]


def camera_rotation(eye, target):
    """The quaternion of a camera at `eye` looking at `target`, +Y up."""
    forward = [target[i] - eye[i] for i in range(3)]
    yaw = math.atan2(-forward[0], -forward[2])
    pitch = math.atan2(forward[1], math.hypot(forward[0], forward[2]))
    qy = (0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2))
    qx = (math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2))
    return [qy[3] * qx[0], qy[1] * qx[3], -qy[1] * qx[0], qy[3] * qx[3]]


def embedded_buffer(data):
    return {"byteLength": len(data),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}


def write_gltf(out, generator, parts, materials, camera, extensions_used, lights=None,
               scene_extras=None):
    """Writes a glTF of mesh_nodes' parts (buffer embedded), its materials
    (glTF material objects), a camera node (eye, target, yfov, znear) after
    the parts' nodes, and KHR_lights_punctual `lights` (their nodes already
    among the parts')."""
    data, views, accessors, meshes, nodes = parts
    eye, target, yfov, znear = camera
    nodes.append({"name": "camera", "camera": 0, "translation": list(eye),
                  "rotation": camera_rotation(eye, target)})
    gltf = {"asset": {"version": "2.0", "generator": generator},
            "extensionsUsed": list(extensions_used)}
    if lights:
        gltf["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
    scene = {"nodes": list(range(len(nodes)))}
    if scene_extras is not None:
        scene["extras"] = scene_extras
    gltf.update({
        "scene": 0,
        "scenes": [scene],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "znear": znear}}],
        "buffers": [embedded_buffer(data)],
        "bufferViews": views,
        "accessors": accessors,
    })
    with open(out, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


def write_sunlit_scene(out, generator, materials, quads, sun, camera, scene_extras):
    """Writes a glTF of the quads (one mesh per material, buffer embedded),
    a 3 W/m^2 directional sun at (elevation, azimuth) degrees (sun_rotation),
    a camera (eye, target, yfov, znear) and the scene's extras."""
    parts = mesh_nodes(materials, quads)
    parts[4].append({"name": "sun", "rotation": sun_rotation(*sun),
                     "extensions": {"KHR_lights_punctual": {"light": 0}}})
    gltf_materials = [{"name": name, "pbrMetallicRoughness": {
        "baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}}
        for name, color in materials]
    sun_light = {"type": "directional", "name": "sun", "color": [1.0, 0.95, 0.85], "intensity": 3.0}
    write_gltf(out, generator, parts, gltf_materials, camera, ["KHR_lights_punctual"],
               lights=[sun_light], scene_extras=scene_extras)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "data", "courtyard.gltf")
    materials = [
        ("ground", (0.3, 0.3, 0.3)),
        ("white", (0.75, 0.73, 0.7)),
        ("brick", (0.6, 0.3, 0.22)),
        ("blue", (0.35, 0.45, 0.6)),
        ("sand", (0.7, 0.6, 0.42)),
    ]
    # (material, lower corner, upper corner)
    blocks = [
        (1, (-12, 0, -12), (4, 10, -6)),   # north: long, tall
        (2, (6, 0, -12), (12, 12, 4)),     # east: the tallest
        (3, (-12, 0, -4), (-6, 6, 12)),    # west: low
        (4, (-2, 0, 6), (12, 8, 12)),      # south
        (1, (-5, 0, 8), (-3, 1.5, 10)),    # a low wall in the south-west gap
    ]
    quads = [(0, ((-20, 0, -20), (0, 0, 40), (40, 0, 0)))]
    for material, lo, hi in blocks:
        for face in box_faces(lo, hi):
            if face[0][1] == 0 and face[1][1] == 0 and face[2][1] == 0:
                continue  # the bottom face lies on the ground: never seen
            quads.append((material, face))

    # The sun 40 degrees high from the south-west; the camera above the
    # south-west corner, looking at the courtyard's centre.
    write_sunlit_scene(out, "tools/make_courtyard.py", materials, quads, sun=(40, 225),
                       camera=((-16.0, 14.0, 18.0), (2.0, 0.0, -1.0), 0.9, 0.1),
                       scene_extras={"lightoctree_sky": [0.12, 0.16, 0.22]})
    write_sky_hdr(os.path.join(os.path.dirname(out), "courtyard-sky.hdr"))


if __name__ == "__main__":
    main()
