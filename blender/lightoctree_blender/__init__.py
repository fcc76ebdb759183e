# Light Octree for Blender (3.4 or later; Python only). The 3D viewport's
# sidebar, tab "Light Octree": a Bake panel that exports the scene, bakes it
# with the project's Python module (`import lightoctree`) in the background
# and lights the scene's own materials with the lightmaps (panel.py).
# File > Import >
#   "Light Octree bake (.vdb)": the grid as a Volume object in the scene's
#     frame (glTF's Y up turned to Blender's Z up) with a material that shows
#     the baked irradiance as emission, and optionally each voxel's strongest
#     VDL as an arrow (geometry nodes on a point per voxel);
#   "Lightmapped glTF (Light Octree)": Blender's glTF importer (with the
#     numpy fix Blender 3.4 on numpy 1.24 needs), then every material that
#     names a lightmap page in its extras gets the page wired in: the outgoing
#     radiance baseColor / pi * E added as emission, without losing the
#     material's own emission, alpha, metal or glass.
# docs/blender.md shows them; tests/blender/ runs them headless (test_addon.py
# the imports, test_bake_panel.py and test_light_units.py the Bake panel).

bl_info = {
    "name": "Light Octree",
    "author": "Light Octree",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Light Octree; File > Import",
    "description": "Bake the scene's light with Light Octree; import its bakes (.vdb) and "
                   "lightmapped glTF files",
    "category": "Lighting",
}

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import lightmap, panel, volume


class LIGHTOCTREE_OT_import_vdb(bpy.types.Operator, ImportHelper):
    """Import a Light Octree bake (.vdb) as a Volume showing its irradiance"""

    bl_idname = "lightoctree.import_vdb"
    bl_label = "Import Light Octree bake"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".vdb"
    filter_glob: StringProperty(default="*.vdb", options={"HIDDEN"})
    strength: FloatProperty(
        name="Emission strength",
        description="Scale of the irradiance shown as the volume's emission (W/m^2 per unit)",
        default=1.0, min=0.0)
    arrows: BoolProperty(
        name="VDL arrows",
        description="Also draw each voxel's strongest virtual directional light as an arrow "
                    "towards its light, coloured by its irradiance (needs the lightoctree Python "
                    "module)",
        default=False)
    max_arrows: IntProperty(
        name="Most arrows",
        description="Draw at most this many arrows, from voxels picked evenly through the grid",
        default=20000, min=1)

    def execute(self, context):
        try:
            obj = volume.import_bake(context, self.filepath, self.strength, self.arrows,
                                     self.max_arrows)
        except (OSError, RuntimeError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, f"imported {obj.name}: grids {', '.join(volume.grid_names(obj))}")
        return {"FINISHED"}


class LIGHTOCTREE_OT_import_gltf(bpy.types.Operator, ImportHelper):
    """Import a glTF written by `lightoctree lightmap`, its lightmap pages wired into the materials"""

    bl_idname = "lightoctree.import_gltf"
    bl_label = "Import lightmapped glTF"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".glb"
    filter_glob: StringProperty(default="*.glb;*.gltf", options={"HIDDEN"})
    mode: EnumProperty(
        name="Shading",
        items=[("ADD", "Add to the material",
                "The baked light added as emission to each material (EEVEE with its own indirect "
                "light off, or to see the bake beside Blender's lights)"),
               ("BAKE_ONLY", "Baked light only",
                "Each surface shows baseColor / pi * E and its own emission, nothing else: the "
                "bake as the project's renderer draws the indirect light")],
        default="ADD")

    def execute(self, context):
        try:
            wired = lightmap.import_lightmapped_gltf(context, self.filepath, self.mode)
        except (OSError, RuntimeError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, f"{wired} material(s) lit by their lightmap pages")
        return {"FINISHED"}


def menu_import(self, context):
    self.layout.operator(LIGHTOCTREE_OT_import_vdb.bl_idname, text="Light Octree bake (.vdb)")
    self.layout.operator(LIGHTOCTREE_OT_import_gltf.bl_idname,
                         text="Lightmapped glTF (Light Octree)")


classes = (LIGHTOCTREE_OT_import_vdb, LIGHTOCTREE_OT_import_gltf)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)
    panel.register()


def unregister():
    panel.unregister()
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
