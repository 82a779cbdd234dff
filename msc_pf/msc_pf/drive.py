"""Turning a per-period displacement into wheel commands for a differential-drive base.

The controller decides, once per control period, where the robot should be at the end of
the period (a waypoint). Between decisions the node steers toward it at a faster rate with
:func:`unicycle_command`: turn toward the waypoint, and drive forward at the speed that
reaches it by the deadline, slowed by the cosine of the heading error (no reversing).
"""

from __future__ import annotations

import math

from swarm_common.angles import wrap_angle

__all__ = ['unicycle_command', 'wrap_angle']


def unicycle_command(
    pose: tuple[float, float, float],
    waypoint_m: tuple[float, float],
    time_left_s: float,
    *,
    max_speed_m_s: float,
    max_yaw_rate_rad_s: float,
    heading_gain: float = 2.0,
    arrive_radius_m: float = 0.05,
) -> tuple[float, float]:
    """(forward speed [m/s], yaw rate [rad/s]) that drives ``pose`` toward ``waypoint_m``.

    Args:
        pose: x [m], y [m], yaw [rad].
        waypoint_m: where the robot should be at the deadline [m].
        time_left_s: time to the deadline [s] (floored at a small positive value).
        max_speed_m_s: forward speed limit.
        max_yaw_rate_rad_s: yaw rate limit.
        heading_gain: yaw rate per radian of heading error [1/s].
        arrive_radius_m: closer than this the robot stops.
    """
    dx, dy = waypoint_m[0] - pose[0], waypoint_m[1] - pose[1]
    distance = math.hypot(dx, dy)
    if distance < arrive_radius_m:
        return 0.0, 0.0
    error = wrap_angle(math.atan2(dy, dx) - pose[2])
    yaw_rate = max(-max_yaw_rate_rad_s, min(max_yaw_rate_rad_s, heading_gain * error))
    speed = min(max_speed_m_s, distance / max(time_left_s, 0.05)) * max(0.0, math.cos(error))
    return speed, yaw_rate
