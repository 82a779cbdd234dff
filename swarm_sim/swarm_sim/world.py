"""The simulated world: static walls and disc robots driven as kinematic unicycles.

The world is ROS-free and deterministic. It integrates every robot's commanded forward speed
and yaw rate (clipped to the body's limits) once per physics step and resolves collisions the
way a real base pressing against an obstacle behaves: a robot whose move would bring its disc
into a wall or another robot keeps its rotation but does not translate. Robots are updated in
bridge order (r0 first), so later robots see the already-moved earlier ones.

Geometry queries (lidar rays, wall crossings) go through :mod:`swarm_sim.geometry`; a pybullet
scene of the same walls and bodies is available for cross-checks and as an alternative ray
backend (:mod:`swarm_sim.pybullet_scene`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError, WorldGeometryError
from swarm_sim.geometry import WallGrid, as_segments
from swarm_sim.world_kernel import world_step_kernel

__all__ = ['BodyConfig', 'World']


@dataclass(frozen=True)
class BodyConfig:
    """Robot body and drive limits shared by every robot.

    Attributes:
        robot_radius_m: radius of the robot's disc [m] (the paper's robots are 0.2 m wide).
        wall_thickness_m: thickness of every wall [m] (the authors' simulator: 2.5 cm).
        max_linear_speed_mps: forward speed limit [m/s]; reverse is limited the same.
        max_angular_speed_radps: yaw rate limit [rad/s].
    """

    robot_radius_m: float = parameter(0.1, 'Radius of every robot disc.', unit='m', gt=0.0)
    wall_thickness_m: float = parameter(0.025, 'Thickness of every wall.', unit='m', ge=0.0)
    max_linear_speed_mps: float = parameter(0.5, 'Forward speed limit.', unit='m/s', gt=0.0)
    max_angular_speed_radps: float = parameter(2.0, 'Yaw rate limit.', unit='rad/s', gt=0.0)

    def __post_init__(self) -> None:
        for name in ('robot_radius_m', 'max_linear_speed_mps', 'max_angular_speed_radps'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigurationError(msg)
        if not (math.isfinite(self.wall_thickness_m) and self.wall_thickness_m >= 0.0):
            msg = f'wall_thickness_m must be >= 0, got {self.wall_thickness_m!r}'
            raise ConfigurationError(msg)


class World:
    """Walls plus N disc robots; owns the true state of every robot."""

    def __init__(
        self, walls: np.ndarray, initial_poses: np.ndarray, body: BodyConfig | None = None
    ) -> None:
        """Build the world.

        Args:
            walls: (M, 2, 2) wall centre lines [m].
            initial_poses: (N, 3) x [m], y [m], yaw [rad] of every robot.
            body: body and drive limits; defaults to :class:`BodyConfig`.
        """
        self.body = body or BodyConfig()
        self.walls = as_segments(walls)
        poses = np.array(initial_poses, dtype=float)
        if poses.ndim != 2 or poses.shape[1] != 3 or len(poses) == 0:
            msg = f'initial_poses must have shape (N, 3) with N >= 1, got {poses.shape}'
            raise WorldGeometryError(msg)
        if not np.all(np.isfinite(poses)):
            raise WorldGeometryError('initial_poses contain NaN or inf')
        poses[:, 2] = wrap_angle(poses[:, 2])
        self._poses = poses
        self._velocities = np.zeros((len(poses), 2))
        self._wall_clearance_m = self.body.robot_radius_m + 0.5 * self.body.wall_thickness_m
        self.collision_count = np.zeros(len(poses), dtype=int)
        self._clearance_cache: np.ndarray | None = None
        self._limits = np.array([self.body.max_linear_speed_mps, self.body.max_angular_speed_radps])
        self._walls_near = WallGrid(self.walls, cell_m=0.5, reach_m=2.0 * self._wall_clearance_m)
        self._no_clearance = np.zeros(len(poses))

    def _wall_clearance(self) -> np.ndarray:
        """(N,) distance [m] from each robot centre to the nearest wall centre line (exact
        up to twice the contact clearance; only smaller values decide a move)."""
        if self._clearance_cache is None:
            self._clearance_cache = self._walls_near.nearest_distance(self._poses[:, :2])
        return self._clearance_cache

    @property
    def num_robots(self) -> int:
        """Number of robots N."""
        return len(self._poses)

    @property
    def poses(self) -> np.ndarray:
        """(N, 3) copy of the true poses: x [m], y [m], yaw [rad] in (-pi, pi]."""
        return self._poses.copy()

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) achieved forward speed [m/s] and yaw rate [rad/s] of the last step."""
        return self._velocities.copy()

    def clip_commands(self, commands: np.ndarray) -> np.ndarray:
        """Clip (N, 2) commands (speed [m/s], yaw rate [rad/s]) to the drive limits.

        Non-finite commands become zero (a base driver ignores garbage and stops).
        """
        cmd = np.array(commands, dtype=float).reshape(self.num_robots, 2)
        bad = ~np.isfinite(cmd)
        if bad.any():
            cmd[bad] = 0.0
        return np.clip(cmd, -self._limits, self._limits, out=cmd)

    def step(self, commands: np.ndarray, dt_s: float) -> None:
        """Advance every robot by ``dt_s`` seconds under (N, 2) velocity commands.

        The unicycle is integrated exactly (arc of constant curvature). A move that would end
        closer to a wall or another robot than contact distance, and closer than before, is
        cancelled (the robot still turns). Runs the compiled step
        (:func:`swarm_sim.world_kernel.world_step_kernel`), bit-identical to
        :meth:`step_reference`.
        """
        cmd = np.array(commands, dtype=float).reshape(self.num_robots, 2)
        cache = self._clearance_cache
        after, computed = world_step_kernel(
            self._poses,
            cmd,
            float(self._limits[0]),
            float(self._limits[1]),
            float(dt_s),
            self._wall_clearance_m,
            2.0 * self.body.robot_radius_m,
            len(self.walls) > 0,
            self._no_clearance if cache is None else cache,
            cache is not None,
            self.collision_count,
            self._velocities,
            self._walls_near.kernel_arguments(),
        )
        if computed:
            self._clearance_cache = after

    def step_reference(self, commands: np.ndarray, dt_s: float) -> None:
        """:meth:`step` in numpy, the reference of the compiled step."""
        cmd = self.clip_commands(commands)
        v = cmd[:, 0]
        w = cmd[:, 1]
        yaw = self._poses[:, 2]
        new_yaw = yaw + w * dt_s
        small = np.abs(w) < 1e-9
        safe_w = np.where(small, 1.0, w)
        cos_yaw, sin_yaw = np.cos(yaw), np.sin(yaw)
        dx = np.where(small, v * dt_s * cos_yaw, v / safe_w * (np.sin(new_yaw) - sin_yaw))
        dy = np.where(small, v * dt_s * sin_yaw, -v / safe_w * (np.cos(new_yaw) - cos_yaw))
        old_xy = self._poses[:, :2]
        cand_xy = old_xy + np.column_stack([dx, dy])
        moves = (dx != 0.0) | (dy != 0.0)
        allowed = moves.copy()
        new_clear = None
        if len(self.walls) and moves.any():
            new_clear = self._walls_near.nearest_distance(cand_xy)
            old_clear = self._wall_clearance()
            blocked = (new_clear < self._wall_clearance_m) & (new_clear < old_clear)
            allowed &= ~blocked
        final_xy = old_xy.copy()
        contact = 2.0 * self.body.robot_radius_m
        # Only robots that may touch another after this step need the sequential check.
        gap = np.hypot(*(cand_xy[:, None, :] - old_xy[None, :, :]).transpose(2, 0, 1))
        step_len = np.hypot(dx, dy)
        np.fill_diagonal(gap, np.inf)
        close = (gap < contact + step_len.max() + 1e-9).any(axis=1)
        quiet = allowed & ~close
        final_xy[quiet] = cand_xy[quiet]
        for i in np.flatnonzero(allowed & close).tolist():
            # Distances to the others (the robot itself set to inf), as they stand now.
            new_d = np.hypot(*(final_xy - cand_xy[i]).T)
            old_d = np.hypot(*(final_xy - old_xy[i]).T)
            new_d[i] = old_d[i] = np.inf
            if new_d.min() < contact and new_d.min() < old_d.min():
                allowed[i] = False
                continue
            final_xy[i] = cand_xy[i]
        self.collision_count += moves & ~allowed
        self._poses[:, :2] = final_xy
        self._poses[:, 2] = wrap_angle(new_yaw)
        if new_clear is not None:
            # The distance of a point does not depend on the others: reuse it.
            self._clearance_cache = np.where(allowed, new_clear, self._wall_clearance())
        achieved_v = np.where(allowed, v, 0.0)
        self._velocities = np.column_stack([achieved_v, w])
