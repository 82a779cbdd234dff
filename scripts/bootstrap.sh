#!/usr/bin/env bash
# Prepare a development machine: Debian packages the tests need, then one virtualenv (.venv)
# with every ament_python package of the workspace installed editable from its own setup.py,
# all third-party versions taken from constraints.txt, then real ROS 2 Jazzy from its wheels
# where they exist (scripts/install_ros_wheels.sh).
#
# Safe to run repeatedly: it does nothing when the virtualenv is already up to date.
# Environment: PYTHON (interpreter for the virtualenv, default python3), VENV (default .venv),
# INSTALLER=pip to install with pip instead of uv (scripts/venv_install.sh).
set -euo pipefail

cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
VENV=${VENV:-.venv}
PACKAGES=(swarm_common src/swarm_runtime src/swarm_analysis oabug_robot bayes_swarm msc_pf hw_drivers swarm_sim sim_bridge swarm_experiments)
# Optional extras of the development install: the simulator's pybullet physics backend (its
# marker skips pybullet on Python >= 3.12, where it has no wheels; robot installs never get it).
declare -A EXTRAS=([swarm_sim]=pybullet)
# Debian packages: the real ROS message parser and package.xml tools used by the tests.
APT_PACKAGES=(python3-rosidl python3-catkin-pkg python3-ament-xmllint)

log() { printf '[bootstrap] %s\n' "$*"; }

install_debian_packages() {
  local missing=()
  for pkg in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if ! command -v apt-get >/dev/null; then
    log "missing Debian packages ${missing[*]} and no apt-get: the .msg lint tests will fail"
    return 0
  fi
  local sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  log "installing ${missing[*]}"
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
}

install_python_packages() {
  local stamp="$VENV/.bootstrap-stamp"
  local digest
  digest=$(cat constraints.txt requirements-dev.txt "${PACKAGES[@]/%//setup.py}" | sha256sum | cut -d' ' -f1)
  if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$digest" ]; then
    return 0
  fi
  [ -x "$VENV/bin/python" ] || { log "creating $VENV with $($PYTHON --version)"; "$PYTHON" -m venv "$VENV"; }
  log "installing Python packages (versions from constraints.txt)"
  local editable=()
  for pkg in "${PACKAGES[@]}"; do editable+=(-e "$pkg${EXTRAS[$pkg]:+[${EXTRAS[$pkg]}]}"); done
  scripts/venv_install.sh "$VENV" -c constraints.txt -r requirements-dev.txt "${editable[@]}"
  echo "$digest" > "$stamp"
}

install_debian_packages
install_python_packages
# Real ROS 2 Jazzy (rclpy and the generated interfaces) where wheels exist; else one line.
VENV="$VENV" scripts/install_ros_wheels.sh
log "ready: $VENV"
