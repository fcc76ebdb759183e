"""The Bake panel in Debian's Blender, headless (ctest blender.bake_panel):

  BLENDER_USER_SCRIPTS=OUT/scripts blender -b --factory-startup \
      --python tests/blender/test_bake_panel.py -- ADDON_ZIP MODULE_DIR LIGHTOCTREE OUT

1. Installs the zip as Edit > Preferences > Add-ons > Install... does
   (into BLENDER_USER_SCRIPTS), enables it, and checks the message the panel
   shows when `import lightoctree` fails (also for a folder holding a build
   for another Python); then names MODULE_DIR (build/python) in the add-on's
   preferences.
2. Builds a room in bpy (bake_room.py: walls, a window, two boxes, a sun
   through the window, a point lamp) and runs the panel's operator
   (lightoctree.bake, its synchronous path): lightmap UVs added and packed,
   the scene exported, baked (depth 6, the default target error), lightmapped
   and wired into the scene's own materials. The time beyond the export is
   printed (a figure for docs/blender.md, not a check: the machine is
   shared); the .vdb is shown as a volume with VDL arrows. A second
   bake reuses the UVs, rewires in place, exports no baked light as emission
   and replaces the volume; a linked duplicate (two objects, one mesh) is
   refused with a clear message.
3. The worker's progress and cancellation, as the panel drives them: every
   stage reports, and a cancel at the first report stops the bake with
   nothing written.
4. Renders the room with EEVEE and with Cycles (160 x 120) using the baked
   light, and `lightoctree render` of the exported glTF with the .vdb; the
   mean brightness of each Blender picture is held within 3% of ours
   (`lightoctree compare --bin 4`, whose binned relative RMSE is printed).
Pictures (PNG) stay in OUT. Prints "FAILED: ..." for what is wrong.
"""
import json
import os
import shutil
import subprocess
import sys
import threading

import bpy
import numpy as np

args = sys.argv[sys.argv.index("--") + 1:]
zip_path, module_dir, cli, out = args[:4]
os.makedirs(out, exist_ok=True)
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_room  # noqa: E402

SIZE = (160, 120)
MEAN_TOLERANCE = 0.03
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
    return ok


def install_addon():
    """The zip through Blender's own Install and Enable operators."""
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    bpy.ops.preferences.addon_enable(module="lightoctree_blender")
    addons = bpy.context.preferences.addons
    check("lightoctree_blender" in addons, "the add-on is not enabled after Install")
    check(hasattr(bpy.types, "LIGHTOCTREE_PT_bake"), "the Bake panel is not registered")
    installed = bpy.utils.user_resource("SCRIPTS", path="addons")
    check(os.path.isfile(os.path.join(installed, "lightoctree_blender", "panel.py")),
          f"the zip was not installed into {installed}")


class _NoModule:
    """A finder that refuses `import lightoctree`, as a Python without it would."""

    def find_spec(self, name, path=None, target=None):
        if name == "lightoctree":
            raise ImportError("No module named 'lightoctree'")
        return None


def check_module_message():
    """Without the module the panel says what to do; with the preferences'
    folder it loads."""
    from lightoctree_blender import module
    blocker = _NoModule()
    sys.meta_path.insert(0, blocker)
    saved = sys.modules.pop("lightoctree", None)
    other = os.path.join(out, "module-for-python-3.9")  # a build for another Python
    os.makedirs(other, exist_ok=True)
    open(os.path.join(other, "lightoctree.cpython-39-x86_64-linux-gnu.so"), "w").close()
    try:
        message = module.problem(os.path.join(out, "no-module-here"))
        wrong = module.problem(other)
    finally:
        sys.meta_path.remove(blocker)
        if saved is not None:
            sys.modules["lightoctree"] = saved
    print(f"panel message without the module: {message}")
    check(message is not None and "import lightoctree failed" in message and "docs/python.md" in message
          and "preferences" in message, f"unclear message without the module: {message}")
    check(wrong is not None and "lightoctree.cpython-39-x86_64-linux-gnu.so is built for another Python" in wrong,
          f"a module for another Python is not named as such: {wrong}")
    prefs = bpy.context.preferences.addons["lightoctree_blender"].preferences
    prefs.module_folder = module_dir
    check(module.problem(module_dir) is None, f"the module does not load from {module_dir}")
    return module.load(module_dir)


def bake(scene):
    result = bpy.ops.lightoctree.bake()
    check("FINISHED" in result, f"the bake operator returned {result}")
    last = scene.get("lightoctree_last")
    return last.to_dict() if last is not None else None


