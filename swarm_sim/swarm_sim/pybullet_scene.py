"""The same walls as a pybullet scene (DIRECT mode): cross-checks and an alternative ray backend.

The numpy caster in :mod:`swarm_sim.geometry` is what the bridge uses by default because it
is much faster for 2D scans (docs/simulation.md has the measurement). This scene builds every
wall as a thin static box and casts rays with ``rayTestBatch``, so the two can be compared
on the same geometry. The physics client id is passed to every pybullet call, and the
client is disconnected on :meth:`close` (or at the end of a ``with`` block).
"""

from __future__ import annotations

import math
from types import TracebackType

import numpy as np

from swarm_sim.errors import SimulationError
from swarm_sim.geometry import as_segments

__all__ = ['PybulletScene']

# Bullet's own limit on rays per rayTestBatch call.
_MAX_RAYS_PER_BATCH = 16384


class PybulletScene:
    """Static thin-box walls in a private pybullet DIRECT client."""

    def __init__(
        self,
        walls: np.ndarray,
        *,
        wall_thickness_m: float,
        wall_height_m: float = 0.3,
        sensor_height_m: float = 0.1,
    ) -> None:
        try:
            import pybullet
        except ImportError as err:
            msg = 'pybullet is not installed (it belongs to the simulation install only)'
            raise SimulationError(msg) from err
        self._p = pybullet
        self._client = pybullet.connect(pybullet.DIRECT)
        if self._client < 0:
            raise SimulationError('could not start a pybullet DIRECT client')
        self._sensor_height_m = sensor_height_m
        half_t = 0.5 * max(wall_thickness_m, 1e-4)
        for a, b in as_segments(walls):
            length = float(np.hypot(*(b - a)))
            shape = pybullet.createCollisionShape(
                pybullet.GEOM_BOX,
                halfExtents=[0.5 * length + half_t, half_t, 0.5 * wall_height_m],
                physicsClientId=self._client,
            )
            centre = 0.5 * (a + b)
            yaw = math.atan2(b[1] - a[1], b[0] - a[0])
            pybullet.createMultiBody(
                baseMass=0.0,
                baseCollisionShapeIndex=shape,
                basePosition=[float(centre[0]), float(centre[1]), 0.5 * wall_height_m],
                baseOrientation=pybullet.getQuaternionFromEuler([0.0, 0.0, yaw]),
                physicsClientId=self._client,
            )

    def cast_scan(
        self, pose: np.ndarray, bin_angles_rad: np.ndarray, max_range_m: float
    ) -> np.ndarray:
        """Ranges [m] along the robot-frame angles from ``pose`` (x, y, yaw); inf if no hit."""
        angles = pose[2] + np.asarray(bin_angles_rad, dtype=float)
        origin = [float(pose[0]), float(pose[1]), self._sensor_height_m]
        out = np.full(len(angles), np.inf)
        for start in range(0, len(angles), _MAX_RAYS_PER_BATCH):
            chunk = angles[start : start + _MAX_RAYS_PER_BATCH]
            ends = [
                [origin[0] + max_range_m * c, origin[1] + max_range_m * s, origin[2]]
                for c, s in zip(np.cos(chunk), np.sin(chunk), strict=True)
            ]
            hits = self._p.rayTestBatch(
                [origin] * len(chunk), ends, numThreads=1, physicsClientId=self._client
            )
            for k, hit in enumerate(hits):
                if hit[0] >= 0:
                    out[start + k] = hit[2] * max_range_m
        return out

    def close(self) -> None:
        """Disconnect the pybullet client (idempotent)."""
        if self._client >= 0:
            self._p.disconnect(physicsClientId=self._client)
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
