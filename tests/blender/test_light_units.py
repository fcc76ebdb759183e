"""Light units from Blender to the project (ctest blender.light_units):

  blender -b --factory-startup --python tests/blender/test_light_units.py -- \
      ADDON_ZIP MODULE_DIR OUT_DIR

For each kind of Blender light (point, spot, sun, area: a rectangle and a
disk) and for the World's colour as a sky, a scene of its own: a large
matte floor (base colour 0.8, no specular layer), the light 1 m above it
(the sun 30 degrees from the zenith) and a camera 0.5 m above the floor
looking straight down at a patch of it 5 cm wide. The add-on's export path (export.py, as the Bake panel
runs it) writes the scene; the project's path tracer (lightoctree.reference,
direct light) renders it; Cycles renders the Blender scene (a Lambert floor,
direct light). Each floor's mean irradiance E = pi L / 0.8 is held to the
analytic irradiance of what Blender means by the light within 1%:

  point, spot of P W:  I = P / (4 pi) W/sr (a spot on its axis), E = I cos / d^2
  sun of S W/m^2:      E = S cos(30 degrees)
  area of P W, A m^2:  L = P / (4 A) W/(m^2 sr), one-sided, E from the
                       rectangle (a 0.2 x 0.3 m one) or disk (0.3 m across)
  World colour C x strength S:  E = pi C S (the floor sees the upper hemisphere)
  World environment texture:    E = sum of L cos dw over its texels, on a wall
                                facing +X (the image turned to the project's frame)

Prints "FAILED: ..." for each failure and "light units: ok" when all hold.
"""
import math
import os
import sys
import zipfile

import bpy
import numpy as np
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
zip_path, module_dir, out = args[:3]
os.makedirs(out, exist_ok=True)
with zipfile.ZipFile(zip_path) as z:
    z.extractall(os.path.join(out, "addon"))
sys.path.insert(0, os.path.join(out, "addon"))
from lightoctree_blender import export, module  # noqa: E402

lo = module.load(module_dir)
ALBEDO = 0.8
HEIGHT = 1.0  # of the light above the floor
CAMERA = 0.5  # height of the camera, looking down
VIEW = 0.1  # the camera's field of view (radians)
PIXELS = 16
TOLERANCE = 0.01
KINDS = ("point", "spot", "sun", "area", "disk", "sky", "sky image")
SKY_IMAGE = (64, 32)  # texels of the environment texture the test makes


def build(kind):
    """The floor, the camera and `kind`'s light (or World colour); returns the analytic E."""
    for data in (bpy.data.objects, bpy.data.meshes, bpy.data.lights, bpy.data.materials,
                 bpy.data.cameras, bpy.data.worlds):
        for item in list(data):
            data.remove(item)
    for image in [i for i in bpy.data.images if i.type == "IMAGE"]:
        bpy.data.images.remove(image)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=20.0)
    floor = bpy.context.active_object
    floor.data.materials.append(_matte("floor"))
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.angle = VIEW
    camera.location = (0.0, 0.0, CAMERA)
    if kind == "sky image":  # the floor stands up as a wall facing +X, the camera before it
        floor.rotation_euler = (0.0, math.pi / 2, 0.0)
        camera.location = (CAMERA, 0.0, 0.0)
        camera.rotation_euler = (math.pi / 2, 0.0, math.pi / 2)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.world = bpy.data.worlds.new("world")
    scene.world.color = (0.0, 0.0, 0.0)
    if kind == "sky":
        scene.world.use_nodes = True
        background = scene.world.node_tree.nodes["Background"]
        background.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
        background.inputs["Strength"].default_value = 1.5
        return lambda x, y: math.pi * 0.45
    if kind == "sky image":
        return _sky_image(scene.world)
    light = bpy.data.lights.new(kind, {"point": "POINT", "spot": "SPOT", "sun": "SUN"}.get(kind, "AREA"))
    obj = bpy.data.objects.new(kind, light)
    scene.collection.objects.link(obj)
    obj.location = (0.0, 0.0, HEIGHT)
    if kind == "sun":
        light.energy, light.angle = 3.0, 0.0
        obj.rotation_euler = Vector((math.sin(math.radians(30)), 0.0, -math.cos(math.radians(30)))) \
            .to_track_quat("-Z", "Y").to_euler()
        return lambda x, y: 3.0 * math.cos(math.radians(30))
    light.energy = 100.0
    if kind == "area":
        light.shape, light.size, light.size_y = "RECTANGLE", 0.2, 0.3
        radiance = light.energy / (4 * 0.2 * 0.3)
        return lambda x, y: radiance * _rectangle(x, y, 0.1, 0.15, HEIGHT)
    if kind == "disk":
        light.shape, light.size = "DISK", 0.3
        radiance = light.energy / (4 * math.pi * 0.15 ** 2)
        return lambda x, y: radiance * _disk(math.hypot(x, y), 0.15, HEIGHT)
    light.shadow_soft_size = 0.0
    if kind == "spot":
        light.spot_size, light.spot_blend = math.radians(60), 0.15
    intensity = light.energy / (4 * math.pi)
    return lambda x, y: intensity * HEIGHT / (x * x + y * y + HEIGHT * HEIGHT) ** 1.5


