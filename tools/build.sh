#!/usr/bin/env bash
# Installs the dependencies (tools/setup.sh), configures and builds everything
# into build/. Used by both README commands.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
# With the distributed bake on OpenMPI (docs/scale.md).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DLO_WITH_MPI=ON >/dev/null
cmake --build build --parallel "$(nproc)"
# `import lightoctree` from anywhere: the built module linked into Python's
# site folder (docs/python.md), where this user may write there.
module=$(ls build/python/lightoctree*.so 2>/dev/null | head -1 || true)
python=python3
[ -x /usr/bin/python3 ] && python=/usr/bin/python3  # Debian's, the one the module is built for
site=$($python -c 'import site; print(site.getsitepackages()[0])' 2>/dev/null || true)
if [ -n "$module" ] && [ -n "$site" ]; then
  if mkdir -p "$site" 2>/dev/null && [ -w "$site" ]; then
    ln -sf "$PWD/$module" "$site/$(basename "$module")"
  else
    echo "build: $site is not writable: PYTHONPATH=$PWD/build/python $python -c 'import lightoctree'"
  fi
fi
