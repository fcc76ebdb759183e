"""A small room built in bpy for the Bake panel's test (test_bake_panel.py):
walls with a window in the south wall, two boxes, a sun shining through the
window onto the floor, a point lamp under the ceiling and a camera. Separate
objects, some with a UV map and some without, so that the lightmap UVs are
added and packed as in a user's scene."""
import math

import bpy
from mathutils import Vector

ROOM = (4.0, 3.0, 2.5)  # x, y, height (m)
ROUGHNESS = 0.5
WINDOW = (-0.6, 0.6, 0.9, 1.9)  # x from, x to, z from, z to, in the wall y = -1.5


def build_room(context):
    w, d, h = ROOM[0] / 2, ROOM[1] / 2, ROOM[2]
    wall = _material("wall", (0.8, 0.8, 0.78))
    _surface(context, "floor", [(-w, -d, 0), (w, -d, 0), (w, d, 0), (-w, d, 0)], (0, 0, 1),
             _material("floor", (0.55, 0.42, 0.3)))
    _surface(context, "ceiling", [(-w, -d, h), (w, -d, h), (w, d, h), (-w, d, h)], (0, 0, -1), wall)
    _surface(context, "north wall", [(-w, d, 0), (w, d, 0), (w, d, h), (-w, d, h)], (0, -1, 0), wall)
    _surface(context, "east wall", [(w, -d, 0), (w, d, 0), (w, d, h), (w, -d, h)], (-1, 0, 0),
             _material("green wall", (0.3, 0.6, 0.35)))
    _surface(context, "west wall", [(-w, -d, 0), (-w, d, 0), (-w, d, h), (-w, -d, h)], (1, 0, 0), wall)
    x0, x1, z0, z1 = WINDOW
    pieces = [((-w, 0), (x0, h)), ((x1, 0), (w, h)), ((x0, 0), (x1, z0)), ((x0, z1), (x1, h))]
    _surface(context, "south wall", [[(a[0], -d, a[1]), (b[0], -d, a[1]), (b[0], -d, b[1]), (a[0], -d, b[1])]
                                     for a, b in pieces], (0, 1, 0), wall)
    _box(context, "red box", (1.15, 0.55, 0.3), 0.6, 20, _material("red", (0.75, 0.12, 0.1)))
    _box(context, "blue box", (-1.1, 0.6, 0.5), 0.5, -10, _material("blue", (0.15, 0.25, 0.7)), height=1.0)
    _light(context, "sun", "SUN", (0, 0, 0), (0.15, 0.7, -0.7), energy=12.0, angle=math.radians(0.5))
    _light(context, "lamp", "POINT", (-0.9, 0.4, 2.2), None, energy=60.0, shadow_soft_size=0.05)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.lens = 18
    camera.location = (1.8, 1.35, 1.6)
    camera.rotation_euler = _facing(Vector((-0.4, -1.2, 0.7)) - camera.location).to_euler()
    context.scene.collection.objects.link(camera)
    context.scene.camera = camera
    world = bpy.data.worlds.new("night")
    world.color = (0.0, 0.0, 0.0)
    context.scene.world = world


def _facing(direction):
    return Vector(direction).normalized().to_track_quat("-Z", "Y")


def _material(name, colour):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    principled = mat.node_tree.nodes["Principled BSDF"]
    principled.inputs["Base Color"].default_value = (*colour, 1.0)
    principled.inputs["Roughness"].default_value = ROUGHNESS
    # Matte: no specular layer in Blender (Specular 0) nor in the project
    # (glTF KHR_materials_ior 1: F0 = 0), so that the pictures compare the
    # light and not the engines' BRDFs (docs/blender.md).
    principled.inputs["Specular"].default_value = 0.0
    principled.inputs["IOR"].default_value = 1.0
    return mat


def _surface(context, name, quads, normal, material):
    """A mesh object of quads (one, or a list), each wound to face `normal`."""
    if isinstance(quads[0][0], (int, float)):
        quads = [quads]
    vertices, faces = [], []
    for quad in quads:
        q = [Vector(p) for p in quad]
        if (q[1] - q[0]).cross(q[2] - q[0]).dot(Vector(normal)) < 0:
            q.reverse()
        faces.append(list(range(len(vertices), len(vertices) + 4)))
        vertices += [tuple(p) for p in q]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    context.scene.collection.objects.link(obj)
    return obj


def _box(context, name, location, size, turn_degrees, material, height=None):
    bpy.ops.mesh.primitive_cube_add(size=1.0)  # has a UV map, as a modelled object would
    obj = context.active_object
    obj.name = obj.data.name = name
    obj.scale = (size, size, height or size)
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, math.radians(turn_degrees))
    obj.data.materials.append(material)
    return obj


def _light(context, name, kind, location, direction, **settings):
    data = bpy.data.lights.new(name, kind)
    for key, value in settings.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    if direction is not None:
        obj.rotation_euler = _facing(direction).to_euler()
    context.scene.collection.objects.link(obj)
    return obj
