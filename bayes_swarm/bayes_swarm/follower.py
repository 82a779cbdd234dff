"""Straight-line waypoint follower for a differential-drive robot (ROS-free).

The planners assume robots fly straight legs at the nominal speed V; a ground robot gets
close to that by turning in place toward the waypoint, then driving at V while steering out
the remaining heading error, and slowing down over the last ``slow_down_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from swarm_common.angles import wrap_angle

from bayes_swarm.errors import ConfigError

__all__ = ['FollowerConfig', 'VelocityCommand', 'WaypointFollower', 'wrap_angle']


@dataclass(frozen=True)
class FollowerConfig:
    """Follower gains and limits.

    Attributes:
        speed_mps: cruise speed V [m/s].
        max_turn_rate_radps: yaw-rate limit [rad/s].
        heading_gain: yaw rate per radian of heading error [1/s].
        turn_in_place_rad: heading error above which the robot turns without driving [rad].
        arrival_tolerance_m: distance at which the waypoint counts as reached [m].
        slow_down_m: distance over which the speed ramps down to the waypoint [m].
    """

    speed_mps: float = 0.1
    max_turn_rate_radps: float = 2.0
    heading_gain: float = 4.0
    turn_in_place_rad: float = 0.5
    arrival_tolerance_m: float = 0.01
    slow_down_m: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            'speed_mps',
            'max_turn_rate_radps',
            'heading_gain',
            'turn_in_place_rad',
            'arrival_tolerance_m',
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigError(msg)
        if not (math.isfinite(self.slow_down_m) and self.slow_down_m >= 0.0):
            msg = f'slow_down_m must be >= 0, got {self.slow_down_m!r}'
            raise ConfigError(msg)


@dataclass(frozen=True)
class VelocityCommand:
    """Forward speed [m/s], yaw rate [rad/s] and whether the waypoint is reached."""

    linear_mps: float
    angular_radps: float
    arrived: bool


class WaypointFollower:
    """Computes velocity commands that drive a unicycle to a waypoint."""

    def __init__(self, config: FollowerConfig) -> None:
        self._cfg = config

    def command(
        self, x_m: float, y_m: float, yaw_rad: float, waypoint_x_m: float, waypoint_y_m: float
    ) -> VelocityCommand:
        """Command for the pose (x, y, yaw) toward the waypoint."""
        cfg = self._cfg
        dx, dy = waypoint_x_m - x_m, waypoint_y_m - y_m
        distance = math.hypot(dx, dy)
        if distance <= cfg.arrival_tolerance_m:
            return VelocityCommand(0.0, 0.0, True)
        error = wrap_angle(math.atan2(dy, dx) - yaw_rad)
        turn = max(-cfg.max_turn_rate_radps, min(cfg.max_turn_rate_radps, cfg.heading_gain * error))
        if abs(error) > cfg.turn_in_place_rad:
            return VelocityCommand(0.0, turn, False)
        speed = cfg.speed_mps * math.cos(error)
        if cfg.slow_down_m > 0.0:
            speed *= min(1.0, distance / cfg.slow_down_m)
        return VelocityCommand(max(speed, 0.0), turn, False)
