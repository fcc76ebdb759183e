# Finding the project's Python module (`import lightoctree`, docs/python.md)
# from inside Blender, whose Python may not be the one the module was built
# for: the interpreter's own path first (Debian's Blender runs the system
# python3, where tools/build.sh links the module), then the folder named in
# the add-on's preferences, then a copy bundled beside the add-on.
import glob
import importlib.machinery
import importlib.util
import os
import sys


class ModuleMissing(RuntimeError):
    """`import lightoctree` failed; the message says what was tried and what to do."""


_problems = {}  # folder -> the message of the last failed load (the panel redraws often)


def load(folder=""):
    """The lightoctree module. `folder`: where the add-on's preferences say it
    is built (build/python); tried when the interpreter's path lacks it.
    @raises ModuleMissing naming each place tried and its error."""
    _problems.pop(folder, None)
    if "lightoctree" in sys.modules:
        return sys.modules["lightoctree"]
    tried = []
    try:
        import lightoctree
        return lightoctree
    except ImportError as e:
        tried.append(f"Python's path: {e}")
    for place in ([folder] if folder else []) + [os.path.dirname(os.path.abspath(__file__))]:
        found = _load_from(place, tried)
        if found is not None:
            return found
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    raise ModuleMissing(
        f"import lightoctree failed in Blender's Python {version} ({'; '.join(tried)}). "
        f"Build the module for this Python and put it on its path (docs/python.md: Debian's "
        f"Blender runs the system python3, where tools/build.sh links it), or name its folder "
        f"(build/python) in the add-on's preferences")


def problem(folder=""):
    """None when the module loads, else ModuleMissing's message (for the
    panel, which asks at every redraw: a failure is remembered until load()
    is called again, as the Bake button and the preferences' folder do)."""
    if folder in _problems:
        return _problems[folder]
    try:
        load(folder)
        return None
    except ModuleMissing as e:
        _problems[folder] = str(e)
        return str(e)


def _load_from(folder, tried):
    """The module from `folder` (a lightoctree.cpython-*.so built for this
    Python), or None with the reason appended to `tried`."""
    suffixes = importlib.machinery.EXTENSION_SUFFIXES
    candidates = [p for s in suffixes for p in glob.glob(os.path.join(glob.escape(folder), "lightoctree" + s))]
    if not candidates:
        others = glob.glob(os.path.join(glob.escape(folder), "lightoctree*.so"))
        tried.append(f"{folder}: " + (f"{os.path.basename(others[0])} is built for another Python"
                                      if others else "no lightoctree module"))
        return None
    spec = importlib.util.spec_from_file_location("lightoctree", candidates[0])
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except ImportError as e:
        tried.append(f"{candidates[0]}: {e}")
        return None
    sys.modules["lightoctree"] = module
    return module
