"""A trivial wall-bouncing controller: the smallest node that drives a simulated robot.

It goes straight at ``speed_mps`` and turns left in place while the lidar sees anything
closer than ``clearance_m`` within +-35 degrees ahead. It exists to smoke-test the bridge and
the mission runner without any search algorithm (``ros2 run`` it against the bridge to watch
a robot move), not to search.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from swarm_common.params import ParameterSpec, parameter
from swarm_runtime.node_main import run_node
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import Node, message_module, qos_profile_sensor_data

__all__ = ['BOUNCER_PARAMETERS', 'BouncerConfig', 'WallBouncer', 'main']

_geometry = message_module('geometry_msgs')
_sensor = message_module('sensor_msgs')


@dataclass(frozen=True)
class BouncerConfig:
    """The bouncer's parameters."""

    speed_mps: float = parameter(0.3, 'speed', unit='m/s', ge=0.0)
    turn_rate_radps: float = parameter(1.2, 'turn rate', unit='rad/s')
    clearance_m: float = parameter(0.45, 'turn when closer ahead', unit='m', ge=0.0)


BOUNCER_PARAMETERS = ParameterSpec(BouncerConfig)


class WallBouncer(Node):
    """Drive straight; turn left in place while something is close ahead."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('bouncer', **kwargs)
        config = declare_config(self, BOUNCER_PARAMETERS).config
        self._speed = config.speed_mps
        self._turn = config.turn_rate_radps
        self._clearance = config.clearance_m
        self._pub = self.create_publisher(_geometry.Twist, 'cmd_vel', 10)
        self.create_subscription(_sensor.LaserScan, 'scan', self._on_scan, qos_profile_sensor_data)

    def _on_scan(self, msg: Any) -> None:
        ranges = np.asarray(msg.ranges, dtype=float)
        angles = msg.angle_min + msg.angle_increment * np.arange(len(ranges))
        ahead = np.abs(np.mod(angles + math.pi, 2 * math.pi) - math.pi) < math.radians(35.0)
        close = ranges[ahead & np.isfinite(ranges)]
        blocked = bool(close.size and close.min() < self._clearance)
        cmd = _geometry.Twist()
        cmd.linear.x = 0.0 if blocked else self._speed
        cmd.angular.z = self._turn if blocked else 0.0
        self._pub.publish(cmd)


def main(args: list[str] | None = None) -> int:
    """Entry point: ``python -m sim_bridge.bouncer --ros-args -r __ns:=/r0``."""
    return run_node(WallBouncer, args, name='bouncer', parameters=BOUNCER_PARAMETERS)


if __name__ == '__main__':
    raise SystemExit(main())
