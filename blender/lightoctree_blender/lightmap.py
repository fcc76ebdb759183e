# Lightmap pages (docs/lightmap.md) wired into Blender materials: after
# Blender's glTF importer (a glTF written by `lightoctree lightmap`), or in
# place into the scene a bake from the panel exported. Each material gets
# its own Material Output fed by the page's light (its nodes named "Light
# Octree ..." in a frame); the material's own output stays as it was, only
# no longer active, so the wiring comes off (or is redone) cleanly.
import contextlib
import json
import math
import os

import bpy

PREFIX = "Light Octree"  # the name of every node the wiring adds


def fix_numpy():
    """Blender 3.4's glTF importer and exporter use numpy.bool, which numpy
    1.24 removed (Debian 12 ships both): they fail before reading a byte."""
    import numpy
    if "bool" not in vars(numpy):
        numpy.bool = bool


def import_lightmapped_gltf(context, path, mode="ADD"):
    """Imports `path` and wires every lightmapped material; returns how many."""
    if not os.path.isfile(path):
        raise OSError(f"{path}: no such file")
    fix_numpy()
    before = set(bpy.data.materials)
    result = bpy.ops.import_scene.gltf(filepath=path)
    if "FINISHED" not in result:
        raise RuntimeError(f"{path}: the glTF importer failed")
    folder = os.path.dirname(os.path.abspath(path))
    wired = 0
    for mat in [m for m in bpy.data.materials if m not in before]:
        lightmap = mat.get("lightmap")
        if lightmap is None or mat.get("lightmapPreview") is not None:
            continue
        wired += wire_material(mat, lightmap.to_dict(), folder, _uv_name(mat), mode)
    return wired


def apply_lightmaps(materials, path, mode, uv_name):
    """Wires into `materials` (Blender's, in place) the pages that the glTF
    `path` written by `lightoctree lightmap` gives the materials of the same
    names, their lightmap UVs the UV map `uv_name`; returns how many."""
    extras = material_extras(path)
    folder = os.path.dirname(os.path.abspath(path))
    return sum(wire_material(mat, extras[mat.name], folder, uv_name, mode)
               for mat in materials if mat.name in extras)


def material_extras(path):
    """{material name: its extras.lightmap} of a .gltf or .glb file."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":  # binary: the JSON chunk follows the 12-byte header
        length = int.from_bytes(data[12:16], "little")
        data = data[20:20 + length]
    doc = json.loads(data)
    return {m["name"]: m["extras"]["lightmap"] for m in doc.get("materials", [])
            if "name" in m and "lightmap" in m.get("extras", {})}


def wire_material(mat, lightmap, folder, uv_name, mode):
    """Lights `mat` by its page (`lightmap`: the material's extras.lightmap,
    its files in `folder`), read through the UV map `uv_name`; an earlier
    wiring is replaced. False for a material without nodes, a Principled BSDF
    or an output (left as it is)."""
    unwire_material(mat)
    if not mat.use_nodes:
        return False
    nodes = mat.node_tree.nodes
    principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if principled is None or output is None:
        return False
    _wire(mat, lightmap, folder, uv_name, mode, principled, output)
    return True


def unwire_material(mat):
    """Takes a wiring off: its nodes removed, the material's own output active."""
    if not mat.use_nodes:
        return
    nodes = mat.node_tree.nodes
    for node in [n for n in nodes if n.name.startswith(PREFIX)]:
        nodes.remove(node)
    _activate_own_output(mat)
    if "lightoctree" in mat:
        del mat["lightoctree"]


@contextlib.contextmanager
def own_outputs(materials):
    """Within: each wired material shows its own output again (what Blender's
    glTF exporter must see: not the baked light as emission); after: the
    wiring's output is active again."""
    wired = [m for m in materials if m.use_nodes and _wiring_output(m) is not None]
    for mat in wired:
        _activate_own_output(mat)
    try:
        yield
    finally:
        for mat in wired:
            output = _wiring_output(mat)
            if output is not None:
                output.is_active_output = True


def _wiring_output(mat):
    return next((n for n in mat.node_tree.nodes
                 if n.type == "OUTPUT_MATERIAL" and n.name.startswith(PREFIX)), None)


def _activate_own_output(mat):
    own = [n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL" and not n.name.startswith(PREFIX)]
    if own and not any(n.is_active_output for n in own):
        own[0].is_active_output = True


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
    image = _image(path)
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
    """Adds nodes to a material's tree, in a column left of x0, each named
    PREFIX ... and framed, so that unwire_material finds them."""

    def __init__(self, mat, x0):
        self.tree = mat.node_tree
        self.x, self.y = x0, 600
        self.frame = None
        self.frame = self.new("NodeFrame", label="Light Octree lightmap")
        self.frame.location = (0, 0)  # its nodes' locations are relative to it

    def new(self, kind, **settings):
        node = self.tree.nodes.new(kind)
        node.name = f"{PREFIX} {node.bl_label}"
        node.parent = self.frame
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


def _wire(mat, lightmap, folder, uv_name, mode, principled, output):
    """The nodes of the page's light and a new active output they feed:
    with the material's own shader (ADD) or alone (BAKE_ONLY)."""
    page = os.path.join(folder, lightmap["uri"])
    if not os.path.isfile(page):
        raise OSError(f"{mat.name}: its lightmap page {page} is missing")
    n = _Nodes(mat, principled.location.x - 900)
    uv = n.new("ShaderNodeUVMap", uv_map=uv_name)
    image = _image(page)
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
        # The baked light is what the camera and reflections see, not a light:
        # Cycles counts emission that a diffuse ray meets as light on the
        # surface the ray left (even with no diffuse bounces), which would
        # add the indirect light a second time.
        path = n.new("ShaderNodeLightPath")
        n.link(n.math("MAXIMUM", path.outputs["Is Camera Ray"], path.outputs["Is Glossy Ray"]),
               baked.inputs["Strength"])
    n.link(baked.outputs[0], add.inputs[1])
    ours = n.new("ShaderNodeOutputMaterial", target=output.target)
    ours.location = (output.location.x, output.location.y - 300)
    ours.parent = None
    n.link(add.outputs[0], ours.inputs["Surface"])
    for name in ("Volume", "Displacement"):  # as the material's own output has them
        if output.inputs[name].is_linked:
            n.link(output.inputs[name].links[0].from_socket, ours.inputs[name])
    ours.is_active_output = True
    # The lit surfaces are no lights in Cycles: its light sampling would pick
    # their baked emission for nothing (docs/blender.md).
    if hasattr(mat, "cycles"):
        mat.cycles.sample_as_light = False
    mat["lightoctree"] = {"page": page, "mode": mode}


def _image(path):
    """The image of `path`, read again when Blender holds an older copy (a re-bake)."""
    image = bpy.data.images.load(path, check_existing=True)
    image.reload()
    return image
