#!/usr/bin/env python3
"""Writes data/window-room.gltf: a room lit through a window, the case
between an interior and an open scene (the sun and the sky reach the room
through one opening; most of the light inside has bounced).

Contents (metres; +Y up):
  * a 16 x 16 m ground (grey, base colour 0.3) that is also the room's floor
    (the sunlit ground in front of the window lights the ceiling inside);
  * a room 6 x 3 x 5 m inside, walls and roof 0.2 m thick (off-white), a
    2.2 x 1.4 m window in its south wall (+Z) with its sill 0.8 m up, and a
    low block (a sofa, brick red) by the north wall;
  * a sun: a KHR_lights_punctual directional light, 3 W/m^2, 30 degrees
    above the horizon, shining in through the window;
  * the daylight sky of that sun, turbidity 3 (the scene's
    extras.lightoctree_physical_sky, docs/scene.md, "Sky");
  * a camera in the north-east corner looking at the window.

Every face is single-sided and wound outwards from its slab. The file stands
alone (the buffer is a base64 data: URI); stdlib only.

Usage: python3 tools/make_window_room.py [output.gltf]
"""

import os
import sys

from make_courtyard import box_faces, write_sunlit_scene


def slabs():
    """(material, lower, upper) boxes: the walls around the window, the roof,
    the sofa."""
    x0, x1, z0, z1, h, t = -3.0, 3.0, -2.5, 2.5, 3.0, 0.2
    wx0, wx1, sill, head = -1.1, 1.1, 0.8, 2.2
    return [
        (1, (x0 - t, 0, z0 - t), (x1 + t, h, z0)),       # north wall
        (1, (x0 - t, 0, z0), (x0, h, z1)),               # west wall
        (1, (x1, 0, z0), (x1 + t, h, z1)),               # east wall
        (1, (x0 - t, 0, z1), (wx0, h, z1 + t)),          # south wall, west of the window
        (1, (wx1, 0, z1), (x1 + t, h, z1 + t)),          # east of it
        (1, (wx0, 0, z1), (wx1, sill, z1 + t)),          # below it
        (1, (wx0, head, z1), (wx1, h, z1 + t)),          # above it
        (1, (x0 - t, h, z0 - t), (x1 + t, h + t, z1 + t)),  # roof
        (2, (-1.6, 0, -2.3), (0.6, 0.8, -1.5)),          # sofa
    ]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "data", "window-room.gltf")
    materials = [("ground", (0.3, 0.3, 0.3)), ("wall", (0.75, 0.73, 0.7)), ("sofa", (0.6, 0.3, 0.22))]
    quads = [(0, ((-8, 0, -8), (0, 0, 16), (16, 0, 0)))]
    for material, lo, hi in slabs():
        for face in box_faces(lo, hi):
            if face[0][1] == 0 and face[1][1] == 0 and face[2][1] == 0:
                continue  # on the ground: never seen
            quads.append((material, face))
    # The sun 30 degrees high, shining in through the window; the camera in
    # the north-east corner, looking at the window.
    write_sunlit_scene(out, "tools/make_window_room.py", materials, quads, sun=(30, 20),
                       camera=((2.6, 1.7, -2.1), (-0.6, 0.9, 2.5), 1.1, 0.05),
                       scene_extras={"lightoctree_physical_sky": 3})


if __name__ == "__main__":
    main()
