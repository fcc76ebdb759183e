#!/usr/bin/env bash
# `pip install .` into a virtual environment (docs/python.md, "Install into
# any Python"): setup.py builds the module with CMake for the interpreter
# that runs pip, here reusing this build tree (LIGHTOCTREE_BUILD_DIR, made
# for the same Python), offline; the venv's `import lightoctree` is then the
# installed copy, of the project's version, and the Python tests pass with it.
# Usage: python_pip_install.sh SOURCE_DIR BUILD_DIR WORK_DIR PYTHON VERSION [CLI]
set -euo pipefail
src=$1 build=$2 work=$3 python=$4 version=$5 cli=${6:-}
rm -rf "$work" && mkdir -p "$work"
"$python" -m venv --system-site-packages "$work/venv"
LIGHTOCTREE_BUILD_DIR="$build" "$work/venv/bin/python" -m pip install --no-build-isolation \
  --no-deps --no-index --quiet "$src"
cd "$work"
"$work/venv/bin/python" - "$work/venv" "$version" <<'PY'
import os, sys
import lightoctree
venv, version = sys.argv[1], sys.argv[2]
where = os.path.realpath(lightoctree.__file__)
assert where.startswith(os.path.realpath(venv)), f"imported {where}, not the venv's copy"
assert lightoctree.__version__ == version, (lightoctree.__version__, version)
print(f"pip install: lightoctree {lightoctree.__version__} from {where}")
PY
"$work/venv/bin/python" -m pip show lightoctree | grep "^Version: $version$" >/dev/null
# The module's tests with the venv's copy (no PYTHONPATH: what the venv imports).
env -u PYTHONPATH LIGHTOCTREE_CLI="$cli" "$work/venv/bin/python" -m pytest -q -p no:cacheprovider \
  "$src/python/tests" | tail -n 3
echo "pip install: the venv's pip lists lightoctree $version"
