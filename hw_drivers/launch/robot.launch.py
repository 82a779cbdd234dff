"""One robot's bringup for ``ros2 launch``: its drivers and its OA-Bug node.

    ros2 launch hw_drivers robot.launch.py robot:=r0 own_tag_id:=D2 robot_index:=0 \
        robot_count:=4 params_file:=/etc/swarm/r0.params.yaml

The nodes, their order, namespaces and parameters come from
``hw_drivers.robot_bringup.cli.launch_nodes``, the same lists ``robot_bringup`` starts
(``robot_bringup --dry-run`` prints them). launch starts the nodes together, without the
bringup's checks of devices and programs; when any node exits the launch shuts down, as
the bringup stops every child. ``robot_bringup`` stays the recommended way on a robot.
"""

from __future__ import annotations

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, EmitEvent, OpaqueFunction, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.events import Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

ARGUMENTS = {
    'robot': ('r0', "the robot's namespace and frame prefix"),
    'own_tag_id': ('', "the robot's own AoA tag id"),
    'variant': ('gas_sound', 'OA-Bug variant'),
    'robot_index': ('0', "the robot's index in the swarm"),
    'robot_count': ('1', 'robots in the swarm'),
    'fake': ('false', 'simulated devices instead of real ones'),
    'with_oabug': ('true', 'also start the OA-Bug node'),
    'params_file': ('', 'ROS parameter file for every node'),
}


def _nodes(context):
    from hw_drivers.robot_bringup.cli import BringupOptions, launch_nodes

    value = {name: LaunchConfiguration(name).perform(context) for name in ARGUMENTS}
    options = BringupOptions(
        robot=value['robot'],
        own_tag_id=value['own_tag_id'],
        variant=value['variant'],
        robot_index=int(value['robot_index']),
        robot_count=int(value['robot_count']),
        fake=value['fake'].lower() == 'true',
        with_oabug=value['with_oabug'].lower() == 'true',
        params_file=value['params_file'],
    )
    actions = []
    for entry in launch_nodes(options):
        node = Node(
            package=entry['package'],
            executable=entry['executable'],
            namespace=entry['namespace'],
            parameters=entry['parameters'],
            output='screen',
        )
        stop = EmitEvent(event=Shutdown(reason=f'{entry["executable"]} exited'))
        actions += [node, RegisterEventHandler(OnProcessExit(target_action=node, on_exit=[stop]))]
    return actions


def generate_launch_description():
    """The launch description: the arguments, then the nodes built when it runs."""
    declared = [
        DeclareLaunchArgument(name, default_value=default, description=text)
        for name, (default, text) in ARGUMENTS.items()
    ]
    return LaunchDescription([*declared, OpaqueFunction(function=_nodes)])
