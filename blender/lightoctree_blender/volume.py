# A Light Octree bake (.vdb) as a Blender Volume object.
import math
import os

import bpy

from . import module


def grid_names(obj):
    return [g.name for g in obj.data.grids]


def replace_bake(context, path, arrows=False, max_arrows=20000):
    """import_bake of `path`, removing first what an earlier import of the
    same file made (the panel's re-bake)."""
    for obj in [o for o in bpy.data.objects if o.get("lightoctree", {}).get("source") == path]:
        data = obj.data
        bpy.data.objects.remove(obj)
        if data is not None and data.users == 0:
            (bpy.data.volumes if isinstance(data, bpy.types.Volume) else bpy.data.meshes).remove(data)
    return import_bake(context, path, arrows=arrows, max_arrows=max_arrows)


def import_bake(context, path, strength=1.0, arrows=False, max_arrows=20000):
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
    obj.data.materials.append(_irradiance_material(f"{name} irradiance", strength))
    obj["lightoctree"] = {"source": path, "up_axis": "+Y (turned to +Z)"}
    if arrows:
        add_vdl_arrows(context, path, obj, max_arrows)
    return obj


def add_vdl_arrows(context, path, volume_obj, max_arrows=20000):
    """Each voxel's strongest VDL as an arrow pointing towards its light, its
    colour the VDL's irradiance: a point per voxel (at most `max_arrows`,
    evenly picked) with `direction` and `irradiance` attributes, instanced as
    cones by a geometry nodes modifier. Reading the VDLs needs the project's
    Python module (docs/python.md): Blender 3.4 reads no voxel values."""
    import numpy as np
    lightoctree = module.load()  # ModuleMissing (a RuntimeError) says what to do
    grid = lightoctree.read(path)
    if grid.sh_terms > 0:
        raise ValueError(f"{path}: holds spherical harmonics, not VDLs: no arrows to draw")
    keep = np.nonzero(np.asarray(grid.vdl_count) > 0)[0]
    if len(keep) > max_arrows:
        keep = keep[np.linspace(0, len(keep) - 1, max_arrows).astype(np.int64)]
    positions = np.asarray(grid.positions)[keep].astype(np.float32)
    direction = np.asarray(grid.vdl_direction)[keep, 0].astype(np.float32)
    irradiance = np.asarray(grid.vdl_irradiance)[keep, 0].astype(np.float32)
    name = f"{volume_obj.name} VDLs"
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(keep))
    mesh.vertices.foreach_set("co", positions.ravel())
    mesh.attributes.new("direction", "FLOAT_VECTOR", "POINT").data.foreach_set("vector", direction.ravel())
    rgba = np.concatenate([irradiance, np.ones((len(keep), 1), np.float32)], axis=1)
    mesh.attributes.new("irradiance", "FLOAT_COLOR", "POINT").data.foreach_set("color", rgba.ravel())
    obj = bpy.data.objects.new(name, mesh)
    obj.rotation_euler = volume_obj.rotation_euler  # the same turn to Z up
    context.collection.objects.link(obj)
    modifier = obj.modifiers.new("VDL arrows", "NODES")
    modifier.node_group = _arrow_nodes(0.8 * grid.voxel_size, _irradiance_material(name))
    obj["lightoctree"] = {"source": path, "arrows": len(keep), "voxels": grid.size}
    return obj


def _arrow_nodes(length, material):
    """Geometry nodes: a cone `length` long on every point, its tip along the
    point's `direction` attribute, realised so its attributes reach the shader."""
    g = bpy.data.node_groups.new("Light Octree VDL arrows", "GeometryNodeTree")
    g.inputs.new("NodeSocketGeometry", "Geometry")
    g.outputs.new("NodeSocketGeometry", "Geometry")
    nodes, links = g.nodes, g.links
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    cone = nodes.new("GeometryNodeMeshCone")
    cone.inputs["Vertices"].default_value = 8
    cone.inputs["Radius Top"].default_value = 0.0
    cone.inputs["Radius Bottom"].default_value = 0.15 * length
    cone.inputs["Depth"].default_value = length
    base = nodes.new("GeometryNodeTransform")  # the cone's base at the point
    base.inputs["Translation"].default_value = (0.0, 0.0, 0.5 * length)
    links.new(cone.outputs["Mesh"], base.inputs["Geometry"])
    attribute = nodes.new("GeometryNodeInputNamedAttribute")
    attribute.data_type = "FLOAT_VECTOR"
    attribute.inputs["Name"].default_value = "direction"
    align = nodes.new("FunctionNodeAlignEulerToVector")
    align.axis = "Z"
    links.new(next(s for s in attribute.outputs if s.enabled), align.inputs["Vector"])
    instance = nodes.new("GeometryNodeInstanceOnPoints")
    links.new(group_in.outputs[0], instance.inputs["Points"])
    links.new(base.outputs["Geometry"], instance.inputs["Instance"])
    links.new(align.outputs["Rotation"], instance.inputs["Rotation"])
    realize = nodes.new("GeometryNodeRealizeInstances")
    links.new(instance.outputs["Instances"], realize.inputs["Geometry"])
    set_material = nodes.new("GeometryNodeSetMaterial")
    set_material.inputs["Material"].default_value = material
    links.new(realize.outputs["Geometry"], set_material.inputs["Geometry"])
    links.new(set_material.outputs["Geometry"], group_out.inputs[0])
    for i, node in enumerate([group_in, cone, base, attribute, align, instance, realize,
                              set_material, group_out]):
        node.location = (200 * i, 0)
    return g


def _irradiance_material(name, volume_strength=None):
    """A material that shows the `irradiance` attribute (W/m^2 as is) as
    emission: of a volume (a Principled Volume of density 0, its emission
    scaled by `volume_strength`) or, when that is None, of a surface."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "irradiance"
    if volume_strength is None:
        shader = nodes.new("ShaderNodeEmission")
        links.new(attr.outputs["Color"], shader.inputs["Color"])
        links.new(shader.outputs[0], out.inputs["Surface"])
    else:
        shader = nodes.new("ShaderNodeVolumePrincipled")
        shader.inputs["Density"].default_value = 0.0
        shader.inputs["Emission Strength"].default_value = volume_strength
        links.new(attr.outputs["Color"], shader.inputs["Emission Color"])
        links.new(shader.outputs["Volume"], out.inputs["Volume"])
    attr.location, shader.location, out.location = (-400, 0), (-150, 0), (150, 0)
    return mat
