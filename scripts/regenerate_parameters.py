#!/usr/bin/env python3
"""Regenerate every node's parameter file and docs table from its parameter spec.

Each node declares its parameters once, on the fields of its configuration dataclass
(swarm_common.params). From that spec this script writes

* the package's ROS 2 parameter file, ``<package>/config/<node>.yaml`` (every parameter with
  its default and description), and
* the node's parameter table in the docs, between the lines
  ``<!-- BEGIN GENERATED: <node> parameters -->`` and ``<!-- END GENERATED: <node> parameters -->``.

Usage::

    python scripts/regenerate_parameters.py            # rewrite what differs
    python scripts/regenerate_parameters.py --check    # exit 1 and name what differs

It lives here, not in a package, because it imports every node package (the layer rule lets
no package do that). tests/test_parameter_files.py runs the check.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class NodeEntry:
    """Where one node's spec lives and what is generated from it."""

    node: str
    spec: str  # 'module:ATTRIBUTE'
    yaml: str  # path of the parameter file, relative to the repository
    doc: str  # docs page that holds the table
    usage: str  # how to start the node with the file


NODES = (
    NodeEntry(
        'oabug',
        'oabug_robot.node_settings:OABUG_PARAMETERS',
        'oabug_robot/config/oabug.yaml',
        'docs/oabug.md',
        'ros2 run oabug_robot oabug --ros-args -r __ns:=/r0 --params-file oabug.yaml '
        '-p robot_index:=0 -p robot_count:=4',
    ),
    NodeEntry(
        'sgba',
        'oabug_robot.sgba.settings:SGBA_PARAMETERS',
        'oabug_robot/config/sgba.yaml',
        'docs/sgba.md',
        'ros2 run oabug_robot sgba --ros-args -r __ns:=/r0 --params-file sgba.yaml '
        '-p robot_index:=0 -p robot_count:=4 -p own_tag_id:=R0',
    ),
    NodeEntry(
        'bayes_swarm',
        'bayes_swarm.node_settings:BAYES_SWARM_PARAMETERS',
        'bayes_swarm/config/bayes_swarm.yaml',
        'docs/bayes_swarm.md',
        'ros2 run bayes_swarm bayes_swarm_node --ros-args -r __ns:=/r0 --params-file '
        'bayes_swarm.yaml --params-file case1.yaml -p robot_index:=0',
    ),
    NodeEntry(
        'msc_pf',
        'msc_pf.parameters:MSC_PF_PARAMETERS',
        'msc_pf/config/msc_pf.yaml',
        'docs/msc_pf.md',
        'ros2 run msc_pf msc_pf_node --ros-args -r __ns:=/r0 --params-file msc_pf.yaml',
    ),
    NodeEntry(
        'sim_bridge',
        'sim_bridge.bridge_parameters:BRIDGE_PARAMETERS',
        'sim_bridge/config/sim_bridge.yaml',
        'docs/simulation.md',
        'ros2 run sim_bridge sim_bridge --ros-args --params-file sim_bridge.yaml '
        '-p site_file:=small -p robot_count:=6',
    ),
    *(
        NodeEntry(
            node,
            f'hw_drivers.parameters:{attribute}',
            f'hw_drivers/config/{node}.yaml',
            'docs/hardware.md',
            f'ros2 run hw_drivers {node} --ros-args -r __ns:=/r0 --params-file {node}.yaml',
        )
        for node, attribute in (
            ('rplidar_node', 'RPLIDAR_PARAMETERS'),
            ('gas_adc_node', 'GAS_PARAMETERS'),
            ('mpu6050_node', 'MPU6050_PARAMETERS'),
            ('aoa_receiver_node', 'AOA_RECEIVER_PARAMETERS'),
            ('pump_node', 'PUMP_PARAMETERS'),
            ('static_frames_node', 'STATIC_FRAMES_PARAMETERS'),
        )
    ),
)


class RegenerationError(Exception):
    """A docs page lacks the markers of a table, or a spec cannot be imported."""


def load_spec(entry: NodeEntry):  # -> ParameterSpec
    """Import the spec of ``entry``."""
    module, _, attribute = entry.spec.partition(':')
    return getattr(importlib.import_module(module), attribute)


def markers(node: str) -> tuple[str, str]:
    """The begin and end marker lines of a node's docs table."""
    return (
        f'<!-- BEGIN GENERATED: {node} parameters -->',
        f'<!-- END GENERATED: {node} parameters -->',
    )


def render_yaml(entry: NodeEntry) -> str:
    """The parameter file of ``entry``."""
    spec = load_spec(entry)
    header = (
        f'Parameters of the {entry.node} node with their defaults, generated from',
        f'{entry.spec.replace(":", ".")} by scripts/regenerate_parameters.py: edit the',
        'dataclass, not this file. Use:',
        f'  {entry.usage}',
    )
    return spec.render_yaml(f'/**/{entry.node}', header=header)


def render_table(entry: NodeEntry) -> str:
    """The docs table of ``entry`` with its markers."""
    begin, end = markers(entry.node)
    return f'{begin}\n{load_spec(entry).render_markdown()}{end}'


def replace_table(text: str, entry: NodeEntry, path: str) -> str:
    """``text`` with the table of ``entry`` between its markers replaced.

    Raises:
        RegenerationError: the markers are missing or out of order.
    """
    begin, end = markers(entry.node)
    start, stop = text.find(begin), text.find(end)
    if start < 0 or stop < start:
        msg = f'{path}: add the lines {begin!r} and {end!r} where the table goes'
        raise RegenerationError(msg)
    return text[:start] + render_table(entry) + text[stop + len(end) :]


def expected_files(repo: Path = REPO) -> dict[Path, str]:
    """Every generated file's path and the content it must have."""
    files: dict[Path, str] = {}
    for entry in NODES:
        files[repo / entry.yaml] = render_yaml(entry)
        doc = repo / entry.doc
        current = files.get(doc, doc.read_text(encoding='utf-8'))
        files[doc] = replace_table(current, entry, entry.doc)
    return files


def stale_files(repo: Path = REPO) -> list[Path]:
    """The generated files whose content differs from the specs."""
    return [
        path
        for path, text in expected_files(repo).items()
        if not path.exists() or path.read_text(encoding='utf-8') != text
    ]


def main(argv: list[str] | None = None) -> int:
    """Regenerate (or with ``--check`` compare) every generated parameter file and table."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--check', action='store_true', help='only report what differs')
    args = parser.parse_args(argv)
    try:
        files = expected_files()
    except (RegenerationError, ImportError) as err:
        print(f'regenerate_parameters: {err}', file=sys.stderr)
        return 2
    stale = [p for p, text in files.items() if not p.exists() or p.read_text() != text]
    for path in stale:
        relative = path.relative_to(REPO)
        if args.check:
            print(f'out of date: {relative} (run python scripts/regenerate_parameters.py)')
        else:
            path.write_text(files[path], encoding='utf-8')
            print(f'wrote {relative}')
    return 1 if args.check and stale else 0


if __name__ == '__main__':
    raise SystemExit(main())
