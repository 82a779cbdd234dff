"""Compiled physics step: what :meth:`swarm_sim.world.World.step_reference` does to every
robot, in one numba loop instead of a few dozen numpy calls on arrays of N elements.

Simulation only, like :mod:`swarm_sim.raycast_kernel` (whose assumptions it shares: the C
library's ``cos``, ``sin`` and ``hypot`` give numpy's values, and nothing is contracted into
fused multiply-adds). The kernel performs the numpy step's floating-point operations in the
same order, so poses, velocities, collision counts and wall clearances are bit-identical
(``test_world.py`` runs both on random crowded worlds with walls, and with non-finite
commands).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from swarm_sim.raycast_kernel import _wrap, nearest_kernel

__all__ = ['world_step_kernel']


@njit(cache=True)
def world_step_kernel(
    poses: np.ndarray,
    commands: np.ndarray,
    max_speed_mps: float,
    max_yaw_rate_radps: float,
    dt_s: float,
    wall_clearance_m: float,
    contact_m: float,
    has_walls: bool,
    clearance: np.ndarray,
    has_clearance: bool,
    collisions: np.ndarray,
    velocities: np.ndarray,
    grid: tuple,
) -> tuple[np.ndarray, bool]:  # pragma: no cover - compiled
    """One physics step of N robots; ``poses``, ``collisions`` and ``velocities`` are
    updated in place.

    Args:
        poses: (N, 3) x [m], y [m], yaw [rad].
        commands: (N, 2) speed [m/s] and yaw rate [rad/s], not yet clipped.
        max_speed_mps, max_yaw_rate_radps: the drive limits [m/s, rad/s].
        dt_s: step length [s].
        wall_clearance_m: contact distance of a robot centre to a wall centre line [m].
        contact_m: contact distance of two robot centres [m].
        has_walls: the world has walls.
        clearance: (N,) wall clearances of the current positions, if ``has_clearance``.
        has_clearance: ``clearance`` holds them (else they are computed when needed).
        collisions: (N,) collision counts.
        velocities: (N, 2) achieved speed and yaw rate (output).
        grid: the wall grid, :meth:`swarm_sim.geometry.WallGrid.kernel_arguments`.

    Returns:
        The (N,) wall clearances after the step and whether they were computed (they are
        only when a robot tried to move in a world with walls).
    """
    n = poses.shape[0]
    v = np.empty(n)
    w = np.empty(n)
    new_yaw = np.empty(n)
    dx = np.empty(n)
    dy = np.empty(n)
    cand = np.empty((n, 2))
    moves = np.zeros(n, dtype=np.bool_)
    any_move = False
    for i in range(n):
        vi = commands[i, 0]
        wi = commands[i, 1]
        vi = vi if math.isfinite(vi) else 0.0
        wi = wi if math.isfinite(wi) else 0.0
        vi = min(max(vi, -max_speed_mps), max_speed_mps)
        wi = min(max(wi, -max_yaw_rate_radps), max_yaw_rate_radps)
        yaw = poses[i, 2]
        new_yaw[i] = yaw + wi * dt_s
        cos_yaw = math.cos(yaw)
        sin_yaw = math.sin(yaw)
        if abs(wi) < 1e-9:
            dx[i] = vi * dt_s * cos_yaw
            dy[i] = vi * dt_s * sin_yaw
        else:
            dx[i] = vi / wi * (math.sin(new_yaw[i]) - sin_yaw)
            dy[i] = -vi / wi * (math.cos(new_yaw[i]) - cos_yaw)
        cand[i, 0] = poses[i, 0] + dx[i]
        cand[i, 1] = poses[i, 1] + dy[i]
        v[i] = vi
        w[i] = wi
        moves[i] = dx[i] != 0.0 or dy[i] != 0.0
        any_move = any_move or moves[i]
    allowed = moves.copy()
    computed = has_walls and any_move
    new_clear = clearance
    old_clear = clearance
    if computed:
        new_clear = nearest_kernel(cand, *grid)
        if not has_clearance:
            old_clear = nearest_kernel(poses[:, :2].copy(), *grid)
        for i in range(n):
            if new_clear[i] < wall_clearance_m and new_clear[i] < old_clear[i]:
                allowed[i] = False
    longest = -np.inf
    for i in range(n):
        longest = max(longest, math.hypot(dx[i], dy[i]))
    threshold = contact_m + longest + 1e-9
    final = poses[:, :2].copy()
    close = np.zeros(n, dtype=np.bool_)
    for i in range(n):
        for j in range(n):
            gap = math.hypot(cand[i, 0] - poses[j, 0], cand[i, 1] - poses[j, 1])
            if j != i and gap < threshold:
                close[i] = True
        if allowed[i] and not close[i]:
            final[i, 0] = cand[i, 0]
            final[i, 1] = cand[i, 1]
    # Robots that may touch another move one by one, seeing the ones already moved.
    for i in range(n):
        if not (allowed[i] and close[i]):
            continue
        new_min = np.inf
        old_min = np.inf
        for j in range(n):
            if j == i:
                continue
            new_min = min(new_min, math.hypot(final[j, 0] - cand[i, 0], final[j, 1] - cand[i, 1]))
            old_min = min(old_min, math.hypot(final[j, 0] - poses[i, 0], final[j, 1] - poses[i, 1]))
        if new_min < contact_m and new_min < old_min:
            allowed[i] = False
            continue
        final[i, 0] = cand[i, 0]
        final[i, 1] = cand[i, 1]
    after = np.empty(n)
    for i in range(n):
        if moves[i] and not allowed[i]:
            collisions[i] += 1
        poses[i, 0] = final[i, 0]
        poses[i, 1] = final[i, 1]
        poses[i, 2] = _wrap(new_yaw[i])
        if computed:
            after[i] = new_clear[i] if allowed[i] else old_clear[i]
        velocities[i, 0] = v[i] if allowed[i] else 0.0
        velocities[i, 1] = w[i]
    return after, computed


@njit(cache=True)
def rooms_touched_kernel(
    positions: np.ndarray, rects: np.ndarray, rect_room: np.ndarray, num_rooms: int, radius2: float
) -> np.ndarray:  # pragma: no cover - compiled
    """``CoverageTracker.inside_reference`` for the rectangle rooms: (N, K) bool, robot i's
    disc (squared radius ``radius2``) overlaps a rectangle of room k.

    Args:
        positions: (N, 2+) robot positions [m].
        rects: (R, 4) x_min, y_min, x_max, y_max [m].
        rect_room: (R,) the room of each rectangle.
        num_rooms: K.
        radius2: the disc's squared radius [m^2].
    """
    n = positions.shape[0]
    result = np.zeros((n, num_rooms), dtype=np.bool_)
    for i in range(n):
        x = positions[i, 0]
        y = positions[i, 1]
        for r in range(rects.shape[0]):
            dx = max(max(rects[r, 0] - x, x - rects[r, 2]), 0.0)
            dy = max(max(rects[r, 1] - y, y - rects[r, 3]), 0.0)
            if dx * dx + dy * dy < radius2:
                result[i, rect_room[r]] = True
    return result


@njit(cache=True)
def rooms_entered_kernel(
    positions: np.ndarray,
    rects: np.ndarray,
    rect_room: np.ndarray,
    radius2: float,
    first_robot: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """The rooms first entered now: per room not yet entered (``first_robot`` < 0) that a
    robot's disc overlaps (:func:`rooms_touched_kernel`'s test), the lowest such robot.

    Args:
        positions: (N, 2+) robot positions [m].
        rects: (R, 4) x_min, y_min, x_max, y_max [m].
        rect_room: (R,) the room of each rectangle.
        radius2: the disc's squared radius [m^2].
        first_robot: (K,) per room, the robot that entered it first (-1: none yet).

    Returns:
        (K,) per room, the robot entering it now (-1: none), -1 for rooms entered before;
        all -1 is returned as an empty array (nothing new: the common case).
    """
    entering = np.full(first_robot.shape[0], -1, dtype=np.int64)
    found = False
    for r in range(rects.shape[0]):
        room = rect_room[r]
        if first_robot[room] >= 0:
            continue
        for i in range(positions.shape[0]):
            if 0 <= entering[room] <= i:
                break
            x = positions[i, 0]
            y = positions[i, 1]
            dx = max(max(rects[r, 0] - x, x - rects[r, 2]), 0.0)
            dy = max(max(rects[r, 1] - y, y - rects[r, 3]), 0.0)
            if dx * dx + dy * dy < radius2:
                entering[room] = i
                found = True
                break
    return entering if found else entering[:0]


@njit(cache=True)
def actuators_kernel(
    time_s: float,
    command: np.ndarray,
    command_time_s: np.ndarray,
    command_timeout_s: float,
    pump_on: np.ndarray,
    pump_time_s: np.ndarray,
    pump_timeout_s: float,
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """``SimEngine.active_commands`` and ``SimEngine.pumps_running`` in one call: (N, 2)
    the commands in force (zero where older than ``command_timeout_s``) and (N,) the pumps
    running (an "on" older than ``pump_timeout_s`` has timed out). The timeouts include
    the engine's 1e-9 s margin."""
    n = command.shape[0]
    active = np.empty((n, 2))
    running = np.empty(n, dtype=np.bool_)
    for i in range(n):
        fresh = time_s - command_time_s[i] <= command_timeout_s
        active[i, 0] = command[i, 0] if fresh else 0.0
        active[i, 1] = command[i, 1] if fresh else 0.0
        running[i] = pump_on[i] and time_s - pump_time_s[i] <= pump_timeout_s
    return active, running


@njit(cache=True)
def body_points_kernel(poses: np.ndarray, offset_m: float) -> np.ndarray:  # pragma: no cover
    """(N, 2) the points ``offset_m`` ahead of each robot's centre (behind when negative):
    ``SimEngine.gas_sensor_positions``' operations (``nozzle_positions`` with the offset
    negated: the same values), with the C library's cos and sin (numpy's for float64)."""
    n = poses.shape[0]
    out = np.empty((n, 2))
    for i in range(n):
        out[i, 0] = poses[i, 0] + offset_m * math.cos(poses[i, 2])
        out[i, 1] = poses[i, 1] + offset_m * math.sin(poses[i, 2])
    return out
