# The Bake panel (3D viewport sidebar, tab "Light Octree") and its
# operator: lightmap UVs where missing, the scene exported by Blender's glTF
# exporter, baked and lightmapped by the project's Python module on a worker
# thread (progress in the status bar, Esc cancels), and the pages wired into
# the scene's own materials. In a script or `blender -b` the operator runs
# the same steps in the calling thread (execute); docs/blender.md.
import os
import tempfile
import textwrap
import threading
import time

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import export, job, lightmap, module, renders, uv, volume

_ADDON = __package__
_session_folder = None  # the bake's files while the .blend is not saved


class LightOctreeSettings(bpy.types.PropertyGroup):
    """The panel's settings, kept with the scene."""

    depth: IntProperty(
        name="Depth", default=6, min=1, max=12,
        description="Octree depth: 2^depth voxels across the scene's bounding cube")
    target_error: FloatProperty(
        name="Target error", default=0.07, min=0.001, max=1.0, precision=3,
        description="Photons are traced until the bake's noise figure (the relative standard "
                    "error of the light over 90% of the lit area) is at most this")
    representation: EnumProperty(
        name="Store", default="vdl",
        items=[("vdl", "VDLs", "Virtual directional lights per voxel (the paper's)"),
               ("sh1", "SH order 1", "Irradiance as spherical harmonics, 4 terms"),
               ("sh2", "SH order 2", "Irradiance as spherical harmonics, 9 terms")],
        description="How each voxel stores its light")
    atlas: IntProperty(
        name="Lightmap", default=1024, min=64, max=8192,
        description="Texels across the one lightmap page every baked mesh shares (its size)")
    shading: EnumProperty(
        name="Shading", default="ADD",
        items=[("ADD", "Add to the material",
                "The baked indirect light added to each material: Blender's lights give the "
                "direct light (EEVEE, or Cycles without diffuse bounces)"),
               ("BAKE_ONLY", "Baked light only",
                "Each surface shows baseColor / pi * E and its own emission, nothing else")])
    folder: StringProperty(
        name="Folder", default="//lightoctree/", subtype="DIR_PATH",
        description="Where the exported scene, the .vdb and the lightmap pages go (// is beside "
                    "the .blend; a temporary folder while it is not saved)")
    volume: BoolProperty(
        name="Volume", default=False,
        description="Also show the .vdb as a Volume object (replacing the last bake's)")
    arrows: BoolProperty(
        name="VDL arrows", default=False,
        description="With the volume, each voxel's strongest VDL as an arrow towards its light")
    setup_renders: BoolProperty(
        name="Set up renders", default=True,
        description="Cycles without diffuse bounces and the World seen by the camera only, so "
                    "that nothing is lit twice (the bake holds the indirect and the sky's light)")


class LightOctreePreferences(bpy.types.AddonPreferences):
    bl_idname = _ADDON

    module_folder: StringProperty(
        name="Module folder", subtype="DIR_PATH",
        description="Where the lightoctree Python module is built (build/python), when "
                    "Blender's Python does not find it on its own path")

    def draw(self, context):
        self.layout.prop(self, "module_folder")
        _draw_problem(self.layout, module.problem(module_folder(context)))


def module_folder(context):
    """The module folder named in the add-on's preferences ('' when none)."""
    addon = context.preferences.addons.get(_ADDON)
    return bpy.path.abspath(addon.preferences.module_folder) if addon else ""


