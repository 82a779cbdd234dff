#!/usr/bin/env bash
# Prove that the ament_python packages build with colcon as on a robot, without ROS:
# every package installs its ament index marker and package.xml, and every console script
# lands in lib/<package>/ where `ros2 run` looks for it. swarm_interfaces (ament_cmake +
# rosidl) needs a ROS installation and is left out here.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-.venv}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$VENV/bin/colcon" --log-base "$work/log" build --base-paths . --packages-ignore swarm_interfaces \
  --build-base "$work/build" --install-base "$work/install" >"$work/colcon.out" 2>&1 \
  || { cat "$work/colcon.out"; exit 1; }

"$VENV/bin/python" - "$work/install" <<'PY'
"""Compare what colcon installed with each package's own declarations."""
import sys
from importlib.metadata import distribution
from pathlib import Path

install = Path(sys.argv[1])
problems = []
for package_xml in sorted(Path('.').glob('*/package.xml')) + sorted(Path('src').glob('*/package.xml')):
    package = package_xml.parent.name
    if not (package_xml.parent / 'setup.py').exists():
        continue
    prefix = install / package
    for required in (prefix / 'share/ament_index/resource_index/packages' / package,
                     prefix / 'share' / package / 'package.xml'):
        if not required.exists():
            problems.append(f'{package}: {required.relative_to(install)} was not installed')
    scripts = [ep.name for ep in distribution(package).entry_points if ep.group == 'console_scripts']
    missing = [name for name in scripts if not (prefix / 'lib' / package / name).exists()]
    problems += [f'{package}: console script {name} missing from lib/{package}' for name in missing]
    print(f'colcon: {package} built, {len(scripts)} console scripts in lib/{package}')
if problems:
    print('\n'.join(problems), file=sys.stderr)
    sys.exit(1)
PY
