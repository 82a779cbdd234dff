"""Every Python package is a complete ament_python package that `ros2 run` can use.

These checks read the packages' own files (no ROS needed): what colcon installs is checked
end to end by scripts/colcon_check.sh in CI.
"""

from __future__ import annotations

import ast
import configparser
import importlib
import xml.etree.ElementTree as ET
from importlib.metadata import distribution
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
AMENT_PYTHON_PACKAGES = sorted(
    path.parent for path in [*REPO.glob('*/setup.py'), *REPO.glob('src/*/setup.py')]
)


def _ids(paths: list[Path]) -> list[str]:
    return [path.name for path in paths]


def _setup_call(package_dir: Path) -> ast.Call:
    tree = ast.parse((package_dir / 'setup.py').read_text())
    calls = [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'setup'
    ]
    assert len(calls) == 1, f'{package_dir.name}/setup.py must call setup() exactly once'
    return calls[0]


def test_workspace_has_the_documented_packages() -> None:
    names = {path.name for path in AMENT_PYTHON_PACKAGES}
    assert names == {
        'bayes_swarm',
        'hw_drivers',
        'msc_pf',
        'oabug_robot',
        'sim_bridge',
        'swarm_common',
        'swarm_experiments',
        'swarm_sim',
        'swarm_analysis',
        'swarm_runtime',
    }


@pytest.mark.parametrize('package_dir', AMENT_PYTHON_PACKAGES, ids=_ids(AMENT_PYTHON_PACKAGES))
def test_package_xml_declares_an_ament_python_package_of_the_directory_name(
    package_dir: Path,
) -> None:
    root = ET.parse(package_dir / 'package.xml').getroot()
    assert root.get('format') == '3'
    assert root.findtext('name') == package_dir.name
    assert root.findtext('export/build_type') == 'ament_python'
    assert (package_dir / 'resource' / package_dir.name).is_file()
    assert (package_dir / package_dir.name / '__init__.py').is_file()


@pytest.mark.parametrize('package_dir', AMENT_PYTHON_PACKAGES, ids=_ids(AMENT_PYTHON_PACKAGES))
def test_setup_cfg_puts_scripts_where_ros2_run_looks(package_dir: Path) -> None:
    config = configparser.ConfigParser()
    config.read(package_dir / 'setup.cfg')
    expected = f'$base/lib/{package_dir.name}'
    assert config.get('develop', 'script_dir') == expected
    assert config.get('install', 'install_scripts') == expected


@pytest.mark.parametrize('package_dir', AMENT_PYTHON_PACKAGES, ids=_ids(AMENT_PYTHON_PACKAGES))
def test_setup_py_installs_the_marker_and_package_xml(package_dir: Path) -> None:
    source = (package_dir / 'setup.py').read_text()
    call = _setup_call(package_dir)
    keywords = {keyword.arg for keyword in call.keywords}
    assert {'name', 'packages', 'data_files', 'entry_points', 'install_requires'} <= keywords
    assert 'share/ament_index/resource_index/packages' in source
    assert "'package.xml'" in source


@pytest.mark.parametrize('package_dir', AMENT_PYTHON_PACKAGES, ids=_ids(AMENT_PYTHON_PACKAGES))
def test_console_scripts_point_at_callables(package_dir: Path) -> None:
    entry_points = [
        entry
        for entry in distribution(package_dir.name).entry_points
        if entry.group == 'console_scripts'
    ]
    for entry in entry_points:
        module = importlib.import_module(entry.module)
        assert callable(getattr(module, entry.attr)), f'{entry.name} -> {entry.value}'


def test_third_party_versions_are_pinned_in_one_place() -> None:
    pinned = {
        line.split('==')[0].strip().lower()
        for line in (REPO / 'constraints.txt').read_text().splitlines()
        if '==' in line and not line.lstrip().startswith('#')
    }
    first_party = {path.name for path in AMENT_PYTHON_PACKAGES}
    for package_dir in AMENT_PYTHON_PACKAGES:
        call = _setup_call(package_dir)
        requires = next(k.value for k in call.keywords if k.arg == 'install_requires')
        names = {element.value.lower() for element in requires.elts}
        unpinned = names - pinned - first_party
        assert not unpinned, f'{package_dir.name} requires {unpinned} without a pin'
