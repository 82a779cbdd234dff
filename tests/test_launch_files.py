"""The ``ros2 launch`` files: read without launch (it has no wheel), checked against the lists
the spawners' ``--dry-run`` and ``robot_bringup --dry-run`` start.

Each launch file builds its ``Node`` actions from a shared function of the package
(``hw_drivers.robot_bringup.cli.launch_nodes``, ``swarm_experiments.processes.spawner_commands``
and ``launch_entries``). The files are parsed with ``ast``: they must pass every field of
those entries to ``Node`` unchanged, declare arguments whose defaults are the tools'
defaults, and be installed under share/<package>/launch. The shared functions are then
compared with the command lines the tools print.
"""

from __future__ import annotations

import ast
import shlex
from pathlib import Path

import pytest
import yaml
from hw_drivers.robot_bringup.cli import BringupOptions, build_plan, launch_nodes
from swarm_experiments.processes import (
    SPAWNERS,
    launch_entries,
    mission_commands,
    parse_command,
    spawner_commands,
)

from swarm_experiments import spawn

REPO = Path(__file__).resolve().parents[1]
ROBOT_LAUNCH = REPO / 'hw_drivers' / 'launch' / 'robot.launch.py'
SIM_LAUNCH = REPO / 'swarm_experiments' / 'launch' / 'swarm_sim.launch.py'
NODE_FIELDS = ('package', 'executable', 'namespace', 'parameters')


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding='utf-8'), filename=str(path))


def _arguments(tree: ast.Module) -> dict[str, tuple[str, str]]:
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], 'id', '') == 'ARGUMENTS':
            return ast.literal_eval(node.value)
    raise AssertionError('no ARGUMENTS table')


def _node_calls(tree: ast.Module) -> list[ast.Call]:
    return [
        n
        for n in ast.walk(tree)
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == 'Node'
    ]


def _imports(tree: ast.Module) -> set[tuple[str, str]]:
    return {
        (n.module or '', alias.name)
        for n in ast.walk(tree)
        if isinstance(n, ast.ImportFrom)
        for alias in n.names
    }


@pytest.mark.parametrize('path', [ROBOT_LAUNCH, SIM_LAUNCH], ids=['robot', 'swarm_sim'])
def test_each_node_takes_its_entry_unchanged(path: Path) -> None:
    tree = _tree(path)
    calls = _node_calls(tree)
    assert len(calls) == 1
    keywords = {k.arg: k.value for k in calls[0].keywords}
    for name in NODE_FIELDS:
        value = keywords[name]
        assert isinstance(value, ast.Subscript), f'{name} is not taken from the entry'
        assert isinstance(value.value, ast.Name)
        assert value.value.id == 'entry'
        assert ast.literal_eval(value.slice) == name
    assert set(keywords) == {*NODE_FIELDS, 'output'}
    # The launch ends with the nodes: OnProcessExit then Shutdown.
    assert ('launch.event_handlers', 'OnProcessExit') in _imports(tree)
    assert ('launch.events', 'Shutdown') in _imports(tree)
    assert any(
        isinstance(n, ast.FunctionDef) and n.name == 'generate_launch_description'
        for n in tree.body
    )


def test_robot_launch_uses_the_bringup_lists_with_its_defaults() -> None:
    tree = _tree(ROBOT_LAUNCH)
    assert ('hw_drivers.robot_bringup.cli', 'launch_nodes') in _imports(tree)
    defaults = BringupOptions()
    arguments = _arguments(tree)
    assert arguments['robot'][0] == defaults.robot
    assert arguments['own_tag_id'][0] == defaults.own_tag_id
    assert arguments['variant'][0] == defaults.variant
    assert int(arguments['robot_index'][0]) == defaults.robot_index
    assert int(arguments['robot_count'][0]) == defaults.robot_count
    assert (arguments['fake'][0] == 'true') == defaults.fake
    assert (arguments['with_oabug'][0] == 'true') == defaults.with_oabug
    assert arguments['params_file'][0] == defaults.params_file


def test_robot_launch_nodes_are_the_bringup_commands() -> None:
    options = BringupOptions(
        robot='r2',
        own_tag_id='42',
        robot_index=2,
        robot_count=4,
        params_file='r2.yaml',
        launcher='ros2',
        fake=True,
    )
    plan = build_plan(options)
    entries = launch_nodes(options)
    assert [e['executable'] for e in entries] == [c.name for c in plan]
    for entry, child in zip(entries, plan, strict=True):
        words = list(child.command)
        assert words[:4] == ['ros2', 'run', entry['package'], entry['executable']]
        assert words[4:7] == ['--ros-args', '-r', f'__ns:=/{entry["namespace"]}']
        assert words[7:9] == ['--params-file', entry['parameters'][0]]
        params = dict(
            (w.split(':=', 1)[0], yaml.safe_load(w.split(':=', 1)[1])) for w in words[10::2]
        )
        assert params == entry['parameters'][1]
    assert entries[-1]['parameters'][1]['own_tag_id'] == '42'  # a string, as the bringup quotes it


def test_sim_launch_uses_the_spawners_dry_run(tmp_path: Path) -> None:
    tree = _tree(SIM_LAUNCH)
    imported = _imports(tree)
    assert ('swarm_experiments.processes', 'spawner_commands') in imported
    assert ('swarm_experiments.processes', 'launch_entries') in imported
    arguments = _arguments(tree)
    assert arguments['spawner'][0] in SPAWNERS
    argv = ['--robots', '3', '--actions', '50', '--seed', '2']
    entries = launch_entries(spawner_commands('spawn', argv, tmp_path / 'a'))
    spec, _ = spawn.build_mission(spawn.SpawnSettings(robots=3, actions=50, seed=2))
    expected = mission_commands(spec, tmp_path / 'a')
    assert len(entries) == 4
    for entry, command in zip(entries, expected, strict=True):
        assert (entry['package'], entry['executable']) == (command.package, command.executable)
        assert entry['namespace'] == command.namespace.strip('/')
        assert entry['parameters'] == [dict(command.parameters)]
        # and the dry-run line of the same node reads back to the same entry
        line = shlex.join(command.ros2_run())
        assert launch_entries([parse_command(line)]) == [entry]


@pytest.mark.parametrize(
    ('setup', 'package'),
    [
        (REPO / 'hw_drivers' / 'setup.py', 'hw_drivers'),
        (REPO / 'swarm_experiments' / 'setup.py', 'swarm_experiments'),
    ],
)
def test_launch_files_are_installed_in_share(setup: Path, package: str) -> None:
    calls = [
        n
        for n in ast.walk(_tree(setup))
        if isinstance(n, ast.Call)
        and getattr(n.func, 'id', '') == 'share_files'
        and n.args
        and ast.literal_eval(n.args[0]) == 'launch'
    ]
    assert calls, f'{setup} does not install launch/'
    assert any((setup.parent / 'launch').glob('*.launch.py'))
    assert '<exec_depend>launch_ros</exec_depend>' in (setup.parent / 'package.xml').read_text()
