# Lightmap UVs for a bake from Blender: every baked mesh gets a second UV
# map, "LightOctree" (glTF's TEXCOORD_1), laid out by Smart UV Project per
# object and the objects packed side by side into one square atlas at one
# texel density (world area per texel), with a gutter between charts. The
# project then bakes into those very UVs (`lightmap --uv texcoord1`), so its
# pages fit the scene as Blender renders it.
import math

import bpy
import numpy as np

LIGHTMAP_UV = "LightOctree"
GUTTER_TEXELS = 3  # between charts: no texel is covered by two, bilinear reads stay apart
# Modifiers that copy a mesh's UVs onto new geometry: the copies' lightmap
# texels would overlap.
_COPYING_MODIFIERS = {"ARRAY", "MIRROR", "SOLIDIFY", "SCREW"}


def problems(objects):
    """What stops these mesh objects from sharing one lightmap atlas, as
    sentences for the user (empty when nothing does)."""
    found = []
    users = {}
    for obj in objects:
        users.setdefault(obj.data.name, []).append(obj.name)
        layers = obj.data.uv_layers
        if len(layers) > 1 and layers[1].name != LIGHTMAP_UV:
            found.append(f"mesh '{obj.data.name}': its second UV map '{layers[1].name}' would be "
                         f"the lightmap's (glTF's TEXCOORD_1); rename it '{LIGHTMAP_UV}' to bake "
                         f"into it as it is, or remove it")
        for mod in obj.modifiers:
            if mod.type in _COPYING_MODIFIERS and mod.show_render:
                found.append(f"object '{obj.name}': its {mod.type.title()} modifier '{mod.name}' "
                             f"copies the lightmap UVs, so texels would overlap: apply it first")
    for mesh, names in users.items():
        if len(names) > 1:
            found.append(f"objects {', '.join(repr(n) for n in names)} share the mesh '{mesh}': "
                         f"each needs its own lightmap texels (Object > Relation > Make Single User)")
    return found


def needs_packing(objects, atlas):
    """Whether any mesh lacks lightmap UVs packed for this atlas size, or
    changed its faces since they were packed."""
    return any(list(obj.data.get("lightoctree_uv", [])) != _fingerprint(obj.data, atlas) for obj in objects)


def pack(context, objects, atlas):
    """Gives every object a LightOctree UV map (and a first UV map where it
    has none), unwraps each and packs them all into [0, 1]^2 at one texel
    density with GUTTER_TEXELS texels between charts of an atlas x atlas page."""
    for obj in objects:
        layers = obj.data.uv_layers
        if not layers:
            layers.new(name="UVMap")
        if LIGHTMAP_UV not in layers:
            layers.new(name=LIGHTMAP_UV, do_init=False)
    # Smart UV Project's margin is a share of each object's own square; the
    # gutter is in texels of the atlas: unwrap once to learn each object's
    # share of the atlas, then again with the margin that gives the gutter.
    with _editing(context) as unwrap:
        for obj in objects:
            unwrap(obj, 0.02)
        scales = _pack_layout(objects, atlas)[1]
        for obj, scale in zip(objects, scales):
            unwrap(obj, min(0.3, max(0.002, 1.5 * GUTTER_TEXELS / (scale * atlas))))
    placements, scales = _pack_layout(objects, atlas)
    for obj, (offset, lower), scale in zip(objects, placements, scales):
        uv = _uvs(obj.data)
        _set_uvs(obj.data, offset + (uv - lower) * scale)
        obj.data["lightoctree_uv"] = _fingerprint(obj.data, atlas)


def _fingerprint(mesh, atlas):
    return [len(mesh.vertices), len(mesh.polygons), len(mesh.loops), int(atlas)]


def _uvs(mesh):
    layer = mesh.uv_layers[LIGHTMAP_UV]
    uv = np.empty(2 * len(mesh.loops), np.float32)
    layer.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2).astype(np.float64)


def _set_uvs(mesh, uv):
    mesh.uv_layers[LIGHTMAP_UV].data.foreach_set("uv", uv.astype(np.float32).ravel())
    mesh.update()  # the viewport draws the new UVs, not the ones it has cached


