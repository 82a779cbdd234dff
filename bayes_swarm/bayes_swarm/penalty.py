"""Local penalty of Bayes-Swarm-P (paper Eqs. 8-11).

For a peer's planned waypoint x_p the exclusion ball has a Gaussian radius with mean
(M - mu(x_p)) / L and std sigma(x_p) / L, so

    gamma(x, x_p) = 0.5 * erfc(-(L |x - x_p| - M + mu(x_p)) / (sqrt(2) sigma(x_p)))

is the probability that x lies outside the ball, and Gamma(x) is the product over peers.
Gamma is near 0 at a peer's waypoint whose belief is well below M and tends to 1 far away.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import erfc

__all__ = ['local_penalty']


def local_penalty(
    points_m: np.ndarray,
    peer_waypoints_m: np.ndarray,
    peer_mean: np.ndarray,
    peer_std: np.ndarray,
    *,
    max_signal: float,
    lipschitz: float,
    std_floor: float = 1e-3,
) -> np.ndarray:
    """Gamma (q,) of Eq. 11 at (q, 2) points.

    Args:
        points_m: (q, 2) candidate waypoints [m].
        peer_waypoints_m: (p, 2) peers' planned next waypoints [m].
        peer_mean: (p,) GP mean at the peers' waypoints.
        peer_std: (p,) GP std at the peers' waypoints; values below ``std_floor`` are raised
            to it so the factor stays a smooth function.
        max_signal: M, the maximum signal strength.
        lipschitz: L, a Lipschitz constant of the signal [signal / m].
    """
    pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
    peers = np.asarray(peer_waypoints_m, dtype=float).reshape(-1, 2)
    if peers.shape[0] == 0:
        return np.ones(pts.shape[0])
    dist = np.hypot(pts[:, None, 0] - peers[None, :, 0], pts[:, None, 1] - peers[None, :, 1])
    std = np.maximum(np.asarray(peer_std, dtype=float), std_floor)
    z = (lipschitz * dist - max_signal + np.asarray(peer_mean, dtype=float)) / (
        math.sqrt(2.0) * std
    )
    return np.prod(0.5 * erfc(-z), axis=1)
