#!/usr/bin/env bash
# The robot install on the robots' Python (3.12 on Ubuntu 24.04 / Jazzy): every package a
# robot runs, without the simulator (pybullet has no 3.12 wheels), and their unit tests.
# Uses PYTHON_ROBOT, else python3.12 from PATH or pyenv. Without a 3.12 interpreter it says so
# and fails under CI, where one is expected.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV_ROBOT:-.venv-robot}
ROBOT_PACKAGES=(swarm_common src/swarm_runtime oabug_robot bayes_swarm msc_pf hw_drivers)

find_python() {
  if [ -n "${PYTHON_ROBOT:-}" ]; then echo "$PYTHON_ROBOT"; return; fi
  if command -v python3.12 >/dev/null && python3.12 --version >/dev/null 2>&1; then
    command -v python3.12; return
  fi
  if command -v pyenv >/dev/null; then
    local version
    version=$(pyenv versions --bare 2>/dev/null | grep -E '^3\.12(\.|$)' | tail -n 1 || true)
    [ -n "$version" ] && { echo "$(pyenv root)/versions/$version/bin/python3.12"; return; }
  fi
}

python=$(find_python)
if [ -z "$python" ]; then
  echo "[robot-python] no Python 3.12 interpreter found (set PYTHON_ROBOT)" >&2
  [ "${CI:-}" = "true" ] && exit 1 || exit 0
fi
echo "[robot-python] $("$python" --version) in $VENV"
[ -x "$VENV/bin/python" ] || "$python" -m venv "$VENV"
editable=()
for pkg in "${ROBOT_PACKAGES[@]}"; do editable+=(-e "$pkg"); done
scripts/venv_install.sh "$VENV" -c constraints.txt pytest pytest-xdist hypothesis mcap mcap-ros2-support "${editable[@]}"
if "$VENV/bin/python" -c 'import pybullet' 2>/dev/null; then
  echo "[robot-python] pybullet must not be part of the robot install" >&2
  exit 1
fi
test_dirs=()
for pkg in "${ROBOT_PACKAGES[@]}"; do test_dirs+=("$pkg/test"); done
"$VENV/bin/python" -m pytest -q -n 2 -p no:cacheprovider "${test_dirs[@]}"
