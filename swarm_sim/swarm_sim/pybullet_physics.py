"""The pybullet physics backend: rigid cylinder robots among box walls, pybullet's contacts.

How the robots are driven (velocity-driven dynamic bodies): every robot is a dynamic
cylinder of ``PybulletConfig.robot_mass_kg`` that turns only about z (infinite inertia about
x and y) in a world without gravity or floor. At every pybullet step (``substeps`` of them
per engine step, a whole number, so the engine's period is exactly ``substeps`` pybullet
steps) each robot's base velocity is set to its clipped command: forward speed along its
heading (at the middle of that step, so free motion follows the unicycle's arc) and the
commanded yaw rate. pybullet's solver then resolves the contacts:
a robot driving into a wall stops at its face, one pressed against a wall at an angle slides
along it (contacts are frictionless by default), and a robot driving into another pushes it
(their masses share the motion). Resetting the velocity at every step means contact impulses
never accumulate into bounces or spin, so the motion stays stable with the default solver
(penetrations under 1 mm at 0.5 m/s and 10 substeps); z and tilt cannot drift through the
contacts, whose normals stay horizontal, and are put back should they move by more than
0.1 mm. A kinematic body (pose set each step, contacts only detected) was not chosen: it
would leave the contact resolution to this code, which is what the numpy backend already is.

The lidar's rays go through ``rayTestBatch`` of the same client
(:class:`swarm_sim.pybullet_scene.PybulletScene`); the bearing model and the scent field
count the walls on their paths on the wall centre lines themselves, as with the numpy
backend. The run is deterministic: the client is private to the backend, and pybullet in
DIRECT mode gives equal results for equal calls.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
from swarm_common.angles import wrap_angle

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import as_segments
from swarm_sim.physics import PhysicsSetup
from swarm_sim.pybullet_render import FrameRecorder, place_gui_camera, robot_colours
from swarm_sim.pybullet_scene import PybulletScene, yaw_quaternion
from swarm_sim.world import checked_poses

__all__ = ['PybulletPhysics']

# z or tilt drift that is put back (never reached in the tests; a safeguard) [m], [rad].
_PLANE_TOLERANCE = 1e-4


class PybulletPhysics:
    """N robots and the walls in a private pybullet client (see the module docstring)."""

    def __init__(self, setup: PhysicsSetup) -> None:
        """Build the scene and the robots.

        Raises:
            SimulationError: pybullet is not installed, or the window has no display.
            WorldGeometryError: malformed walls or start poses.
        """
        cfg = setup.pybullet
        body = setup.body
        self.config = cfg
        self.body = body
        self.walls = as_segments(setup.walls)
        poses = checked_poses(setup.initial_poses)
        render = setup.render
        self._scene = PybulletScene(
            self.walls,
            wall_thickness_m=body.wall_thickness_m,
            wall_height_m=cfg.wall_height_m,
            sensor_height_m=cfg.sensor_height_m,
            gui=render.mode == 'gui',
            visuals=render.mode != 'none',
        )
        p, c = self._scene.pybullet, self._scene.client
        self._p, self._c = p, c
        p.setGravity(0.0, 0.0, 0.0, physicsClientId=c)
        self._period_s = 0.0
        self._set_period(setup.physics_period_s)
        p.setPhysicsEngineParameter(numSolverIterations=cfg.solver_iterations, physicsClientId=c)
        self._bodies = self._scene.add_robots(
            poses,
            radius_m=body.robot_radius_m,
            height_m=cfg.robot_height_m,
            mass_kg=cfg.robot_mass_kg,
            friction=cfg.contact_friction,
            collide=cfg.robot_contacts,
            colours=robot_colours(len(poses)) if render.mode != 'none' else None,
        )
        self._z_m = 0.5 * cfg.robot_height_m
        self._poses = poses
        self._velocities = np.zeros((len(poses), 2))
        self.collision_count = np.zeros(len(poses), dtype=int)
        self._limits = np.array([body.max_linear_speed_mps, body.max_angular_speed_radps])
        self.num_bins = setup.scan_bins or 0
        self._bin_angles = -math.pi + 2.0 * math.pi / max(self.num_bins, 1) * np.arange(
            self.num_bins
        )
        self._render = render
        # The animation written by close() when frames are recorded.
        self.gif_path: Path | None = None
        self._time_s = 0.0
        self._recorder: FrameRecorder | None = None
        self._next_frame_s = 0.0
        self._wall_start_s = time.perf_counter()
        if render.mode == 'gui':
            place_gui_camera(p, c, self.walls)
        elif render.mode == 'frames':
            assert render.frames_dir is not None
            self._recorder = FrameRecorder(
                p,
                c,
                self.walls,
                render.frames_dir,
                width_px=render.width_px,
                height_px=render.height_px,
                gif_frame_s=render.gif_frame_s,
            )
            self._capture()

    def _set_period(self, period_s: float) -> None:
        if not (math.isfinite(period_s) and period_s > 0.0):
            msg = f'the physics step must be positive, got {period_s!r}'
            raise ConfigurationError(msg)
        if period_s != self._period_s:
            self._period_s = period_s
            self._p.setPhysicsEngineParameter(
                fixedTimeStep=period_s / self.config.substeps, physicsClientId=self._c
            )

    @property
    def client(self) -> int:
        """The pybullet physics client id of this backend (-1 once closed)."""
        return self._scene.client

    @property
    def robot_bodies(self) -> list[int]:
        """pybullet body ids of the robots, in robot order."""
        return list(self._bodies)

    @property
    def num_robots(self) -> int:
        """Number of robots N."""
        return len(self._poses)

    @property
    def poses(self) -> np.ndarray:
        """(N, 3) copy of the true poses x [m], y [m], yaw [rad] in (-pi, pi]."""
        return self._poses.copy()

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) forward speed [m/s] and yaw rate [rad/s] achieved over the last step."""
        return self._velocities.copy()

    def _clip(self, commands: np.ndarray) -> np.ndarray:
        cmd = np.array(commands, dtype=float).reshape(self.num_robots, 2)
        cmd[~np.isfinite(cmd)] = 0.0
        return np.clip(cmd, -self._limits, self._limits, out=cmd)

    def step(self, commands: np.ndarray, dt_s: float) -> None:
        """Advance ``dt_s`` (``substeps`` pybullet steps) under (N, 2) commands."""
        self._set_period(float(dt_s))
        cmd = self._clip(commands)
        p, c, bodies = self._p, self._c, self._bodies
        before = self._poses.copy()
        speeds = cmd[:, 0].tolist()
        yaw_rates = cmd[:, 1].tolist()
        yaws = before[:, 2].tolist()
        # Each pybullet step moves along the heading of its middle (the chord of the arc).
        half_turns = (0.5 * dt_s / self.config.substeps * cmd[:, 1]).tolist()
        for sub in range(self.config.substeps):
            for i, body in enumerate(bodies):
                v = speeds[i]
                if v != 0.0 and sub > 0:
                    _, (qx, qy, qz, qw) = p.getBasePositionAndOrientation(body, physicsClientId=c)
                    yaws[i] = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
                yaw = yaws[i] + half_turns[i]
                p.resetBaseVelocity(
                    body,
                    linearVelocity=[v * math.cos(yaw), v * math.sin(yaw), 0.0],
                    angularVelocity=[0.0, 0.0, yaw_rates[i]],
                    physicsClientId=c,
                )
            p.stepSimulation(physicsClientId=c)
        self._read_poses()
        self._time_s += dt_s
        moved = self._poses[:, :2] - before[:, :2]
        turn = wrap_angle(self._poses[:, 2] - before[:, 2])
        mid = before[:, 2] + 0.5 * turn
        self._velocities[:, 0] = (moved[:, 0] * np.cos(mid) + moved[:, 1] * np.sin(mid)) / dt_s
        self._velocities[:, 1] = turn / dt_s
        touching = {
            body
            for contact in p.getContactPoints(physicsClientId=c)
            if contact[8] <= 0.0
            for body in (contact[1], contact[2])
        }
        for i, body in enumerate(bodies):
            if body in touching:
                self.collision_count[i] += 1
        self._after_step()

    def _read_poses(self) -> None:
        p, c = self._p, self._c
        for i, body in enumerate(self._bodies):
            (x, y, z), (qx, qy, qz, qw) = p.getBasePositionAndOrientation(body, physicsClientId=c)
            yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
            if abs(z - self._z_m) > _PLANE_TOLERANCE or max(abs(qx), abs(qy)) > _PLANE_TOLERANCE:
                p.resetBasePositionAndOrientation(
                    body, [x, y, self._z_m], yaw_quaternion(yaw), physicsClientId=c
                )
            self._poses[i] = (x, y, yaw)
        self._poses[:, 2] = wrap_angle(self._poses[:, 2])

    def _capture(self) -> None:
        assert self._recorder is not None
        self._recorder.capture(self._time_s)
        self._next_frame_s += 1.0 / self._render.frame_rate_hz

    def _after_step(self) -> None:
        if self._recorder is not None and self._time_s + 1e-9 >= self._next_frame_s:
            self._capture()
        rtf = self._render.gui_real_time_factor
        if self._render.mode == 'gui' and rtf > 0.0:
            ahead_s = self._time_s / rtf - (time.perf_counter() - self._wall_start_s)
            if ahead_s > 0.0:
                time.sleep(ahead_s)

    def scan(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """(N, num_bins) ranges [m] by ``rayTestBatch`` from the robots' centres at sensor
        height; ``inf`` where no wall or other robot is within ``max_range_m``."""
        if self.num_bins == 0:
            raise ConfigurationError('this physics backend was built without a lidar')
        return self._scene.scan(poses, self._bin_angles, max_range_m)

    def close(self) -> None:
        """Write the GIF of the frames (if recording) and disconnect the client."""
        if self._recorder is not None:
            self.gif_path = self._recorder.finish()
            self._recorder = None
        self._scene.close()
