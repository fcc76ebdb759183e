# The Blender add-on (blender/lightoctree_blender) in Blender, headless:
#   blender -b --factory-startup --python tests/blender/test_addon.py -- \
#       ADDON_PARENT SCENE.glb GRID.vdb OUT_DIR SIZE [MODULE_DIR]
# Imports the lightmapped glTF in "baked light only" mode and renders it with
# Cycles from the file's camera (OUT_DIR/blender-bake.png, sRGB, Standard view,
# no tone mapping), and imports the .vdb as a Volume (checks its grids, frame
# and material) and, with MODULE_DIR (where `import lightoctree` is built),
# with its VDL arrows (a point per voxel, cones by geometry nodes; checked on
# the evaluated mesh and drawn to OUT_DIR/blender-arrows.png).
# tests/blender/blender_addon.sh compares the picture with the
# project's own render. Prints "FAILED: ..." for what is wrong.
import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
addon_parent, glb, vdb, out, size = args[:5]
module_dir = args[5] if len(args) > 5 and args[5] else None
size = int(size)
sys.path.insert(0, addon_parent)
if module_dir:
    sys.path.insert(0, module_dir)
import lightoctree_blender  # noqa: E402

failures = []
bpy.ops.wm.read_factory_settings(use_empty=True)
lightoctree_blender.register()

result = bpy.ops.lightoctree.import_gltf(filepath=glb, mode="BAKE_ONLY")
if "FINISHED" not in result:
    failures.append(f"import_gltf returned {result}")
wired = [m.name for m in bpy.data.materials if m.get("lightoctree")]
print(f"lightmapped materials: {', '.join(sorted(wired))}")
if len(wired) < 4:
    failures.append(f"only {len(wired)} materials wired")

scene = bpy.context.scene
cameras = [o for o in bpy.data.objects if o.type == "CAMERA"]
if not cameras:
    failures.append("no camera imported")
else:
    scene.camera = cameras[0]
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 16
scene.cycles.use_denoising = False
scene.cycles.filter_width = 0.01  # a sample at each pixel centre, as the project's renderer
scene.cycles.max_bounces = 0  # emission seen by the camera alone
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.render.film_transparent = False
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0
scene.display_settings.display_device = "sRGB"
scene.world = bpy.data.worlds.new("black")
scene.world.color = (0.0, 0.0, 0.0)
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_depth = "8"
scene.render.filepath = os.path.join(out, "blender-bake.png")
bpy.ops.render.render(write_still=True)
print(f"wrote {scene.render.filepath}")

result = bpy.ops.lightoctree.import_vdb(filepath=vdb, arrows=bool(module_dir), max_arrows=1500)
volumes = [o for o in bpy.data.objects if o.type == "VOLUME"]
if "FINISHED" not in result or not volumes:
    failures.append(f"import_vdb returned {result}")
else:
    v = volumes[0]
    grids = [g.name for g in v.data.grids]
    print(f"volume {v.name}: grids {', '.join(grids[:6])}..., rotation {tuple(round(a, 4) for a in v.rotation_euler)}")
    if "irradiance" not in grids:
        failures.append("the volume has no irradiance grid")
    if abs(v.rotation_euler[0] - math.pi / 2) > 1e-6:
        failures.append("the volume is not turned from Y up to Z up")
    if not v.data.materials or v.data.materials[0].node_tree.nodes.get("Attribute") is None:
        failures.append("the volume has no irradiance material")

if module_dir:
    arrows = [o for o in bpy.data.objects if o.get("lightoctree") and o.type == "MESH"]
    if not arrows:
        failures.append("no VDL arrows object")
    else:
        a = arrows[0]
        points = len(a.data.vertices)
        evaluated = a.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        print(f"VDL arrows: {points} points ({a['lightoctree']['voxels']} voxels), "
              f"{len(evaluated.vertices)} vertices after geometry nodes, "
              f"attributes {sorted(k.name for k in evaluated.attributes if not k.name.startswith('.'))}")
        if points != min(1500, a["lightoctree"]["voxels"]) or len(evaluated.vertices) < 2 * points:
            failures.append("the arrows' geometry nodes made no cones")
        if "irradiance" not in evaluated.attributes:
            failures.append("the arrows lost their irradiance attribute")
        # A picture of the volume's arrows from the file's camera.
        for o in bpy.data.objects:
            if o.type == "MESH" and o is not a:
                o.hide_render = True
        scene.render.resolution_x = scene.render.resolution_y = 2 * size
        scene.render.filepath = os.path.join(out, "blender-arrows.png")
        bpy.ops.render.render(write_still=True)
        print(f"wrote {scene.render.filepath}")

for f in failures:
    print(f"FAILED: {f}")
print("blender add-on: ok" if not failures else f"blender add-on: {len(failures)} failure(s)")
sys.exit(1 if failures else 0)
