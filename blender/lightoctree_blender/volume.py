# A Light Octree bake (.vdb) as a Blender Volume object.
import math
import os

import bpy


def grid_names(obj):
    return [g.name for g in obj.data.grids]


def import_bake(context, path, strength=1.0):
    """The .vdb as a Volume object, turned from glTF's Y up to Blender's Z up
    (the bake's coordinates are the scene file's, metres), with a material
    whose emission is the irradiance grid (no density: the light shows
    without shadowing itself)."""
    if not os.path.isfile(path):
        raise OSError(f"{path}: no such file")
    name = os.path.splitext(os.path.basename(path))[0]
    data = bpy.data.volumes.new(name)
    data.filepath = path
    if not data.grids.load():
        raise RuntimeError(f"{path}: Blender could not read the file ({data.grids.error_message})")
    if "irradiance" not in [g.name for g in data.grids]:
        raise ValueError(f"{path}: no 'irradiance' grid: not a Light Octree bake")
    obj = bpy.data.objects.new(name, data)
    # glTF (and the bake) are Y up; Blender is Z up: the glTF importer's turn,
    # (x, y, z) -> (x, -z, y), is +90 degrees about X.
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)
    context.collection.objects.link(obj)
    obj.data.materials.append(_material(name, strength))
    obj["lightoctree"] = {"source": path, "up_axis": "+Y (turned to +Z)"}
    return obj


def _material(name, strength):
    mat = bpy.data.materials.new(f"{name} irradiance")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    vol = nodes.new("ShaderNodeVolumePrincipled")
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "irradiance"
    vol.inputs["Density"].default_value = 0.0
    vol.inputs["Emission Strength"].default_value = strength
    links.new(attr.outputs["Color"], vol.inputs["Emission Color"])
    links.new(vol.outputs["Volume"], out.inputs["Volume"])
    attr.location, vol.location, out.location = (-400, 0), (-150, 0), (150, 0)
    return mat