def wiring(materials):
    """{material: number of Light Octree nodes} and whether each shows them."""
    from lightoctree_blender import lightmap
    nodes = {m.name: sum(n.name.startswith(lightmap.PREFIX) for n in m.node_tree.nodes) for m in materials}
    active = all(next(n for n in m.node_tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output)
                 .name.startswith(lightmap.PREFIX) for m in materials)
    return nodes, active


def _gltf_json(path):
    """The JSON chunk of a .glb."""
    with open(path, "rb") as f:
        data = f.read()
    return data[20:20 + int.from_bytes(data[12:16], "little")]


def lightmap_uvs(objects):
    out_uvs = {}
    for obj in objects:
        layer = obj.data.uv_layers[1]
        uv = np.empty(2 * len(obj.data.loops), np.float32)
        layer.data.foreach_get("uv", uv)
        out_uvs[obj.name] = (layer.name, uv)
    return out_uvs


def check_progress_and_cancel(lo, folder):
    """The worker as the panel runs it on its thread: reports from every stage;
    a cancel at the first report stops the bake and writes nothing."""
    from lightoctree_blender import job
    settings = {"depth": 6, "target_error": 0.07, "representation": "vdl", "atlas": 256}
    for name, cancel in (("progress", False), ("cancel", True)):
        files = job.BakeFiles(os.path.join(out, name))
        os.makedirs(files.folder, exist_ok=True)
        shutil.copy(os.path.join(folder, "scene.glb"), files.scene)
        work = job.BakeJob(lo, files, settings, {"sky": (0.0, 0.0, 0.0)})
        reports = []
        report = work._progress

        def spy(task, done, total, work=work, cancel=cancel):
            reports.append((task, done, total))
            if cancel and done > 0:
                work.cancel()
            report(task, done, total)
        work._progress = spy
        thread = threading.Thread(target=work.run)
        thread.start()
        thread.join(timeout=120)
        tasks = list(dict.fromkeys(t for t, _, _ in reports))
        print(f"worker, {name}: {len(reports)} reports, stages {tasks}, cancelled {work.cancelled}, "
              f"error {work.error}")
        check(not thread.is_alive(), f"{name}: the worker did not end")
        if cancel:
            check(work.cancelled and work.error is None and not os.path.exists(files.vdb),
                  "a cancel at the first report did not stop the bake before its .vdb")
        else:
            check(not work.cancelled and work.error is None and os.path.isfile(files.lightmap),
                  f"the worker failed: {work.error}")
            check(len(tasks) >= 3 and tasks[-1] == "done", f"too few stages reported: {tasks}")


def render(scene, engine, path):
    scene.render.engine = engine
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = path + ".exr"
    bpy.ops.render.render(write_still=True)
    settings = scene.render.image_settings
    settings.file_format, settings.color_mode, settings.color_depth, settings.compression = "PNG", "RGB", "8", 100
    bpy.data.images["Render Result"].save_render(path + ".png", scene=scene)


def compare(test, ours, name):
    report = os.path.splitext(test)[0] + "-compare.json"
    subprocess.run([cli, "compare", test, ours, "--bin", "4", "--json", report], check=True,
                   stdout=subprocess.DEVNULL)
    with open(report) as f:
        c = json.load(f)
    ratio = c["mean_test_luminance"] / c["mean_reference_luminance"]
    rmse = c["channels"]["Y"]["rel_rmse"]
    print(f"{name} / lightoctree render: mean brightness {ratio:.4f} (target {1 - MEAN_TOLERANCE:.2f}-"
          f"{1 + MEAN_TOLERANCE:.2f}), 4x4-binned relative RMSE {rmse:.4f}")
    check(abs(ratio - 1) <= MEAN_TOLERANCE, f"{name}: mean brightness {ratio:.4f} of ours")


