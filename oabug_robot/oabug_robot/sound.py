"""The auditory direction: opposite to the resultant of the peers' bearings (paper Sec. II-B).

Each heard peer j gives p_j = (rho_j, theta_j), converted to c_j = rho_j (cos theta_j,
sin theta_j); c_i,opp = -sum_j c_j and its angle theta_opp is the new preferred direction.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from oabug_robot.settings import SoundWeighting

__all__ = ['PeerBearings', 'opposite_direction']

# A resultant shorter than this carries no direction (peers all around cancel out).
_MIN_RESULTANT = 1e-9


class PeerBearings(NamedTuple):
    """The peers heard in one locator cycle (a named tuple: a robot holds a new one every
    cycle, and a tuple is built several times faster than a frozen dataclass).

    Attributes:
        azimuths_rad: (B,) bearing of each peer in the robot frame at reception [rad].
        distances_m: (B,) distance of each peer [m]; NaN where unknown.
        stamp_s: when they were heard [s, node clock].
        yaw_at_stamp_rad: the robot's yaw when they were heard [rad], so bearings can be
            turned into the yaw frame after the robot has rotated.
    """

    azimuths_rad: np.ndarray
    distances_m: np.ndarray
    stamp_s: float
    yaw_at_stamp_rad: float

    def azimuths_now(self, yaw_rad: float) -> np.ndarray:
        """Return (B,) bearings [rad] in the robot frame at yaw ``yaw_rad`` (rotation only)."""
        return self.azimuths_rad + (self.yaw_at_stamp_rad - yaw_rad)

    def near_peers_now(
        self, yaw_rad: float, max_distance_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Bearings [rad] at yaw ``yaw_rad`` and distances [m] of the peers that may be near.

        A peer whose (coarse) distance is known and larger than ``max_distance_m`` is left
        out; one whose distance is unknown (NaN) is kept.
        """
        with np.errstate(invalid='ignore'):
            near = ~(self.distances_m > max_distance_m)
        return self.azimuths_now(yaw_rad)[near], self.distances_m[near]


def opposite_direction(
    azimuths_rad: np.ndarray, distances_m: np.ndarray, weighting: SoundWeighting
) -> float | None:
    """Return theta_opp [rad, same frame as the azimuths], or None when nothing is heard.

    Args:
        azimuths_rad: (B,) peer bearings [rad]; NaN entries are ignored.
        distances_m: (B,) peer distances [m]; with DISTANCE weighting an unknown (NaN, inf or
            non-positive) distance counts as a unit vector.
        weighting: distance-weighted (paper) or unit vectors (the authors' robot).
    """
    azimuths = np.asarray(azimuths_rad, dtype=float)
    keep = np.isfinite(azimuths)
    if not keep.any():
        return None
    azimuths = azimuths[keep]
    if weighting is SoundWeighting.DISTANCE:
        distances = np.asarray(distances_m, dtype=float)[keep]
        weights = np.where(np.isfinite(distances) & (distances > 0.0), distances, 1.0)
    else:
        weights = np.ones_like(azimuths)
    dx = -float(np.dot(weights, np.cos(azimuths)))
    dy = -float(np.dot(weights, np.sin(azimuths)))
    if math.hypot(dx, dy) < _MIN_RESULTANT:
        return None
    return math.atan2(dy, dx)
