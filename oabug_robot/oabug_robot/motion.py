"""Motion primitives: turn in place, go straight on a heading, follow a wall.

Each is a pure function of the current error signals and returns a :class:`Twist2D`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from oabug_robot.scan_features import SideWall
from oabug_robot.settings import MotionConfig

__all__ = [
    'STOP',
    'Twist2D',
    'follow_wall',
    'go_straight',
    'inner_corner_ahead',
    'turn_in_place',
    'wrap_corner',
]


class Twist2D(NamedTuple):
    """A planar velocity command: forward speed [m/s] and yaw rate [rad/s, CCW positive].

    A named tuple rather than a frozen dataclass: the controller builds one per step, and a
    tuple is built several times faster.
    """

    linear_mps: float
    angular_radps: float


STOP = Twist2D(0.0, 0.0)

# Heading errors above this are turned out on the spot before driving on.
_DRIVE_ERROR_RAD = math.radians(30.0)
# Slowest forward speed while following, as a fraction of cruise speed.
_MIN_FOLLOW_FRACTION = 0.3


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


def turn_in_place(error_rad: float, cfg: MotionConfig) -> Twist2D:
    """Rotate on the spot to remove ``error_rad`` (target minus current heading)."""
    rate = min(
        cfg.turn_rate_radps, max(cfg.min_turn_rate_radps, cfg.heading_gain_per_s * abs(error_rad))
    )
    return Twist2D(0.0, math.copysign(rate, error_rad))


def go_straight(error_rad: float, cfg: MotionConfig) -> Twist2D:
    """Drive at cruise speed holding a heading; ``error_rad`` is target minus current heading."""
    if abs(error_rad) > _DRIVE_ERROR_RAD:
        return turn_in_place(error_rad, cfg)
    return Twist2D(
        cfg.forward_speed_mps, _clamp(cfg.heading_gain_per_s * error_rad, cfg.turn_rate_radps)
    )


def follow_wall(
    side: int,
    wall: SideWall,
    front_blocked: bool,
    cfg: MotionConfig,
    *,
    front_wall_m: float = math.inf,
    body_radius_m: float = 0.0,
) -> Twist2D:
    """Keep the wall on ``side`` (+1 left, -1 right) parallel at ``cfg.wall_distance_m``.

    An inner corner (a wall ahead) is taken on the move: once the wall ahead is within
    :func:`inner_corner_ahead`'s distance the follower turns away from its side at the
    largest yaw rate while driving on, on an arc of radius ``cfg.inner_corner_arc_radius_m``
    that tightens as the wall comes closer and becomes a turn on the spot where the wall
    would touch the body. Without the arc (radius 0) it turns on the spot once the wall
    blocks the way. With no wall beside it, it arcs towards its side until one is back.

    Args:
        side: the followed side.
        wall: the wall beside the robot on that side.
        front_blocked: a wall is within hit distance ahead.
        cfg: speeds and gains.
        front_wall_m: forward distance to the nearest wall ahead [m].
        body_radius_m: the body's radius, where the wall ahead would touch it [m].
    """
    if inner_corner_ahead(front_wall_m, cfg):
        start_m = cfg.wall_distance_m + cfg.inner_corner_arc_radius_m
        room = (front_wall_m - body_radius_m) / max(start_m - body_radius_m, 1e-9)
        speed = cfg.turn_rate_radps * cfg.inner_corner_arc_radius_m
        speed = min(cfg.forward_speed_mps, speed) * min(1.0, max(0.0, room))
        return Twist2D(speed, -side * cfg.turn_rate_radps)
    if front_blocked:
        return Twist2D(0.0, -side * cfg.turn_rate_radps)
    if not wall.found:
        speed = 0.5 * cfg.forward_speed_mps
        return Twist2D(speed, side * min(cfg.turn_rate_radps, speed / cfg.wall_distance_m))
    distance_error = wall.distance_m - cfg.wall_distance_m
    rate = (
        cfg.wall_angle_gain_per_s * wall.angle_rad
        + side * cfg.wall_distance_gain_radps_per_m * distance_error
    )
    fraction = max(_MIN_FOLLOW_FRACTION, math.cos(min(abs(wall.angle_rad), math.pi / 2)))
    return Twist2D(cfg.forward_speed_mps * fraction, _clamp(rate, cfg.turn_rate_radps))


def inner_corner_ahead(front_wall_m: float, cfg: MotionConfig) -> bool:
    """Whether a follower should start arcing away from the wall ``front_wall_m`` ahead.

    A 90 deg arc of radius r ends r further on, so it starts r beyond the wall distance and
    ends parallel to the new wall at the wall distance; 0 disables the arc (the follower
    drives on until the wall blocks the way and turns on the spot).
    """
    radius = cfg.inner_corner_arc_radius_m
    return radius > 0.0 and front_wall_m <= cfg.wall_distance_m + radius


def wrap_corner(side: int, cfg: MotionConfig) -> Twist2D:
    """Arc towards ``side`` at the wall distance: round the end of the wall just passed."""
    rate = min(cfg.turn_rate_radps, cfg.forward_speed_mps / cfg.wall_distance_m)
    return Twist2D(rate * cfg.wall_distance_m, side * rate)
