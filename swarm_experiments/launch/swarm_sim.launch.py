"""A multi-robot simulation for ``ros2 launch``: the nodes a spawner's ``--processes`` runs.

    ros2 launch swarm_experiments swarm_sim.launch.py spawner:=spawn \
        args:='--robots 4 --actions 300 --seed 1'
    ros2 launch swarm_experiments swarm_sim.launch.py spawner:=spawn_msc_pf args:='--robots 6'

The sim bridge and one node per robot, with the command lines
``<spawner> --processes --dry-run <args>`` prints (built by
``swarm_experiments.processes.spawner_commands``, the spawner's own code). The bridge ends
the mission at the spawner's end condition and exits, and the launch shuts down with it; the
outcome (coverage, room entries, tau or captures) is in ``outcome.json`` of ``run_dir``.
Unlike the spawner, the launch prints no summary and records no bag (run ``ros2 bag
record`` beside it, or use the spawner with ``--processes --record``).
"""

from __future__ import annotations

import shlex
import tempfile
from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, EmitEvent, OpaqueFunction, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.events import Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = {
    'spawner': ('spawn', 'spawn (OA-Bug), spawn_bayes_swarm or spawn_msc_pf'),
    'args': ('', "the spawner's options, e.g. '--robots 4 --seed 1'"),
    'run_dir': ('', 'directory for the mission and outcome files (default: a new one)'),
}


def _nodes(context):
    from swarm_experiments.processes import launch_entries, spawner_commands

    spawner = LaunchConfiguration('spawner').perform(context)
    args = shlex.split(LaunchConfiguration('args').perform(context))
    run_dir = LaunchConfiguration('run_dir').perform(context)
    run_dir = Path(run_dir) if run_dir else Path(tempfile.mkdtemp(prefix='swarm-launch-'))
    nodes = [
        Node(
            package=entry['package'],
            executable=entry['executable'],
            namespace=entry['namespace'],
            parameters=entry['parameters'],
            output='screen',
        )
        for entry in launch_entries(spawner_commands(spawner, args, run_dir))
    ]
    stop = EmitEvent(event=Shutdown(reason=f'mission ended, outcome in {run_dir}'))
    return [*nodes, RegisterEventHandler(OnProcessExit(target_action=nodes[0], on_exit=[stop]))]


def generate_launch_description():
    """The launch description: the arguments, then the nodes built when it runs."""
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=text)
        for name, (default, text) in ARGUMENTS.items()
    ]
    return LaunchDescription([*declared, OpaqueFunction(function=_nodes)])
