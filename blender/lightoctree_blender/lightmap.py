# A glTF written by `lightoctree lightmap`, imported with Blender's glTF
# importer, each material's lightmap page (extras.lightmap, docs/lightmap.md)
# wired into its node tree.
import math
import os

import bpy


def _fix_numpy():
    # Blender 3.4's glTF importer uses numpy.bool, which numpy 1.24 removed
    # (Debian 12 ships both): the importer fails before reading a byte.
    import numpy
    if "bool" not in vars(numpy):
        numpy.bool = bool


def import_lightmapped_gltf(context, path, mode="ADD"):
    """Imports `path` and wires every lightmapped material; returns how many."""
    if not os.path.isfile(path):
        raise OSError(f"{path}: no such file")
    _fix_numpy()
    before = set(bpy.data.materials)
    result = bpy.ops.import_scene.gltf(filepath=path)
    if "FINISHED" not in result:
        raise RuntimeError(f"{path}: the glTF importer failed")
    folder = os.path.dirname(os.path.abspath(path))
    wired = 0
    for mat in [m for m in bpy.data.materials if m not in before]:
        lightmap = mat.get("lightmap")
        if lightmap is None or mat.get("lightmapPreview") is not None or not mat.use_nodes:
            continue
        _wire(mat, lightmap.to_dict(), folder, _uv_name(mat), mode)
        wired += 1
    return wired


def _uv_name(mat):
    """The name the importer gave TEXCOORD_1 on the meshes using `mat`."""
    for obj in bpy.data.objects:
        if obj.type == "MESH" and mat.name in [m.name for m in obj.data.materials if m]:
            if len(obj.data.uv_layers) > 1:
                return obj.data.uv_layers[1].name
    return "UVMap.001"


