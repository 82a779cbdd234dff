"""Lint of the workspace's ROS package metadata with the real ROS tools.

- every ``swarm_interfaces/msg/*.msg`` is parsed by rosidl_adapter (what ``colcon build``
  runs through rosidl), so a definition that would break the robot build fails here;
- every message package a definition refers to is declared in swarm_interfaces/package.xml
  and the referenced type exists in ROS 2 Jazzy (or in swarm_interfaces);
- every package.xml is valid for catkin_pkg, format 3, has a build type, and an
  ament_python package has its setup.py, setup.cfg and resource marker.

rosidl_adapter and catkin_pkg come from Debian's python3-rosidl and python3-catkin-pkg,
installed for the system interpreter (not the virtualenv), so the checks run in a subprocess
with it. The interpreter can be overridden with ``SWARM_LINT_PYTHON``.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

REPO_ROOT = Path(__file__).resolve().parent.parent
INTERFACES = REPO_ROOT / 'swarm_interfaces'
SYSTEM_PYTHON = os.environ.get('SWARM_LINT_PYTHON', '/usr/bin/python3')
INSTALL_HINT = (
    'install the ROS interface tools for the system Python: '
    'sudo apt install python3-rosidl python3-catkin-pkg (CI installs them)'
)
_SKIPPED_DIRS = {'.venv', 'build', 'install', 'log', 'node_modules', '.git'}

# Runs under the system interpreter: parse every .msg and every package.xml, print JSON.
_LINT_SCRIPT = r"""
import json, os, sys
request = json.loads(sys.argv[1])
try:
    from rosidl_adapter.parser import parse_message_file
    from catkin_pkg.package import parse_package
except ImportError as err:
    print(json.dumps({'missing': str(err)}))
    sys.exit(0)
result = {'messages': {}, 'packages': {}}
for path in request['msg_files']:
    entry = {'error': None, 'references': []}
    try:
        spec = parse_message_file(request['interfaces_package'], path)
        for field in spec.fields:
            if not field.type.is_primitive_type():
                entry['references'].append([field.type.pkg_name, field.type.type])
    except Exception as err:  # the parser's own exception types vary; report any of them
        entry['error'] = '%s: %s' % (type(err).__name__, err)
    result['messages'][path] = entry
for path in request['package_files']:
    entry = {'error': None}
    try:
        package = parse_package(path)
        package.validate()
        entry.update(
            name=package.name,
            format=package.package_format,
            build_type=package.get_build_type(),
            dependencies=sorted(
                {d.name for d in package.build_depends + package.exec_depends
                 + package.build_export_depends}
            ),
        )
    except Exception as err:  # catkin_pkg raises InvalidPackage and plain errors alike
        entry['error'] = '%s: %s' % (type(err).__name__, err)
    result['packages'][path] = entry
print(json.dumps(result))
"""


def _package_files() -> list[Path]:
    found = []
    for directory, subdirs, files in os.walk(REPO_ROOT):
        subdirs[:] = sorted(d for d in subdirs if d not in _SKIPPED_DIRS and not d.startswith('.'))
        if 'package.xml' in files:
            found.append(Path(directory) / 'package.xml')
    return sorted(found)


MSG_FILES = sorted((INTERFACES / 'msg').glob('*.msg'))
PACKAGE_FILES = _package_files()


@pytest.fixture(scope='module')
def lint() -> dict[str, Any]:
    """The system interpreter's verdict on every .msg and package.xml."""
    request = {
        'interfaces_package': 'swarm_interfaces',
        'msg_files': [str(p) for p in MSG_FILES],
        'package_files': [str(p) for p in PACKAGE_FILES],
    }
    try:
        completed = subprocess.run(
            [SYSTEM_PYTHON, '-c', _LINT_SCRIPT, json.dumps(request)],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
    except FileNotFoundError:
        pytest.fail(f'{SYSTEM_PYTHON} does not exist; {INSTALL_HINT}')
    if completed.returncode != 0:
        pytest.fail(f'the lint subprocess failed: {completed.stderr.strip()}')
    result = json.loads(completed.stdout)
    if 'missing' in result:
        pytest.fail(
            f'{SYSTEM_PYTHON} cannot import the ROS tools ({result["missing"]}); {INSTALL_HINT}'
        )
    return result


def test_workspace_has_interfaces_and_packages() -> None:
    assert MSG_FILES, f'no .msg files under {INTERFACES / "msg"}'
    assert INTERFACES / 'package.xml' in PACKAGE_FILES


@pytest.mark.parametrize('msg_file', MSG_FILES, ids=lambda p: p.name)
def test_message_definition_parses_with_rosidl(lint: dict[str, Any], msg_file: Path) -> None:
    error = lint['messages'][str(msg_file)]['error']
    assert error is None, f'{msg_file.relative_to(REPO_ROOT)}: {error}'


@pytest.mark.parametrize('msg_file', MSG_FILES, ids=lambda p: p.name)
def test_message_dependencies_are_declared_and_exist(lint: dict[str, Any], msg_file: Path) -> None:
    from swarm_runtime.messages.typestore import jazzy_typestore

    interfaces = lint['packages'][str(INTERFACES / 'package.xml')]
    declared = set(interfaces.get('dependencies', ()))
    jazzy = jazzy_typestore().fielddefs
    local = {p.stem for p in MSG_FILES}
    for package, name in lint['messages'][str(msg_file)]['references']:
        where = f'{msg_file.relative_to(REPO_ROOT)} uses {package}/{name}'
        if package == 'swarm_interfaces':
            assert name in local, f'{where}, which is not defined in swarm_interfaces/msg'
            continue
        assert package in declared, (
            f'{where}, but swarm_interfaces/package.xml does not depend on {package}'
        )
        assert f'{package}/msg/{name}' in jazzy, f'{where}, which ROS 2 Jazzy does not define'


@pytest.mark.parametrize(
    'package_file', PACKAGE_FILES, ids=lambda p: str(p.parent.relative_to(REPO_ROOT))
)
def test_package_manifest_is_valid(lint: dict[str, Any], package_file: Path) -> None:
    entry = lint['packages'][str(package_file)]
    where = package_file.relative_to(REPO_ROOT)
    assert entry['error'] is None, f'{where}: {entry["error"]}'
    assert entry['format'] == 3, f'{where}: package format {entry["format"]}, expected 3'
    assert entry['build_type'], f'{where}: no <export><build_type> given'
    assert entry['name'] == package_file.parent.name, (
        f'{where}: package name {entry["name"]!r} differs from its directory'
    )
    if entry['build_type'] == 'ament_python':
        package_dir = package_file.parent
        for needed in ('setup.py', 'setup.cfg', f'resource/{entry["name"]}'):
            assert (package_dir / needed).is_file(), f'{where}: ament_python package lacks {needed}'
