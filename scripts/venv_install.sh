#!/usr/bin/env bash
# Install Python packages into a virtualenv: scripts/venv_install.sh VENV PIP-ARGS...
#
# Uses uv (`uv pip install`, the version pinned in constraints.txt), which resolves the same
# pins as pip and installs the development environment in about a third of pip's time; uv
# is first installed into VENV with pip. INSTALLER=pip uses pip throughout (e.g. where
# packages come from an index that only pip is configured for: uv reads UV_* settings, not
# pip.conf), and pip is also the fallback when uv cannot be installed.
set -euo pipefail
venv=$1
shift
py="$venv/bin/python"
here="$(cd "$(dirname "$0")/.." && pwd)"

if [ "${INSTALLER:-uv}" != "pip" ] && [ ! -x "$venv/bin/uv" ]; then
  "$py" -m pip install -q --disable-pip-version-check -c "$here/constraints.txt" uv ||
    echo "[venv-install] uv could not be installed: using pip" >&2
fi
if [ "${INSTALLER:-uv}" != "pip" ] && [ -x "$venv/bin/uv" ]; then
  # Bytecode now, as pip does: uv skips it by default, and where PYTHONDONTWRITEBYTECODE is
  # set every process would compile the modules it imports from source again.
  exec "$venv/bin/uv" pip install -q --compile-bytecode --python "$py" "$@"
fi
"$py" -m pip install -q --disable-pip-version-check --upgrade pip
exec "$py" -m pip install -q --disable-pip-version-check "$@"