def _areas(obj):
    """(world area, UV area) of the object's faces, as the renderer sees them."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    loops = np.empty(3 * len(mesh.loop_triangles), np.int64)
    mesh.loop_triangles.foreach_get("loops", loops)
    loops = loops.reshape(-1, 3)
    corners = np.empty(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("vertex_index", corners)
    co = np.empty(3 * len(mesh.vertices), np.float64)
    mesh.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    world = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    p = world[corners[loops]]
    world_area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    t = _uvs(mesh)[loops]
    e1, e2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    uv_area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    return world_area, uv_area


def _pack_layout(objects, atlas):
    """Where each object's chart square goes: ([(offset, its UVs' lower
    corner)], [scale from its UVs to the atlas]), one density for all, rows
    of rectangles tallest first, GUTTER_TEXELS apart."""
    boxes, density = [], []
    for obj in objects:
        uv = _uvs(obj.data)
        world_area, uv_area = _areas(obj)
        density.append(math.sqrt(world_area / uv_area) if uv_area > 0 and world_area > 0 else 1e-6)
        boxes.append((uv.min(axis=0), uv.max(axis=0) - uv.min(axis=0)))
    sizes = np.array([size * d for (_, size), d in zip(boxes, density)])
    # The gap is in texels of the result, whose scale the packing decides:
    # pack, measure, pack again with the gap in those units.
    scale, gap = 1.0, 0.0
    for _ in range(3):
        positions, extent = _best_rows(sizes, gap)
        scale = 1.0 / (extent + 2.0 * gap)  # the same gap from the atlas's border
        gap = GUTTER_TEXELS / (atlas * scale)
    positions, extent = _best_rows(sizes, gap)
    scale = 1.0 / (extent + 2.0 * gap)
    placements = [((positions[i] + gap) * scale, boxes[i][0]) for i in range(len(objects))]
    return placements, [d * scale for d in density]


def _best_rows(sizes, gap):
    """Rows of `sizes` (tallest first) for a few row widths: the positions and
    extent of the layout whose larger side is smallest."""
    total = float(np.sum((sizes[:, 0] + gap) * (sizes[:, 1] + gap))) if len(sizes) else 0.0
    widest = float(sizes[:, 0].max()) if len(sizes) else 0.0
    best = None
    for factor in (1.0, 1.1, 1.25, 1.5, 2.0):
        width = max(widest, factor * math.sqrt(total))
        positions, extent = _rows(sizes, gap, width)
        if best is None or extent < best[1]:
            best = (positions, extent)
    return best


def _rows(sizes, gap, width):
    order = np.argsort(-sizes[:, 1], kind="stable")
    positions = np.zeros_like(sizes)
    x = y = row = 0.0
    right = 0.0
    for i in order:
        w, h = sizes[i]
        if x > 0 and x + w > width:
            x, y, row = 0.0, y + row + gap, 0.0
        positions[i] = (x, y)
        x += w + gap
        row = max(row, h)
        right = max(right, x - gap)
    return positions, max(right, y + row)


class _editing:
    """Runs Smart UV Project on one object at a time (Edit Mode, every face,
    the LightOctree map active), then gives back the mode, selection, active
    object and active UV maps as they were."""

    def __init__(self, context):
        self.context = context

    def __enter__(self):
        layer = self.context.view_layer
        self.active = layer.objects.active
        self.selected = [o for o in layer.objects if o.select_get()]
        self.mode = self.context.object.mode if self.context.object else "OBJECT"
        if self.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        return self.unwrap

    def unwrap(self, obj, margin):
        layer = self.context.view_layer
        for o in layer.objects:
            o.select_set(o == obj)
        layer.objects.active = obj
        hidden = obj.hide_get()
        obj.hide_set(False)
        layers = obj.data.uv_layers
        before = layers.active_index
        layers.active = layers[LIGHTMAP_UV]
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.uv.smart_project(angle_limit=math.radians(66), island_margin=margin,
                                 correct_aspect=False, scale_to_bounds=False)
        bpy.ops.object.mode_set(mode="OBJECT")
        obj.data.uv_layers.active_index = before
        obj.hide_set(hidden)

    def __exit__(self, *exc):
        layer = self.context.view_layer
        for o in layer.objects:
            o.select_set(o in self.selected)
        layer.objects.active = self.active
        if self.active is not None and self.mode != "OBJECT":
            bpy.ops.object.mode_set(mode=self.mode)
        return False
