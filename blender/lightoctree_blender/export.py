# The scene as the project reads it (docs/scene.md), written by Blender's
# own glTF exporter, and the World's light as the project's sky. Light units
# (docs/blender.md, "Light units"): the exporter's "Unitless" lighting mode
# writes a point or spot light of P W as P / (4 pi) and a sun of S W/m^2 as
# S, which the project reads as W/sr and W/m^2, the radiometric quantities
# Blender means; area lights, which glTF has no word for, go out as one-sided
# emissive meshes of radiance P / (4 A), the radiance Cycles gives them.
import contextlib
import math
import os

import bpy
import numpy as np

from . import lightmap

_DISK_SIDES = 32


def baked_objects(context):
    """The mesh objects a bake lights: shown in the viewport, enabled for
    renders, with faces."""
    context.view_layer.update()  # objects linked since the last update count too
    return [o for o in context.view_layer.objects
            if o.type == "MESH" and o.visible_get() and not o.hide_render and len(o.data.polygons)]


def materials_of(objects):
    """The materials the objects show (their slots', object-linked ones included)."""
    return {slot.material for o in objects for slot in o.material_slots if slot.material}


def export_scene(context, path, objects):
    """Writes `objects`, the visible point, spot and sun lights, the area
    lights as emitters and the scene's camera to the glTF `path` (.glb) for
    the project; returns warnings for the user (what the project cannot take
    as Blender has it)."""
    lightmap.fix_numpy()
    context.view_layer.update()
    lights = [o for o in context.view_layer.objects
              if o.type == "LIGHT" and o.visible_get() and not o.hide_render]
    warnings = _light_warnings(lights)
    camera = [context.scene.camera] if context.scene.camera else []
    materials = materials_of(objects)
    with _area_lights_as_emitters(context, [o for o in lights if o.data.type == "AREA"]) as emitters, \
            lightmap.own_outputs(materials), \
            _selected(context, objects + [o for o in lights if o.data.type != "AREA"] + camera + emitters):
        result = bpy.ops.export_scene.gltf(
            filepath=path, export_format="GLB", use_selection=True, export_apply=True,
            export_yup=True, export_texcoords=True, export_normals=True, export_colors=True,
            export_materials="EXPORT", export_cameras=True, export_lights=True,
            convert_lighting_mode="COMPAT", export_extras=True, export_animations=False,
            export_skins=False, export_morph=False, will_save_settings=False)
    if "FINISHED" not in result:
        raise RuntimeError(f"{path}: Blender's glTF exporter failed")
    return warnings


def sky_settings(world, folder):
    """The World's light as the keywords of lightoctree.bake and lightmap
    (`sky`, and `sky_image` for an environment texture, written turned to
    the project's frame into `folder`) and warnings for the user. The project
    takes the upper hemisphere of it (docs/scene.md, "Sky")."""
    if world is None:
        return {"sky": (0.0, 0.0, 0.0)}, []
    if not world.use_nodes:
        return {"sky": tuple(world.color)}, []
    shader = _world_shader(world)
    if shader is None:
        return {"sky": (0.0, 0.0, 0.0)}, []
    if shader.type != "BACKGROUND":
        return {"sky": tuple(world.color)}, [
            f"World '{world.name}': its light comes from a {shader.bl_label} node; the bake "
            f"takes the World's viewport colour instead (a Background node is read)"]
    return _background_sky(world, shader, folder)


