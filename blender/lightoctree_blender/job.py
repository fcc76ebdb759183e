# The part of a bake from the panel that needs no Blender data, so that it
# can run on a worker thread while Blender stays usable: lightoctree.bake of
# the exported scene (its progress reported, cancelled at the next report),
# the .vdb written, lightoctree.lightmap into the scene's own lightmap UVs.
import os
import threading
import time


class Cancelled(Exception):
    """The user stopped the bake (Esc)."""


class BakeFiles:
    """Where a bake's files go: the exported scene, the .vdb, the lightmapped
    glTF (its pages beside it) and the sky image, in one folder."""

    def __init__(self, folder):
        self.folder = folder
        self.scene = os.path.join(folder, "scene.glb")
        self.vdb = os.path.join(folder, "bake.vdb")
        self.lightmap = os.path.join(folder, "lightmap.gltf")


class BakeJob:
    """lightoctree.bake then lightoctree.lightmap with `settings` (depth,
    target_error, representation, atlas) and the sky keywords `sky`. run()
    on any thread; task, fraction and seconds tell how it goes; afterwards
    error holds what failed, cancelled whether cancel() stopped it."""

    def __init__(self, lo, files, settings, sky):
        self.lo, self.files, self.settings, self.sky = lo, files, settings, sky
        self.task, self.fraction = "starting", 0.0
        self.seconds = {}
        self.grid = None  # {"voxels", "photons", "noise"} of the bake
        self.error = None
        self.cancelled = False
        self._stop = threading.Event()

    def cancel(self):
        self._stop.set()

    def run(self):
        try:
            self._timed("bake", self._bake)
            self._timed("lightmap", self._lightmap)
        except Cancelled:
            self.cancelled = True
        except Exception as e:  # the module's InputError, IoError, ...: shown to the user
            self.error = e

    def status(self):
        return f"{self.task} {100 * self.fraction:.0f}%"

    def _timed(self, stage, work):
        start = time.perf_counter()
        work()
        self.seconds[stage] = time.perf_counter() - start

    def _bake(self):
        s = self.settings
        grid = self.lo.bake(self.files.scene, depth=s["depth"], target_error=s["target_error"],
                            representation=s["representation"], progress=self._progress,
                            **self.sky)
        self._step("writing the .vdb")
        self.lo.write(self.files.vdb, grid)
        self.grid = {"voxels": grid.size, "photons": grid.stats["stored_photons"],
                     "noise": grid.stats["noise"]}

    def _lightmap(self):
        self._step("lightmap pages")
        self.lo.lightmap(self.files.scene, self.files.vdb, self.files.lightmap,
                         atlas=self.settings["atlas"], uv="texcoord1", image="exr", **self.sky)
        self._step("done")  # a cancel during the lightmap (which has no progress) counts here

    def _step(self, task):
        self._progress(task, 0, 1)

    def _progress(self, task, done, total):
        """The bake's progress callback: raising stops the bake."""
        self.task, self.fraction = task, done / total if total else 0.0
        if self._stop.is_set():
            raise Cancelled()
