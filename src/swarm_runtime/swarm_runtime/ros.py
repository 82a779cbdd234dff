"""The one module that node code imports rclpy and message classes from.

On a ROS 2 Jazzy machine this hands out the real ``rclpy`` and the real generated message
modules and adds nothing. Where rclpy cannot be imported (CI, a laptop) it hands out the
built-in runtime, :mod:`swarm_runtime.builtin`, which mirrors rclpy's module layout, and
message classes generated from the same definitions.

Node code looks like plain rclpy code::

    from swarm_runtime.ros import rclpy, Node, message_module, qos_profile_sensor_data

    sensor_msgs = message_module('sensor_msgs')

    class Echo(Node):
        ...

The environment variable ``SWARM_RUNTIME`` chooses explicitly: ``auto`` (default: real rclpy
when importable), ``rclpy`` (fail if it is missing) or ``builtin`` (use the built-in runtime
even on a ROS machine, e.g. for a headless simulation).
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType
from typing import Any

__all__ = [
    'RUNTIME_ENV_VAR',
    'Duration',
    'ExternalShutdownException',
    'HistoryPolicy',
    'Node',
    'Parameter',
    'QoSDurabilityPolicy',
    'QoSProfile',
    'ReliabilityPolicy',
    'SingleThreadedExecutor',
    'Time',
    'message_module',
    'qos_profile_sensor_data',
    'qos_profile_system_default',
    'rclpy',
    'using_real_rclpy',
]

RUNTIME_ENV_VAR = 'SWARM_RUNTIME'
_CHOICES = ('auto', 'rclpy', 'builtin')


class RuntimeSelectionError(ImportError):
    """The runtime asked for through SWARM_RUNTIME cannot be provided."""


def _select_rclpy() -> tuple[ModuleType, bool]:
    choice = os.environ.get(RUNTIME_ENV_VAR, 'auto').strip().lower() or 'auto'
    if choice not in _CHOICES:
        msg = f'{RUNTIME_ENV_VAR}={choice!r} is not one of {", ".join(_CHOICES)}'
        raise RuntimeSelectionError(msg)
    if choice != 'builtin':
        try:
            real = importlib.import_module('rclpy')
        except ImportError as err:
            if choice == 'rclpy':
                msg = f'{RUNTIME_ENV_VAR}=rclpy but rclpy cannot be imported: {err}'
                raise RuntimeSelectionError(msg) from err
        else:
            for submodule in ('node', 'qos', 'executors', 'parameter', 'time', 'duration'):
                importlib.import_module(f'rclpy.{submodule}')
            return real, True
    return importlib.import_module('swarm_runtime.builtin'), False


rclpy, _REAL = _select_rclpy()


def using_real_rclpy() -> bool:
    """Return True when node code runs on the real rclpy."""
    return _REAL


def message_module(package: str) -> Any:
    """Return the message module of an interface package, e.g. ``message_module('sensor_msgs')``.

    With real rclpy this is ``importlib.import_module('sensor_msgs.msg')``; otherwise a module of
    rclpy-like classes generated from the Jazzy definitions (and swarm_interfaces/msg).
    """
    if _REAL:
        return importlib.import_module(f'{package}.msg')
    from swarm_runtime.messages import get_message_module

    return get_message_module(package)


Node = rclpy.node.Node
ExternalShutdownException = rclpy.executors.ExternalShutdownException
SingleThreadedExecutor = rclpy.executors.SingleThreadedExecutor
QoSProfile = rclpy.qos.QoSProfile
ReliabilityPolicy = rclpy.qos.ReliabilityPolicy
HistoryPolicy = rclpy.qos.HistoryPolicy
QoSDurabilityPolicy = rclpy.qos.DurabilityPolicy
qos_profile_sensor_data = rclpy.qos.qos_profile_sensor_data
qos_profile_system_default = rclpy.qos.qos_profile_system_default
Parameter = rclpy.parameter.Parameter
Time = rclpy.time.Time
Duration = rclpy.duration.Duration
