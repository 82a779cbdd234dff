"""Angles: wrapping, yaw from the IMU quaternion, the paper's preferred directions."""

from __future__ import annotations

import math

from swarm_common.angles import TWO_PI, wrap_angle, yaw_from_quaternion

from oabug_robot.settings import Departure

__all__ = ['angle_difference', 'preferred_direction', 'wrap_angle', 'yaw_from_quaternion']


def angle_difference(target_rad: float, source_rad: float) -> float:
    """Return the signed rotation [rad], in (-pi, pi], from ``source_rad`` to ``target_rad``."""
    return wrap_angle(target_rad - source_rad)


def preferred_direction(
    robot_index: int, robot_count: int, departure: Departure, bias_rad: float
) -> float:
    """Return robot i's preferred direction phi_i [rad], wrapped to (-pi, pi].

    Centre departure (paper, Sec. II-B): phi_i = bias + i * 2 pi / n. Edge departure: the n
    directions split the half circle into the building evenly, phi_i = bias + (i + 1/2) *
    pi / n, so with bias = (direction into the building) - pi/2 no robot starts along the
    outer wall.
    """
    if departure is Departure.CENTER:
        return wrap_angle(bias_rad + robot_index * TWO_PI / robot_count)
    return wrap_angle(bias_rad + (robot_index + 0.5) * math.pi / robot_count)