def _sky_image(world):
    """An equirectangular environment texture (Blender's convention: the
    middle column looks along +X, azimuth turning towards -Y) brighter
    towards +X and +Y and black below the horizon; returns the analytic
    irradiance of the wall facing +X (the sum over the texels above the
    horizon of L cos dw), which a sky turned by a quarter would miss."""
    width, height = SKY_IMAGE
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height  # bpy's rows go up from the nadir
    azimuth = 2 * math.pi * (0.5 - u)[None, :]
    elevation = (math.pi * (v - 0.5))[:, None]
    radiance = (1.25 + np.cos(azimuth) + 0.5 * np.sin(azimuth)) * (elevation > 0)
    image = bpy.data.images.new("sky", width, height, alpha=False, float_buffer=True)
    rgba = np.ones((height, width, 4), np.float32)
    rgba[..., :3] = radiance[..., None]
    image.pixels.foreach_set(rgba.ravel())
    world.use_nodes = True
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    texture.interpolation = "Closest"  # texel by texel, as the analytic sum
    tree.links.new(texture.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    toward_x = np.maximum(np.cos(elevation) * np.cos(azimuth), 0.0)
    solid_angle = np.cos(elevation) * (2 * math.pi / width) * (math.pi / height)
    irradiance = float(np.sum(radiance * toward_x * solid_angle))
    return lambda x, y: irradiance


def _rectangle(x, y, a, b, h):
    """Irradiance at (x, y, 0) facing up from a Lambertian rectangle of unit
    radiance [-a, a] x [-b, b] at height h facing down (corner sums of the
    form factor to a parallel rectangle)."""
    def corner(u, v):
        su, sv = math.sqrt(u * u + h * h), math.sqrt(v * v + h * h)
        return 0.5 * (u / su * math.atan(v / su) + v / sv * math.atan(u / sv))
    return (corner(a - x, b - y) - corner(-a - x, b - y) - corner(a - x, -b - y)
            + corner(-a - x, -b - y))


def _disk(r, radius, h):
    """Irradiance at distance r from the axis of a Lambertian disk of unit
    radiance at height h, parallel to the floor."""
    s = h * h + r * r
    return 0.5 * math.pi * (1 - (s - radius ** 2) / math.sqrt((s + radius ** 2) ** 2 - 4 * r * r * radius ** 2))


def _matte(name):
    """Base colour 0.8 without a specular layer: Specular 0 in Blender, and
    KHR_materials_ior 1 (F0 = 0) in the export, so the project's floor is
    Lambertian where the camera looks (the Fresnel of 1 - v.h only)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    principled = mat.node_tree.nodes["Principled BSDF"]
    principled.inputs["Base Color"].default_value = (ALBEDO, ALBEDO, ALBEDO, 1.0)
    principled.inputs["Specular"].default_value = 0.0
    principled.inputs["IOR"].default_value = 1.0
    principled.inputs["Roughness"].default_value = 1.0
    return mat


def analytic_mean(irradiance):
    """The mean of E over the pixels' centres (4 x 4 samples a pixel)."""
    half = CAMERA * math.tan(VIEW / 2)
    n = 4 * PIXELS
    t = (np.arange(n) + 0.5) / n * 2 - 1
    return float(np.mean([[irradiance(x * half, y * half) for x in t] for y in t]))


def project_mean(path, sky):
    """E of the floor from the project's path tracer: direct light, pi L / albedo."""
    image = lo.reference(path, width=PIXELS, height=PIXELS, spp=256, part="direct", **sky)
    return float(image.mean()) * math.pi / ALBEDO


def cycles_mean(kind):
    """E of the floor from Cycles: direct light on a Lambert floor, pi L / albedo."""
    scene = bpy.context.scene
    floor = bpy.data.materials["floor"]
    tree = floor.node_tree
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (ALBEDO, ALBEDO, ALBEDO, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert
    tree.links.new(diffuse.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16 if kind in ("point", "spot", "sun") else 1024
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 0  # direct light
    scene.cycles.filter_width = 0.01
    scene.render.resolution_x = scene.render.resolution_y = PIXELS
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = os.path.join(out, f"cycles-{kind}.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    pixels = np.array(image.pixels[:]).reshape(-1, 4)[:, :3]
    return float(pixels.mean()) * math.pi / ALBEDO


failures = []
scene = bpy.context.scene
scene.render.resolution_x = scene.render.resolution_y = PIXELS
for kind in KINDS:
    irradiance = build(kind)
    path = os.path.join(out, f"{kind}.glb")
    floor = [o for o in bpy.data.objects if o.type == "MESH"]
    sky, warnings = export.sky_settings(scene.world, out)
    warnings += export.export_scene(bpy.context, path, floor)
    expected = analytic_mean(irradiance)
    ours = project_mean(path, sky)
    blender = cycles_mean(kind)
    print(f"light units, {kind}: analytic E {expected:.5f} W/m^2; the project's path tracer "
          f"{ours:.5f} ({ours / expected - 1:+.2%}); Cycles {blender:.5f} "
          f"({blender / expected - 1:+.2%}); tolerance {TOLERANCE:.0%}")
    if warnings:
        failures.append(f"{kind}: the export warned: {warnings}")
    if abs(ours / expected - 1) > TOLERANCE:
        failures.append(f"{kind}: the project's irradiance is {ours / expected - 1:+.2%} off")
    if abs(blender / expected - 1) > TOLERANCE:
        failures.append(f"{kind}: Cycles' irradiance is {blender / expected - 1:+.2%} off the "
                        f"formula docs/blender.md gives")
for f in failures:
    print(f"FAILED: {f}")
print("light units: ok" if not failures else f"light units: {len(failures)} failure(s)")
sys.exit(1 if failures else 0)
