"""Builds the `lightoctree` Python module with CMake for the interpreter that
runs pip (pyproject.toml says how to call it).

The module links the whole C++ library, so the first build of a fresh tree
takes minutes. It goes to build/pip-py<version>-<interpreter hash>/ in the source tree and
is reused by the next install; LIGHTOCTREE_BUILD_DIR names another tree (an
existing `cmake -B build` of this project made for the same interpreter is
reused as it is). The system packages the build needs are those of
`bash tools/setup.sh` (README.md).
"""

import hashlib
import os
import re
import shutil
import site as site_module
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Command, Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(LightOctree VERSION ([0-9][0-9.]*)", text)
    if not match:
        sys.exit("setup.py: no 'project(LightOctree VERSION x.y.z)' in CMakeLists.txt")
    return match.group(1)


def cached(build_dir, name):
    """A variable of build_dir's CMakeCache.txt, or None."""
    cache = build_dir / "CMakeCache.txt"
    if not cache.exists():
        return None
    for line in cache.read_text().splitlines():
        if line.startswith(name + ":"):
            return line.split("=", 1)[1]
    return None


def interpreter():
    """The interpreter behind sys.executable (a virtual environment's base)."""
    return os.path.realpath(getattr(sys, "_base_executable", None) or sys.executable)


class CMakeModule(Extension):
    def __init__(self):
        super().__init__("lightoctree", sources=[])


class BuildWithCMake(build_ext):
    def build_extension(self, ext):
        # One tree per interpreter: Debian's and a pyenv Python may share a version.
        version = f"{sys.version_info.major}.{sys.version_info.minor}"
        tag = hashlib.sha1(interpreter().encode()).hexdigest()[:8]
        build_dir = Path(os.environ.get("LIGHTOCTREE_BUILD_DIR") or
                         ROOT / "build" / f"pip-py{version}-{tag}")
        configured_for = cached(build_dir, "PYTHON_EXECUTABLE")
        if configured_for is None:
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            self.run_command_line(
                ["cmake", "-S", str(ROOT), "-B", str(build_dir), *generator,
                 "-DCMAKE_BUILD_TYPE=Release", f"-DLO_PYTHON={interpreter()}"])
        elif os.path.realpath(configured_for) != interpreter():
            sys.exit(f"setup.py: {build_dir} was configured for {configured_for}, not for "
                     f"{interpreter()}: remove it or set LIGHTOCTREE_BUILD_DIR to another folder")
        jobs = str(os.cpu_count() or 1)
        self.run_command_line(["cmake", "--build", str(build_dir), "--target", "lightoctree_python",
                               "--parallel", jobs])
        built = sorted((build_dir / "python").glob("lightoctree*.so"))
        if not built:
            sys.exit(f"setup.py: the build left no lightoctree*.so in {build_dir / 'python'}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)

    def run_command_line(self, command):
        print(" ".join(command), flush=True)
        subprocess.check_call(command)


class InstallModule(Command):
    """`python3 setup.py install_module [--user]`: builds the module and copies
    it into this interpreter's site-packages (or the user's), for a Python
    whose pip cannot build offline (pip needs the `wheel` package, which a
    pyenv Python without a package index lacks)."""

    description = "build the module and copy it into this interpreter's site-packages"
    user_options = [("user", None, "into the user's site-packages")]
    boolean_options = ["user"]

    def initialize_options(self):
        self.user = False

    def finalize_options(self):
        pass

    def run(self):
        self.run_command("build_ext")
        build = self.get_finalized_command("build_ext")
        built = Path(build.get_ext_fullpath("lightoctree"))
        site = Path(site_module.getusersitepackages() if self.user
                    else sysconfig.get_paths()["platlib"])
        site.mkdir(parents=True, exist_ok=True)
        for old in site.glob("lightoctree*.so"):
            old.unlink()
        shutil.copy2(built, site / built.name)
        print(f"installed {site / built.name}")


# setuptools' own files (its build folders, the egg-info) stay under the
# ignored build/ folder, out of the source tree.
(ROOT / "build" / "pip").mkdir(parents=True, exist_ok=True)
setup(
    version=project_version(),
    ext_modules=[CMakeModule()],
    cmdclass={"build_ext": BuildWithCMake, "install_module": InstallModule},
    options={"build": {"build_base": str(ROOT / "build" / "pip")},
             "egg_info": {"egg_base": str(ROOT / "build" / "pip")}},
    zip_safe=False,
)
