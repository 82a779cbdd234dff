"""Where the robots start: the paper's fan of preferred directions around a departure point.

Centre departure: phi_i = bias + i * 360 deg / n. Edge departure: a half circle into the
building, phi_i = bias + (i + 1/2) * 180 deg / n with bias = (direction into the building)
- 90 deg, so the fan is centred on the way in. Robot i starts ``start_radius_m`` from the
departure point along phi_i, facing phi_i (the authors' simulator: 2 cells, 0.53 m).
These are the same formulas the OA-Bug node uses for its preferred directions, so a robot's
first heading is its preferred direction.

:func:`max_fan_robots` says how many robots fit on a fan: all inside the site, clear of the
walls, and no robot's centre inside another's body.
"""

from __future__ import annotations

import math

import numpy as np

from swarm_sim.errors import ConfigurationError

__all__ = [
    'DEFAULT_START_RADIUS_M',
    'departure_poses',
    'fan_fits',
    'max_fan_robots',
    'preferred_directions',
]

DEFAULT_START_RADIUS_M = 2 * 4.0 / 15.0


def preferred_directions(departure: str, robot_count: int, bias_rad: float) -> np.ndarray:
    """(n,) preferred directions phi_i [rad] in (-pi, pi] for 'center' or 'edge'."""
    if robot_count < 1:
        msg = f'robot_count must be >= 1, got {robot_count}'
        raise ConfigurationError(msg)
    i = np.arange(robot_count, dtype=float)
    if departure == 'center':
        phi = bias_rad + i * 2.0 * math.pi / robot_count
    elif departure == 'edge':
        phi = bias_rad + (i + 0.5) * math.pi / robot_count
    else:
        msg = f"departure must be 'center' or 'edge', got {departure!r}"
        raise ConfigurationError(msg)
    return np.mod(phi + math.pi, 2.0 * math.pi) - math.pi


def departure_poses(
    departure_xy: tuple[float, float],
    departure: str,
    robot_count: int,
    bias_rad: float,
    start_radius_m: float = DEFAULT_START_RADIUS_M,
) -> np.ndarray:
    """(n, 3) start poses x [m], y [m], yaw [rad] on the fan around ``departure_xy``."""
    phi = preferred_directions(departure, robot_count, bias_rad)
    x = departure_xy[0] + start_radius_m * np.cos(phi)
    y = departure_xy[1] + start_radius_m * np.sin(phi)
    return np.column_stack([x, y, phi])


def fan_fits(
    poses: np.ndarray,
    walls: np.ndarray,
    bounds_m: tuple[float, float],
    *,
    robot_radius_m: float,
    wall_clearance_m: float,
) -> bool:
    """True when every start pose lies in the bounds, ``wall_clearance_m`` or more from every
    wall (M, 4), and no robot's centre lies inside another robot's body (centres at least
    ``robot_radius_m`` apart)."""
    from swarm_sim.sites.validation import point_segment_distances

    xy = np.asarray(poses, dtype=float)[:, :2]
    width, height = bounds_m
    if np.any((xy < 0.0) | (xy > np.array([width, height]))):
        return False
    if len(xy) > 1:
        gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(gaps, np.inf)
        if gaps.min() < robot_radius_m:
            return False
    segments = np.asarray(walls, dtype=float).reshape(-1, 4)
    if len(segments):
        for point in xy:
            if point_segment_distances((point[0], point[1]), segments).min() < wall_clearance_m:
                return False
    return True


def max_fan_robots(
    departure_xy: tuple[float, float],
    departure: str,
    bias_rad: float,
    walls: np.ndarray,
    bounds_m: tuple[float, float],
    *,
    robot_radius_m: float,
    wall_clearance_m: float,
    start_radius_m: float = DEFAULT_START_RADIUS_M,
) -> int:
    """The largest swarm whose fan (:func:`departure_poses`) fits (:func:`fan_fits`); 0 when
    not even one robot does.

    Only counts up to the spacing limit: n robots on an arc of radius r are 2 r sin(a / 2n)
    apart (a = 360 deg for a centre fan, 180 deg for an edge fan).
    """
    arc_rad = 2.0 * math.pi if departure == 'center' else math.pi
    limit = 1
    ratio = robot_radius_m / (2.0 * start_radius_m)
    if ratio < 1.0:
        limit = max(1, math.floor(arc_rad / (2.0 * math.asin(ratio))))
    for count in range(limit, 0, -1):
        poses = departure_poses(departure_xy, departure, count, bias_rad, start_radius_m)
        if fan_fits(
            poses,
            walls,
            bounds_m,
            robot_radius_m=robot_radius_m,
            wall_clearance_m=wall_clearance_m,
        ):
            return count
    return 0