def build_and_bake():
    """The room, baked from the panel's operator; checks the first bake.
    Returns the scene, its meshes and materials, their UVs and wiring."""
    from lightoctree_blender import uv
    from lightoctree_blender.panel import beyond_export
    bpy.ops.wm.read_homefile(use_empty=True)  # the add-on stays enabled
    scene = bpy.context.scene
    bake_room.build_room(bpy.context)
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    settings = scene.lightoctree
    settings.depth, settings.atlas = 6, 256
    settings.folder = os.path.join(out, "bake") + os.sep
    settings.volume = settings.arrows = True
    first = bake(scene)
    if check(first is not None, "the bake recorded no figures"):
        s = first["seconds"]
        beyond = beyond_export(s)
        print(f"bake from the panel: {first['voxels']:,} voxels; {beyond:.2f} s beyond the export "
              f"(UVs {s['uvs']:.2f}, bake {s['bake']:.2f}, lightmap {s['lightmap']:.2f}, apply "
              f"{s['apply']:.2f}); export {s['export']:.2f} s")
    meshes = [o for o in scene.objects if o.type == "MESH" and not o.get("lightoctree")]  # not the arrows
    materials = sorted({m for o in meshes for m in o.data.materials}, key=lambda m: m.name)
    nodes, active = wiring(materials)
    print(f"wired materials: {nodes}")
    check(len(materials) == 5 and all(nodes.values()) and active, "not every material shows the baked light")
    uvs = lightmap_uvs(meshes)
    check(not uv.needs_packing(meshes, settings.atlas), "the packed UVs do not count as packed")
    check(all(name == "LightOctree" for name, _ in uvs.values()), "a mesh's second UV map is not LightOctree")
    check(all(0.0 <= t.min() and t.max() <= 1.0 for _, t in uvs.values()), "lightmap UVs outside [0, 1]")
    return scene, meshes, materials, uvs, nodes


def check_rebake(scene, meshes, materials, uvs, nodes):
    """A re-bake: the UVs as they are, no baked light exported as emission,
    the wiring and the volume replaced, not added to."""
    bake(scene)
    exported = json.loads(_gltf_json(os.path.join(scene.lightoctree.folder, "scene.glb")))
    check(not any("emissiveFactor" in m for m in exported["materials"]),
          "the re-bake exported the first bake's light as the materials' emission")
    again = lightmap_uvs(meshes)
    check(all(np.array_equal(uvs[k][1], again[k][1]) for k in uvs), "a re-bake packed the UVs again")
    check(wiring(materials)[0] == nodes, "a re-bake left the first wiring's nodes behind")
    shown = [o for o in scene.objects if o.get("lightoctree")]
    print(f"the bake shown: {sorted((o.name, o.type) for o in shown)}")
    check(sorted(o.type for o in shown) == ["MESH", "VOLUME"],
          "a re-bake did not replace the last bake's volume and VDL arrows")
    for obj in shown:
        obj.hide_render = True  # the pictures compare the surfaces' light


def check_refusal(scene):
    """Two objects sharing a mesh (a linked duplicate) are refused by name."""
    twin = bpy.data.objects.new("red box twin", bpy.data.objects["red box"].data)
    scene.collection.objects.link(twin)
    try:
        bpy.ops.lightoctree.bake()
        check(False, "a bake of two objects sharing a mesh was not refused")
    except RuntimeError as e:  # the operator's error report, raised in a script
        print(f"refused: {e}")
        check("share the mesh 'red box'" in str(e), f"unclear refusal: {e}")
    bpy.data.objects.remove(twin)


def compare_renders(scene):
    """EEVEE and Cycles pictures of the room against `lightoctree render` of
    the exported scene and its .vdb."""
    scene.cycles.samples = 64
    scene.cycles.use_denoising = False
    scene.eevee.taa_render_samples = 16
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    folder = scene.lightoctree.folder
    ours = os.path.join(out, "ours")
    for suffix, extra in ((".exr", []), (".png", ["--exposure", "0", "--tone-map", "clamp"])):
        subprocess.run([cli, "render", os.path.join(folder, "scene.glb"), os.path.join(folder, "bake.vdb"),
                        "--width", str(SIZE[0]), "--height", str(SIZE[1]), "-o", ours + suffix, "--quiet"]
                       + extra, check=True)
    for engine, name in (("BLENDER_EEVEE", "EEVEE"), ("CYCLES", "Cycles")):
        picture = os.path.join(out, f"blender-{name.lower()}")
        render(scene, engine, picture)
        compare(picture + ".exr", ours + ".exr", f"Blender 3.4 {name}")


install_addon()
lo = check_module_message()
scene, meshes, materials, uvs, nodes = build_and_bake()
check_rebake(scene, meshes, materials, uvs, nodes)
check_refusal(scene)
check_progress_and_cancel(lo, scene.lightoctree.folder)
compare_renders(scene)
for f in failures:
    print(f"FAILED: {f}")
print("blender bake panel: ok" if not failures else f"blender bake panel: {len(failures)} failure(s)")
sys.exit(1 if failures else 0)