class LIGHTOCTREE_OT_bake(bpy.types.Operator):
    """Bake the scene's light with Light Octree and light its materials with the lightmaps"""

    bl_idname = "lightoctree.bake"
    bl_label = "Bake Light Octree"
    bl_options = {"REGISTER", "UNDO"}  # one undo step takes the UVs and the wiring back

    running = None  # the BakeJob under way: one at a time

    @classmethod
    def poll(cls, context):
        return cls.running is None and context.scene is not None

    def execute(self, context):
        """The whole bake in this thread (scripts, `blender -b`)."""
        work = self._prepare(context)
        if work is None:
            return {"CANCELLED"}
        work.run()
        return self._finish(context, work)

    def invoke(self, context, event):
        """The bake on a worker thread, Blender usable meanwhile."""
        work = self._prepare(context)
        if work is None:
            return {"CANCELLED"}
        type(self).running = work
        self._thread = threading.Thread(target=work.run, name="Light Octree bake", daemon=True)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.2, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, 100)
        self._thread.start()
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        work = type(self).running
        if event.type == "ESC" and event.value == "PRESS":
            work.cancel()
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        if self._thread.is_alive():
            context.window_manager.progress_update(int(100 * work.fraction))
            context.workspace.status_text_set(f"Light Octree: {work.status()} (Esc cancels)")
            _redraw_sidebars(context)
            return {"PASS_THROUGH"}
        self._stop_watching(context)
        return self._finish(context, work)

    def cancel(self, context):
        """Blender ends the operator (a file loaded, Blender closing): the bake
        stops at its next report; waits for it a few seconds at most."""
        work = type(self).running
        if work is not None:
            work.cancel()
            self._thread.join(timeout=5.0)
        self._stop_watching(context)

    def _stop_watching(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        type(self).running = None
        _redraw_sidebars(context)

    def _prepare(self, context):
        """The steps that need Blender's data: the module, the lightmap UVs,
        the sky and the export. A BakeJob for the rest, or None after
        reporting why not."""
        settings = context.scene.lightoctree
        try:
            lo = module.load(module_folder(context))
            objects, lit = _objects(context)
            files = job.BakeFiles(self._folder(settings))
            start = time.perf_counter()
            if uv.needs_packing(lit, settings.atlas):
                uv.pack(context, lit, settings.atlas)
            packed = time.perf_counter()
            sky, warnings = export.sky_settings(context.scene.world, files.folder)
            warnings += export.export_scene(context, files.scene, objects)
            exported = time.perf_counter()
        except (OSError, RuntimeError, ValueError) as e:  # ModuleMissing is a RuntimeError
            self.report({"ERROR"}, f"Light Octree: {e}")
            return None
        for warning in warnings:
            self.report({"WARNING"}, f"Light Octree: {warning}")
        self._materials = sorted(m.name for m in export.materials_of(objects))
        work = job.BakeJob(lo, files, {"depth": settings.depth, "target_error": settings.target_error,
                                       "representation": settings.representation,
                                       "atlas": settings.atlas}, sky)
        work.seconds.update(uvs=packed - start, export=exported - packed)
        return work

    def _folder(self, settings):
        """The settings' folder, made; a temporary one (for the session) when
        it is relative to a .blend not yet saved."""
        global _session_folder
        folder = settings.folder
        if folder.startswith("//") and not bpy.data.filepath:
            if _session_folder is None:
                _session_folder = tempfile.mkdtemp(prefix="lightoctree-")
            self.report({"INFO"}, f"Light Octree: the .blend is not saved: the bake's files go "
                                  f"to {_session_folder} (gone after a restart)")
            folder = _session_folder
        folder = bpy.path.abspath(folder)
        os.makedirs(folder, exist_ok=True)
        return folder

    def _finish(self, context, work):
        """The result applied to the scene, in place; the report."""
        if work.cancelled:
            self.report({"WARNING"}, "Light Octree: bake cancelled; the materials are as they were")
            return {"CANCELLED"}
        if work.error is not None:
            self.report({"ERROR"}, f"Light Octree: {work.error}")
            return {"CANCELLED"}
        settings = context.scene.lightoctree
        start = time.perf_counter()
        try:
            materials = [bpy.data.materials[n] for n in self._materials if n in bpy.data.materials]
            wired = lightmap.apply_lightmaps(materials, work.files.lightmap, settings.shading,
                                             uv.LIGHTMAP_UV)
            changed = renders.setup(context.scene) if settings.setup_renders else []
            if settings.volume:
                volume.replace_bake(context, work.files.vdb, settings.arrows)
        except (OSError, RuntimeError, ValueError) as e:
            self.report({"ERROR"}, f"Light Octree: {e}")
            return {"CANCELLED"}
        work.seconds["apply"] = time.perf_counter() - start
        summary = _summary(work, wired, changed)
        context.scene["lightoctree_last"] = {"summary": summary, "folder": work.files.folder,
                                             "seconds": work.seconds, "materials": wired, **work.grid}
        self.report({"INFO"}, summary)
        print(summary)
        return {"FINISHED"}


def _objects(context):
    """The meshes to export and, of those, the ones to lightmap (a region
    marker is no surface). @raises ValueError when there are none or they
    cannot share one lightmap atlas (uv.problems)."""
    objects = export.baked_objects(context)
    if not objects:
        raise ValueError("nothing to bake: no mesh with faces is shown and enabled for renders")
    lit = [o for o in objects if not o.get("lightoctree_region")]
    problems = uv.problems(lit)
    if problems:
        more = f" (and {len(problems) - 2} more)" if len(problems) > 2 else ""
        raise ValueError("; ".join(problems[:2]) + more)
    return objects, lit


def beyond_export(seconds):
    """The seconds of a bake's steps after the export (the panel's figure of
    merit: the export is Blender's glTF exporter's time)."""
    return seconds["uvs"] + seconds["bake"] + seconds["lightmap"] + seconds["apply"]


def _summary(work, wired, changed):
    """The report of a bake: what it made, how long each step took, what it set."""
    s = work.seconds
    text = (f"Light Octree: {work.grid['voxels']:,} voxels, {work.grid['photons']:,} photons, "
            f"{wired} material(s) lit; {beyond_export(s):.1f} s beyond the export (UVs {s['uvs']:.1f}, bake "
            f"{s['bake']:.1f}, lightmap {s['lightmap']:.1f}, apply {s['apply']:.1f}), export "
            f"{s['export']:.1f} s")
    return text + (f"; set: {', '.join(changed)}" if changed else "")


def _redraw_sidebars(context):
    """The panel shows the bake's progress: draw it again."""
    for area in context.screen.areas if context.screen else []:
        if area.type == "VIEW_3D":
            area.tag_redraw()


def _draw_problem(layout, problem):
    """The module's problem (module.problem), if any, in red, wrapped for the sidebar."""
    if problem:
        box = layout.box()
        box.alert = True
        for i, line in enumerate(textwrap.wrap(problem, 36)):
            box.label(text=line, icon="ERROR" if i == 0 else "BLANK1")


class LIGHTOCTREE_PT_bake(bpy.types.Panel):
    """The Bake panel: the settings, Bake / Re-bake, the progress, the last bake's figures."""

    bl_label = "Light Octree"
    bl_idname = "LIGHTOCTREE_PT_bake"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Light Octree"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.lightoctree
        _draw_problem(layout, module.problem(module_folder(context)))
        col = layout.column()
        for name in ("depth", "target_error", "representation", "atlas", "shading", "folder"):
            col.prop(settings, name)
        col = layout.column(heading="Show")
        col.prop(settings, "volume")
        sub = col.column()
        sub.enabled = settings.volume
        sub.prop(settings, "arrows")
        layout.column(heading="Set up").prop(settings, "setup_renders", text="EEVEE, Cycles")
        work = LIGHTOCTREE_OT_bake.running
        if work is not None:
            layout.label(text=work.status(), icon="TIME")
            layout.label(text="Esc cancels")
            return
        last = context.scene.get("lightoctree_last")
        row = layout.row()
        row.scale_y = 1.5
        row.operator(LIGHTOCTREE_OT_bake.bl_idname, text="Re-bake" if last else "Bake", icon="LIGHT")
        if last:
            seconds = last["seconds"]
            layout.label(text=f"{last['voxels']:,} voxels, {last['materials']} materials lit")
            layout.label(text=f"{beyond_export(seconds):.1f} s + export {seconds['export']:.1f} s")


classes = (LightOctreeSettings, LightOctreePreferences, LIGHTOCTREE_OT_bake, LIGHTOCTREE_PT_bake)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.lightoctree = PointerProperty(type=LightOctreeSettings)


def unregister():
    if LIGHTOCTREE_OT_bake.running is not None:
        LIGHTOCTREE_OT_bake.running.cancel()
    del bpy.types.Scene.lightoctree
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