def _directional(n, principled, direction, folder, uv, irradiance):
    """E scaled by how the shading normal (normal map included) faces the
    texel's light direction d against how the vertex normal does, as
    `lightoctree render --lighting atlas` shades its diffuse part:
    E * max(n . d, 0) / max(n_vertex . d, 0.05)."""
    path = os.path.join(folder, direction["uri"])
    if direction.get("encoding") != "unit-vector-png" or not os.path.isfile(path):
        return irradiance  # the irradiance alone, as without direction pages
    image = bpy.data.images.load(path, check_existing=True)
    image.colorspace_settings.name = "Non-Color"
    tex = n.new("ShaderNodeTexImage", image=image, interpolation="Linear", extension="EXTEND")
    n.link(uv.outputs["UV"], tex.inputs["Vector"])
    # d = (byte - 128) / 127 per channel, in glTF's frame (Y up); Blender's
    # importer turns (x, y, z) into (x, -z, y).
    decode = n.new("ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    n.link(tex.outputs["Color"], decode.inputs[0])
    decode.inputs[1].default_value = (255 / 127,) * 3
    decode.inputs[2].default_value = (-128 / 127,) * 3
    xyz = n.new("ShaderNodeSeparateXYZ")
    n.link(decode.outputs["Vector"], xyz.inputs[0])
    flip = n.math("MULTIPLY", xyz.outputs["Z"], -1.0)
    frame = n.new("ShaderNodeCombineXYZ")
    n.link(xyz.outputs["X"], frame.inputs["X"])
    n.link(flip, frame.inputs["Y"])
    n.link(xyz.outputs["Y"], frame.inputs["Z"])
    d = n.new("ShaderNodeVectorMath", operation="NORMALIZE")
    n.link(frame.outputs["Vector"], d.inputs[0])
    geometry = n.new("ShaderNodeNewGeometry")
    normal = principled.inputs["Normal"]
    shading = normal.links[0].from_socket if normal.is_linked else geometry.outputs["Normal"]

    def facing(vector):
        dot = n.new("ShaderNodeVectorMath", operation="DOT_PRODUCT")
        n.link(vector, dot.inputs[0])
        n.link(d.outputs["Vector"], dot.inputs[1])
        return dot.outputs["Value"]

    factor = n.math("DIVIDE", n.math("MAXIMUM", facing(shading), 0.0),
                    n.math("MAXIMUM", facing(geometry.outputs["Normal"]), 0.05))
    # No direction (a texel no light reaches): the irradiance as it is.
    length = n.new("ShaderNodeVectorMath", operation="LENGTH")
    n.link(frame.outputs["Vector"], length.inputs[0])
    has = n.math("GREATER_THAN", length.outputs["Value"], 1e-3)
    factor = n.math("ADD", n.math("MULTIPLY", n.math("SUBTRACT", factor, 1.0), has), 1.0)
    scaled = n.new("ShaderNodeVectorMath", operation="SCALE")
    n.link(irradiance, scaled.inputs[0])
    n.link(factor, scaled.inputs["Scale"])
    return scaled.outputs["Vector"]


class _Nodes:
    """Adds nodes to a material's tree, laid out in a column left of x0."""

    def __init__(self, mat, x0):
        self.tree = mat.node_tree
        self.x, self.y = x0, 600

    def new(self, kind, **settings):
        node = self.tree.nodes.new(kind)
        node.location = (self.x, self.y)
        self.y -= 220
        for key, value in settings.items():
            setattr(node, key, value)
        return node

    def link(self, a, b):
        self.tree.links.new(a, b)

    def source(self, socket, kind="ShaderNodeValue"):
        """What feeds an input: its link, or a node holding its value."""
        if socket.is_linked:
            return socket.links[0].from_socket
        node = self.new(kind)
        node.outputs[0].default_value = socket.default_value
        return node.outputs[0]

    def math(self, op, a, b):
        node = self.new("ShaderNodeMath", operation=op)
        for i, v in enumerate((a, b)):
            if isinstance(v, (int, float)):
                node.inputs[i].default_value = v
            else:
                self.link(v, node.inputs[i])
        return node.outputs[0]


def _wire(mat, lightmap, folder, uv_name, mode):
    page = os.path.join(folder, lightmap["uri"])
    if not os.path.isfile(page):
        raise OSError(f"{mat.name}: its lightmap page {page} is missing")
    nodes = mat.node_tree.nodes
    principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if principled is None or output is None:
        return
    n = _Nodes(mat, principled.location.x - 900)
    uv = n.new("ShaderNodeUVMap", uv_map=uv_name)
    image = bpy.data.images.load(page, check_existing=True)
    image.colorspace_settings.name = "Non-Color"  # E in W/m^2, linear
    rgbm = lightmap.get("encoding") == "rgbm-png"
    if rgbm:
        image.alpha_mode = "CHANNEL_PACKED"  # A is RGBM's multiplier, not coverage
    tex = n.new("ShaderNodeTexImage", image=image, interpolation="Linear", extension="EXTEND")
    n.link(uv.outputs["UV"], tex.inputs["Vector"])
    irradiance = tex.outputs["Color"]
    if rgbm:
        # E = RGB x A x rgbmRange (docs/lightmap.md, "Encodings").
        scale = n.math("MULTIPLY", tex.outputs["Alpha"], float(lightmap["rgbmRange"]))
        decode = n.new("ShaderNodeVectorMath", operation="SCALE")
        n.link(irradiance, decode.inputs[0])
        n.link(scale, decode.inputs["Scale"])
        irradiance = decode.outputs["Vector"]
    if lightmap.get("direction"):
        irradiance = _directional(n, principled, lightmap["direction"], folder, uv, irradiance)
    # radiance = baseColor / pi * E, on the diffuse part of the material only:
    # (1 - metallic) (1 - transmission), times alpha.
    times_base = n.new("ShaderNodeVectorMath", operation="MULTIPLY")
    n.link(irradiance, times_base.inputs[0])
    n.link(n.source(principled.inputs["Base Color"], "ShaderNodeRGB"), times_base.inputs[1])
    weight = n.math("SUBTRACT", 1.0, n.source(principled.inputs["Metallic"]))
    weight = n.math("MULTIPLY", weight, n.math("SUBTRACT", 1.0, n.source(principled.inputs["Transmission"])))
    weight = n.math("MULTIPLY", weight, n.source(principled.inputs["Alpha"]))
    weight = n.math("MULTIPLY", weight, 1.0 / math.pi)
    radiance = n.new("ShaderNodeVectorMath", operation="SCALE")
    n.link(times_base.outputs["Vector"], radiance.inputs[0])
    n.link(weight, radiance.inputs["Scale"])
    baked = n.new("ShaderNodeEmission", label="Light Octree lightmap")
    n.link(radiance.outputs["Vector"], baked.inputs["Color"])
    baked.inputs["Strength"].default_value = 1.0
    add = n.new("ShaderNodeAddShader")
    if mode == "BAKE_ONLY":
        # The bake and the material's own emission, nothing Blender lights.
        own = n.new("ShaderNodeEmission", label="the material's emission")
        n.link(n.source(principled.inputs["Emission"], "ShaderNodeRGB"), own.inputs["Color"])
        n.link(n.source(principled.inputs["Emission Strength"]), own.inputs["Strength"])
        n.link(own.outputs[0], add.inputs[0])
    else:
        surface = output.inputs["Surface"]
        shader = surface.links[0].from_socket if surface.is_linked else principled.outputs[0]
        n.link(shader, add.inputs[0])
    n.link(baked.outputs[0], add.inputs[1])
    n.link(add.outputs[0], output.inputs["Surface"])
    mat["lightoctree"] = {"page": page, "mode": mode}
