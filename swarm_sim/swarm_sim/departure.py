"""Where the robots start: the paper's fan of preferred directions around a departure point.

Centre departure: phi_i = bias + i * 360 deg / n. Edge departure: a half circle into the
building, phi_i = bias + (i + 1/2) * 180 deg / n with bias = (direction into the building)
- 90 deg, so the fan is centred on the way in. Robot i starts ``start_radius_m`` from the
departure point along phi_i, facing phi_i (the authors' simulator: 2 cells, 0.53 m).
These are the same formulas the OA-Bug node uses for its preferred directions, so a robot's
first heading is its preferred direction.
"""

from __future__ import annotations

import math

import numpy as np

from swarm_sim.errors import ConfigurationError

__all__ = ['DEFAULT_START_RADIUS_M', 'departure_poses', 'preferred_directions']

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