def _world_shader(world):
    """The shader node that lights the World (past the camera-only mix that
    renders.setup puts in), or None when nothing feeds its output."""
    output = next((n for n in world.node_tree.nodes
                   if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    socket = output.inputs["Surface"] if output else None
    while socket is not None and socket.is_linked:
        node = socket.links[0].from_node
        if not (node.type == "MIX_SHADER" and node.name.startswith(lightmap.PREFIX)):
            return node
        socket = node.inputs[2]  # the sky the camera sees
    return None


def _background_sky(world, background, folder):
    """A Background node's colour x strength, or its equirectangular
    environment texture (written as the project's sky image) x strength."""
    strength = background.inputs["Strength"].default_value
    colour = background.inputs["Color"]
    if not colour.is_linked:
        return {"sky": tuple(strength * c for c in colour.default_value[:3])}, []
    source = colour.links[0].from_node
    if source.type != "TEX_ENVIRONMENT" or source.image is None or source.projection != "EQUIRECTANGULAR":
        return {"sky": (0.0, 0.0, 0.0)}, [
            f"World '{world.name}': its colour comes from a {source.bl_label} node, which the "
            f"bake cannot read (an equirectangular Environment Texture it can): no sky light baked"]
    warnings = []
    if source.inputs["Vector"].is_linked:
        warnings.append(f"World '{world.name}': the environment texture's vector input "
                        f"(a rotation) is not read: the sky is baked unturned")
    path = os.path.join(folder, "sky.exr")
    _write_sky_image(source.image, path)
    return {"sky": (strength,) * 3, "sky_image": path}, warnings


def _write_sky_image(image, path):
    """The equirectangular `image` as the project's sky image (EXR): its
    middle column looks along Blender's +Y (glTF's -Z), Blender's along +X,
    azimuth turning the same way: the columns rolled by a quarter turn."""
    width, height = image.size
    if width < 2 or height < 2:
        raise ValueError(f"environment texture '{image.name}' has no pixels to read")
    pixels = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(pixels)
    pixels = pixels.reshape(height, width, image.channels)
    rgba = np.ones((height, width, 4), np.float32)
    rgba[..., :3] = pixels[..., :3] if image.channels >= 3 else pixels[..., :1]
    rgba = np.roll(rgba, round(width / 4), axis=1)
    if image.colorspace_settings.name == "sRGB" and not image.is_float:
        rgba[..., :3] = np.where(rgba[..., :3] <= 0.04045, rgba[..., :3] / 12.92,
                                 ((rgba[..., :3] + 0.055) / 1.055) ** 2.4)
    out = bpy.data.images.new("Light Octree sky", width, height, alpha=False, float_buffer=True)
    out.colorspace_settings.name = "Non-Color"  # written as it is (Linear would be sRGB-encoded)
    try:
        out.pixels.foreach_set(rgba.ravel())
        out.filepath_raw = path
        out.file_format = "OPEN_EXR"
        out.save()
    finally:
        bpy.data.images.remove(out)


def _light_warnings(lights):
    """What the glTF light of each Blender light leaves out."""
    warnings = []
    for obj in lights:
        light = obj.data
        if light.type == "AREA" and light.spread < math.pi - 1e-4:
            warnings.append(f"area light '{obj.name}': its spread "
                            f"{math.degrees(light.spread):.0f} degrees is baked as 180")
        if light.use_nodes:
            warnings.append(f"light '{obj.name}': its node tree is read as the glTF exporter "
                            f"reads it (an Emission node's strength), not as Cycles renders it")
    return warnings


@contextlib.contextmanager
def _area_lights_as_emitters(context, lights):
    """Within: an emissive mesh object for each area light, removed after."""
    made = [_emitter(context, obj) for obj in lights]
    try:
        yield made
    finally:
        for obj in made:
            mesh, material = obj.data, obj.data.materials[0]
            bpy.data.objects.remove(obj)
            bpy.data.meshes.remove(mesh)
            bpy.data.materials.remove(material)


def _emitter(context, light_obj):
    """An area light as a one-sided emissive polygon where the light is,
    facing its -Z as the light does, of radiance colour x P / (4 A): the
    radiance Cycles 3.4 gives an area light of P watts and world area A."""
    light = light_obj.data
    a = light.size / 2
    b = (light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size) / 2
    if light.shape in ("DISK", "ELLIPSE"):
        # A polygon of the ellipse's area (its corners slightly outside it).
        grow = math.sqrt(2 * math.pi / (_DISK_SIDES * math.sin(2 * math.pi / _DISK_SIDES)))
        angles = [-2 * math.pi * i / _DISK_SIDES for i in range(_DISK_SIDES)]  # clockwise: faces -Z
        corners = [(grow * a * math.cos(t), grow * b * math.sin(t), 0.0) for t in angles]
    else:
        corners = [(-a, -b, 0.0), (-a, b, 0.0), (a, b, 0.0), (a, -b, 0.0)]  # clockwise: faces -Z
    mesh = bpy.data.meshes.new(f"{lightmap.PREFIX} emitter {light_obj.name}")
    mesh.from_pydata(corners, [], [list(range(len(corners)))])
    for name in ("UVMap", "LightOctree"):  # zero UVs: the project gives an emitter no texels
        mesh.uv_layers.new(name=name, do_init=False).data.foreach_set(
            "uv", np.zeros(2 * len(mesh.loops), np.float32))
    obj = bpy.data.objects.new(mesh.name, mesh)
    obj.matrix_world = light_obj.matrix_world
    area = _world_area(obj)
    if area <= 0:
        raise ValueError(f"area light '{light_obj.name}' has no area")
    mesh.materials.append(_emission_material(mesh.name, light.color, light.energy / (4 * area)))
    context.scene.collection.objects.link(obj)
    return obj


def _world_area(obj):
    m = np.array(obj.matrix_world)
    co = np.array([v.co for v in obj.data.vertices]) @ m[:3, :3].T
    edges = co[1:] - co[0]
    return 0.5 * abs(np.linalg.norm(np.cross(edges[:-1], edges[1:]).sum(axis=0)))


def _emission_material(name, colour, radiance):
    """Black, emitting `radiance` x `colour` from its front face only."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.use_backface_culling = True  # glTF: doubleSided false, the project emits one side
    principled = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    principled.inputs["Emission"].default_value = (*colour, 1.0)
    principled.inputs["Emission Strength"].default_value = radiance
    return mat


@contextlib.contextmanager
def _selected(context, objects):
    """Within: `objects` and nothing else selected; after, the selection as it was."""
    layer = context.view_layer
    before = [o for o in layer.objects if o.select_get()]
    chosen = set(objects)
    for o in layer.objects:
        o.select_set(o in chosen)
    try:
        yield
    finally:
        for o in layer.objects:
            o.select_set(o in before)
