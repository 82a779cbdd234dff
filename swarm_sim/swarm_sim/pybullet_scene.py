"""The site as a pybullet scene: box walls, cylinder robots and batched ray tests.

Every wall is a static box over its centre line, as thick as ``wall_thickness_m`` and
reaching half a thickness beyond each free end point (the shape the numpy caster of
:mod:`swarm_sim.geometry` casts against), so the two can be compared on the same geometry;
at junctions the boxes are trimmed so that they do not overlap (:func:`wall_end_reach`).
Robots are upright cylinders. The scene owns one pybullet client (DIRECT, or GUI for a
window), passes its id to every pybullet call and disconnects it on :meth:`close` (or at
the end of a ``with`` block). :mod:`swarm_sim.pybullet_physics` drives the robots; the cross-
check test of the caster uses :meth:`cast_scan` on walls alone.

Walls and robots are in separate collision groups, so that robots can be let pass through
each other while they still hit the walls (and every ray still hits both).
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import weakref
from types import TracebackType
from typing import Any

import numpy as np

from swarm_sim.errors import SimulationError
from swarm_sim.geometry import as_segments, point_segment_distance

__all__ = ['ROBOT_GROUP', 'WALL_GROUP', 'PybulletScene', 'import_pybullet']

# Bullet's own limit on rays per rayTestBatch call.
_MAX_RAYS_PER_BATCH = 16384
# Collision filter groups (bit masks) of the walls and the robots.
WALL_GROUP = 1
ROBOT_GROUP = 2
# Both masks must also hold Bullet's ray group (1, the default filter) for rays to hit.
_ALL_GROUPS = WALL_GROUP | ROBOT_GROUP
_WALL_COLOUR = (0.55, 0.55, 0.6, 1.0)


def import_pybullet() -> Any:
    """The pybullet module.

    Raises:
        SimulationError: pybullet is not installed.
    """
    try:
        import pybullet
    except ImportError as err:
        msg = (
            "pybullet is not installed: pip install 'swarm_sim[pybullet]' (wheels exist only "
            'up to Python 3.11 on x86-64), or use the numpy physics backend'
        )
        raise SimulationError(msg) from err
    return pybullet


def _display_available() -> bool:
    if sys.platform.startswith('linux'):
        return bool(os.environ.get('DISPLAY') or os.environ.get('WAYLAND_DISPLAY'))
    return True


def _disconnect(pybullet: Any, client: int) -> None:
    with contextlib.suppress(pybullet.error):  # already gone
        pybullet.disconnect(physicsClientId=client)


def wall_end_reach(walls: np.ndarray, half_thickness_m: float) -> np.ndarray:
    """(M, 2) how far each wall's box reaches beyond its start and end point [m].

    A free end, or a corner with a wall in another direction, reaches half a thickness
    beyond the end point (the box the numpy caster casts against, corners filled). Where an
    end meets the interior of another wall (a T-junction), the box stops at that wall's face;
    where it meets a collinear wall's end, at the joint. So boxes overlap only in corners,
    and a path through a junction passes through the walls its centre lines cross.
    """
    m = len(walls)
    reach = np.full((m, 2), half_thickness_m)
    if m < 2:
        return reach
    ends = np.concatenate([walls[:, 0], walls[:, 1]])  # (2M, 2): starts, then ends
    owner = np.concatenate([np.arange(m), np.arange(m)])
    direction = walls[:, 1] - walls[:, 0]
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    on_wall = point_segment_distance(ends, walls) < 1e-6
    on_wall[np.arange(2 * m), owner] = False
    for k, j in zip(*np.nonzero(on_wall), strict=True):
        i = owner[k]
        sine = abs(float(direction[i, 0] * direction[j, 1] - direction[i, 1] * direction[j, 0]))
        at_end = min(np.hypot(*(ends[k] - walls[j, 0])), np.hypot(*(ends[k] - walls[j, 1])))
        side = 0 if k < m else 1
        if at_end >= 1e-6 and sine > 1e-6:
            # T-junction: stop at the other wall's face.
            reach[i, side] = min(reach[i, side], -half_thickness_m / sine)
        elif at_end < 1e-6 and sine <= 1e-6:
            reach[i, side] = min(reach[i, side], 0.0)
    return reach


def yaw_quaternion(yaw_rad: float) -> list[float]:
    """Quaternion x, y, z, w of a rotation by ``yaw_rad`` about z."""
    return [0.0, 0.0, math.sin(0.5 * yaw_rad), math.cos(0.5 * yaw_rad)]


class PybulletScene:
    """Static box walls (and robot cylinders once added) in a private pybullet client."""

    def __init__(
        self,
        walls: np.ndarray,
        *,
        wall_thickness_m: float,
        wall_height_m: float = 0.3,
        sensor_height_m: float = 0.1,
        gui: bool = False,
        visuals: bool = False,
    ) -> None:
        """Connect a client and build the walls.

        Args:
            walls: (M, 2, 2) wall centre lines [m].
            wall_thickness_m: wall thickness [m] (0 is built 0.1 mm thick).
            wall_height_m: wall height [m].
            sensor_height_m: height of every ray [m].
            gui: open pybullet's window (needs a display) instead of a DIRECT client.
            visuals: give every body a visual shape (for the window and camera images).

        Raises:
            SimulationError: pybullet is missing, no display for ``gui``, or no client.
        """
        pybullet = import_pybullet()
        self._p = pybullet
        if gui and not _display_available():
            msg = 'the pybullet window needs a display (DISPLAY is not set): render frames instead'
            raise SimulationError(msg)
        self._client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self._client < 0:
            msg = f'could not start a pybullet {"GUI" if gui else "DIRECT"} client'
            raise SimulationError(msg)
        self._finalizer = weakref.finalize(self, _disconnect, pybullet, self._client)
        self.gui = gui
        self.visuals = visuals or gui
        self.sensor_height_m = float(sensor_height_m)
        self.walls = as_segments(walls)
        self.wall_bodies: list[int] = []
        self.robot_bodies: list[int] = []
        half_t = 0.5 * max(wall_thickness_m, 1e-4)
        c = self._client
        reach = wall_end_reach(self.walls, half_t)
        for (a, b), (reach_a, reach_b) in zip(self.walls, reach, strict=True):
            length = float(np.hypot(*(b - a)))
            direction = (b - a) / length
            # The box spans the centre line from reach_a before a to reach_b beyond b.
            a = a - reach_a * direction
            b = b + reach_b * direction
            extents = [0.5 * (length + reach_a + reach_b), half_t, 0.5 * wall_height_m]
            shape = pybullet.createCollisionShape(
                pybullet.GEOM_BOX, halfExtents=extents, physicsClientId=c
            )
            visual = -1
            if self.visuals:
                visual = pybullet.createVisualShape(
                    pybullet.GEOM_BOX,
                    halfExtents=extents,
                    rgbaColor=_WALL_COLOUR,
                    physicsClientId=c,
                )
            centre = 0.5 * (a + b)
            body = pybullet.createMultiBody(
                baseMass=0.0,
                baseCollisionShapeIndex=shape,
                baseVisualShapeIndex=visual,
                basePosition=[float(centre[0]), float(centre[1]), 0.5 * wall_height_m],
                baseOrientation=yaw_quaternion(math.atan2(b[1] - a[1], b[0] - a[0])),
                physicsClientId=c,
            )
            pybullet.setCollisionFilterGroupMask(
                body, -1, WALL_GROUP, _ALL_GROUPS, physicsClientId=c
            )
            self.wall_bodies.append(body)

    @property
    def client(self) -> int:
        """The pybullet physics client id (-1 once closed)."""
        return self._client

    @property
    def pybullet(self) -> Any:
        """The pybullet module."""
        return self._p

    def add_robots(
        self,
        poses: np.ndarray,
        *,
        radius_m: float,
        height_m: float,
        mass_kg: float,
        friction: float,
        collide: bool = True,
        colours: list[tuple[float, float, float, float]] | None = None,
    ) -> list[int]:
        """Add one upright cylinder per (N, 3) pose, standing on z = 0; return their ids.

        The cylinders turn only about z (their inertia about x and y is infinite), have no
        damping and no restitution; ``friction`` is their contact friction coefficient
        (against walls; between robots its square). ``collide`` False lets the robots
        pass through each other (they still hit walls, and rays still hit them).
        """
        p, c = self._p, self._client
        shape = p.createCollisionShape(
            p.GEOM_CYLINDER, radius=radius_m, height=height_m, physicsClientId=c
        )
        inertia_z = 0.5 * mass_kg * radius_m**2
        bodies = []
        for i, (x, y, yaw) in enumerate(np.asarray(poses, dtype=float)):
            visual = -1
            if self.visuals:
                colour = colours[i % len(colours)] if colours else (0.2, 0.4, 0.9, 1.0)
                visual = p.createVisualShape(
                    p.GEOM_CYLINDER,
                    radius=radius_m,
                    length=height_m,
                    rgbaColor=colour,
                    physicsClientId=c,
                )
            body = p.createMultiBody(
                baseMass=mass_kg,
                baseCollisionShapeIndex=shape,
                baseVisualShapeIndex=visual,
                basePosition=[float(x), float(y), 0.5 * height_m],
                baseOrientation=yaw_quaternion(float(yaw)),
                useMaximalCoordinates=True,
                physicsClientId=c,
            )
            # The mass must be given with the inertia, else pybullet's body turns to NaN.
            p.changeDynamics(
                body,
                -1,
                mass=mass_kg,
                localInertiaDiagonal=[0.0, 0.0, inertia_z],
                lateralFriction=friction,
                spinningFriction=0.0,
                rollingFriction=0.0,
                restitution=0.0,
                linearDamping=0.0,
                angularDamping=0.0,
                physicsClientId=c,
            )
            mask = _ALL_GROUPS if collide else WALL_GROUP
            p.setCollisionFilterGroupMask(body, -1, ROBOT_GROUP, mask, physicsClientId=c)
            bodies.append(body)
        for wall in self.wall_bodies:
            # Bullet multiplies the two bodies' coefficients.
            p.changeDynamics(wall, -1, lateralFriction=1.0, physicsClientId=c)
        self.robot_bodies.extend(bodies)
        return bodies

    def _ray_batches(
        self, starts: np.ndarray, ends: np.ndarray, **options: Any
    ) -> list[tuple[Any, ...]]:
        """rayTestBatch results of (K, 3) starts and ends, in batches Bullet accepts."""
        hits: list[tuple[Any, ...]] = []
        for lo in range(0, len(starts), _MAX_RAYS_PER_BATCH):
            hits.extend(
                self._p.rayTestBatch(
                    starts[lo : lo + _MAX_RAYS_PER_BATCH].tolist(),
                    ends[lo : lo + _MAX_RAYS_PER_BATCH].tolist(),
                    numThreads=1,
                    physicsClientId=self._client,
                    **options,
                )
            )
        return hits

    def _lift(self, xy: np.ndarray) -> np.ndarray:
        """(K, 2) points [m] at sensor height as (K, 3)."""
        out = np.empty((len(xy), 3))
        out[:, :2] = xy
        out[:, 2] = self.sensor_height_m
        return out

    def scan(self, poses: np.ndarray, bin_angles_rad: np.ndarray, max_range_m: float) -> np.ndarray:
        """(N, B) ranges [m] from each (N, 3) pose's centre along the robot-frame angles;
        ``inf`` where nothing is hit within ``max_range_m``. A ray ignores the body it
        starts in (the robot's own cylinder)."""
        poses = np.asarray(poses, dtype=float)
        n, nb = len(poses), len(bin_angles_rad)
        if n == 0:
            return np.zeros((0, nb))
        angles = (poses[:, 2, None] + np.asarray(bin_angles_rad, dtype=float)[None, :]).ravel()
        origins = np.repeat(poses[:, :2], nb, axis=0)
        ends = origins + max_range_m * np.column_stack([np.cos(angles), np.sin(angles)])
        hits = self._ray_batches(self._lift(origins), self._lift(ends))
        fraction = np.array([h[2] if h[0] >= 0 else math.inf for h in hits])
        return (fraction * max_range_m).reshape(n, nb)

    def cast_scan(
        self, pose: np.ndarray, bin_angles_rad: np.ndarray, max_range_m: float
    ) -> np.ndarray:
        """Ranges [m] along the robot-frame angles from one ``pose`` (x, y, yaw); inf if no
        hit: :meth:`scan` of one robot."""
        return self.scan(np.asarray(pose, dtype=float)[None, :], bin_angles_rad, max_range_m)[0]

    def close(self) -> None:
        """Disconnect the pybullet client (idempotent)."""
        if self._client >= 0:
            self._finalizer()
            self._client = -1

    def __enter__(self) -> PybulletScene:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
