"""The rule of the layers, read from the imports: each package imports only the layers below it.

Every module of every package is parsed (``ast``, nothing is imported) and its absolute
imports, including those inside functions, are checked against the layer table:

| package | may import of the project |
|---|---|
| swarm_common | nothing |
| swarm_runtime | swarm_common |
| algorithm cores | swarm_common; no ROS, no swarm_runtime (their node.py / conversions.py may) |
| hw_drivers, swarm_analysis | swarm_common, swarm_runtime |
| swarm_sim | swarm_common; no ROS |
| sim_bridge | swarm_common, swarm_runtime, swarm_sim; no algorithm |
| swarm_experiments | all of the above |

Nothing but swarm_experiments itself (and the scripts in benchmarks/, which are not a
package) imports swarm_experiments. Each package's package.xml also declares every project
package it imports. The test folders that ``make test-rclpy`` leaves out (``ROS_FREE_TESTS``
in the Makefile) reach no ROS module through any chain of project imports.
"""

from __future__ import annotations

import ast
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import pytest

pytestmark = pytest.mark.runtime_independent(reason='reads source files')

REPO = Path(__file__).resolve().parents[1]

PACKAGE_DIRS = {
    'swarm_common': REPO / 'swarm_common',
    'swarm_runtime': REPO / 'src' / 'swarm_runtime',
    'swarm_analysis': REPO / 'src' / 'swarm_analysis',
    'oabug_robot': REPO / 'oabug_robot',
    'bayes_swarm': REPO / 'bayes_swarm',
    'msc_pf': REPO / 'msc_pf',
    'hw_drivers': REPO / 'hw_drivers',
    'swarm_sim': REPO / 'swarm_sim',
    'sim_bridge': REPO / 'sim_bridge',
    'swarm_experiments': REPO / 'swarm_experiments',
}
ALGORITHMS = frozenset({'oabug_robot', 'bayes_swarm', 'msc_pf'})
# The modules of an algorithm package that translate messages; everything else is the core.
ALGORITHM_ROS_MODULES = frozenset({'node.py', 'conversions.py'})
# Top-level modules that are ROS: rclpy, the message packages, the project's ROS indirection.
ROS_MODULES = frozenset(
    {
        'rclpy',
        'builtin_interfaces',
        'diagnostic_msgs',
        'geometry_msgs',
        'nav_msgs',
        'rcl_interfaces',
        'rosgraph_msgs',
        'sensor_msgs',
        'std_msgs',
        'swarm_interfaces',
        'swarm_runtime',
    }
)
ALLOWED = {
    'swarm_common': frozenset(),
    'swarm_runtime': frozenset({'swarm_common'}),
    'swarm_analysis': frozenset({'swarm_common', 'swarm_runtime'}),
    'oabug_robot': frozenset({'swarm_common', 'swarm_runtime'}),
    'bayes_swarm': frozenset({'swarm_common', 'swarm_runtime'}),
    'msc_pf': frozenset({'swarm_common', 'swarm_runtime'}),
    'hw_drivers': frozenset({'swarm_common', 'swarm_runtime'}),
    'swarm_sim': frozenset({'swarm_common'}),
    'sim_bridge': frozenset({'swarm_common', 'swarm_runtime', 'swarm_sim'}),
    'swarm_experiments': frozenset(PACKAGE_DIRS) - {'hw_drivers', 'swarm_experiments'},
}


def _modules(package: str) -> list[Path]:
    return sorted((PACKAGE_DIRS[package] / package).rglob('*.py'))


def _import_statements(path: Path) -> Iterator[tuple[int, str, tuple[str, ...]]]:
    """(level, module, imported names) of every import in ``path``, at any depth; level 0 is
    an absolute import, and ``import a.b`` gives (0, 'a.b', ())."""
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield 0, alias.name, ()
        elif isinstance(node, ast.ImportFrom):
            yield node.level, node.module or '', tuple(alias.name for alias in node.names)


def _imports(path: Path) -> set[str]:
    """Absolute module names imported anywhere in ``path``."""
    return {module for level, module, _ in _import_statements(path) if level == 0 and module}


def _module_file(name: str) -> Path | None:
    """The source file of the project module ``name``; None for anything else."""
    parts = name.split('.')
    root = PACKAGE_DIRS.get(parts[0])
    if root is None:
        return None
    base = root.joinpath(*parts)
    for candidate in (base / '__init__.py', base.with_suffix('.py')):
        if candidate.is_file():
            return candidate
    return None


def _module_name(path: Path) -> str | None:
    """The dotted name of a project module's file; None for a file outside the packages."""
    for package, root in PACKAGE_DIRS.items():
        if path.is_relative_to(root / package):
            parts = path.relative_to(root).with_suffix('').parts
            return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)
    return None


def _imported_names(path: Path) -> set[str]:
    """Modules ``path`` imports, with ``from a import b`` also as ``a.b`` and relative
    imports of project modules resolved."""
    own = _module_name(path)
    package = (own if path.name == '__init__.py' else own.rpartition('.')[0]) if own else None
    names: set[str] = set()
    for level, module, imported in _import_statements(path):
        if level == 0:
            base = module
        elif package:
            anchor = package.split('.')[: len(package.split('.')) - level + 1]
            base = '.'.join([*anchor, *([module] if module else [])])
        else:
            continue
        names.add(base)
        names.update(f'{base}.{name}' for name in imported)
    return names


def _reachable_imports(path: Path) -> set[str]:
    """Every module imported by ``path`` or, at any depth, by the project modules it imports
    (inside functions too: what a call could import)."""
    reached: set[str] = set()
    seen: set[Path] = set()
    pending = [path]
    while pending:
        current = pending.pop()
        if current in seen:
            continue
        seen.add(current)
        for name in _imported_names(current):
            reached.add(name)
            parts = name.split('.')
            for depth in range(1, len(parts) + 1):
                found = _module_file('.'.join(parts[:depth]))
                if found is not None:
                    pending.append(found)
    return reached


def _make_variable(name: str) -> list[str]:
    """The words of a ``NAME := ...`` line of the Makefile."""
    for line in (REPO / 'Makefile').read_text().splitlines():
        if line.startswith(f'{name} :='):
            return line.split(':=', 1)[1].split()
    msg = f'the Makefile sets no {name}'
    raise AssertionError(msg)


def _top_levels(path: Path) -> set[str]:
    return {name.split('.')[0] for name in _imports(path)}


def _relative(path: Path) -> str:
    return str(path.relative_to(REPO))


def test_imports_are_found_at_any_depth_and_relative_ones_skipped(tmp_path: Path) -> None:
    module = tmp_path / 'module.py'
    module.write_text(
        'import numpy as np\n'
        'from swarm_sim.engine import SimEngine\n'
        'from . import sibling\n'
        'def later():\n'
        '    import rclpy.node\n'
        '    from bayes_swarm import planner\n'
    )
    assert _imports(module) == {'numpy', 'swarm_sim.engine', 'rclpy.node', 'bayes_swarm'}
    assert _top_levels(module) == {'numpy', 'swarm_sim', 'rclpy', 'bayes_swarm'}


def test_the_table_names_every_package_of_the_workspace() -> None:
    found = {p.parent.name for p in [*REPO.glob('*/setup.py'), *REPO.glob('src/*/setup.py')]}
    assert found == set(PACKAGE_DIRS)
    assert set(ALLOWED) == set(PACKAGE_DIRS)


def test_every_algorithm_package_has_its_ros_modules() -> None:
    for package in ALGORITHMS:
        names = {path.name for path in _modules(package)}
        assert 'node.py' in names, package


@pytest.mark.parametrize('package', sorted(PACKAGE_DIRS))
def test_packages_import_only_the_layers_below_them(package: str) -> None:
    project = set(PACKAGE_DIRS)
    wrong = [
        f'{_relative(path)} imports {name}'
        for path in _modules(package)
        for name in sorted(_top_levels(path) & project - {package} - ALLOWED[package])
    ]
    assert not wrong, '\n'.join(wrong)


@pytest.mark.parametrize('package', sorted(ALGORITHMS))
def test_algorithm_cores_import_no_ros(package: str) -> None:
    cores = [path for path in _modules(package) if path.name not in ALGORITHM_ROS_MODULES]
    assert len(cores) > 5
    wrong = [
        f'{_relative(path)} imports {name}'
        for path in cores
        for name in sorted(_imports(path))
        if name.split('.')[0] in ROS_MODULES
    ]
    assert not wrong, '\n'.join(wrong)


def test_the_simulator_imports_no_ros_and_no_algorithm() -> None:
    wrong = [
        f'{_relative(path)} imports {name}'
        for path in _modules('swarm_sim')
        for name in sorted(_top_levels(path) & (ROS_MODULES | ALGORITHMS))
    ]
    assert not wrong, '\n'.join(wrong)


def test_the_bridge_imports_no_algorithm() -> None:
    wrong = [
        f'{_relative(path)} imports {name}'
        for path in _modules('sim_bridge')
        for name in sorted(_top_levels(path) & ALGORITHMS)
    ]
    assert not wrong, '\n'.join(wrong)


def test_only_benchmarks_import_the_experiments() -> None:
    users = [
        _relative(path)
        for package in sorted(set(PACKAGE_DIRS) - {'swarm_experiments'})
        for path in _modules(package)
        if 'swarm_experiments' in _top_levels(path)
    ]
    assert not users
    assert any(
        'swarm_experiments' in _top_levels(path) for path in (REPO / 'benchmarks').glob('*.py')
    )


@pytest.mark.parametrize('package', sorted(PACKAGE_DIRS))
def test_package_xml_declares_every_project_package_imported(package: str) -> None:
    root = ET.parse(PACKAGE_DIRS[package] / 'package.xml').getroot()
    declared = {element.text for element in root.iter('exec_depend')}
    imported = set().union(*(_top_levels(path) for path in _modules(package)))
    missing = sorted((imported & set(PACKAGE_DIRS)) - {package} - declared)
    assert not missing, f'{package}/package.xml lacks exec_depend {missing}'


def test_reachable_imports_follow_the_project_modules_and_resolve_relative_ones(
    tmp_path: Path,
) -> None:
    test_file = tmp_path / 'test_example.py'
    test_file.write_text('def test_it():\n    from swarm_experiments import mission\n')
    reached = _reachable_imports(test_file)
    # mission imports the sim bridge, whose node imports the ROS indirection.
    assert 'sim_bridge.bridge_node' in reached
    assert 'swarm_runtime.ros' in reached
    builtin_node = REPO / 'src' / 'swarm_runtime' / 'swarm_runtime' / 'builtin' / 'node.py'
    assert _module_name(builtin_node) == 'swarm_runtime.builtin.node'
    assert any(name.startswith('swarm_runtime.builtin.') for name in _imported_names(builtin_node))


def test_the_test_folders_the_rclpy_leg_leaves_out_reach_no_ros() -> None:
    folders = _make_variable('ROS_FREE_TESTS')
    assert folders
    wrong = []
    for folder in folders:
        files = sorted((REPO / folder).rglob('*.py'))
        assert files, folder
        for path in files:
            reached = _reachable_imports(path)
            ros = sorted(name for name in reached if name.split('.')[0] in ROS_MODULES)
            if ros:
                wrong.append(f'{_relative(path)} reaches {", ".join(ros[:3])}')
    assert not wrong, '\n'.join(wrong)
