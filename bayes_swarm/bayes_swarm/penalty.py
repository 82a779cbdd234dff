"""Local penalty of Bayes-Swarm-P (paper Eqs. 8-11).

For a peer's planned waypoint x_p the exclusion ball has a Gaussian radius with mean
(M - mu(x_p)) / L and std sigma(x_p) / L, so

    gamma(x, x_p) = 0.5 * erfc(-(L |x - x_p| - M + mu(x_p)) / (sqrt(2) sigma(x_p)))

is the probability that x lies outside the ball, and Gamma(x) is the product over peers.
Gamma is near 0 at a peer's waypoint whose belief is well below M and tends to 1 far away.

:func:`log_local_penalty` is log Gamma, computed factor by factor with ``log_ndtr`` so that it
stays finite and informative where the product underflows (many peers, large balls): the
form GPyOpt's local penalization maximises (log acquisition plus the log penalizers).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import erfc, log_ndtr

__all__ = ['local_penalty', 'log_local_penalty']


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
    z = _arguments(
        points_m, peer_waypoints_m, peer_mean, peer_std, max_signal, lipschitz, std_floor
    )
    return np.prod(0.5 * erfc(-z), axis=1)


def log_local_penalty(
    points_m: np.ndarray,
    peer_waypoints_m: np.ndarray,
    peer_mean: np.ndarray,
    peer_std: np.ndarray,
    *,
    max_signal: float,
    lipschitz: float,
    std_floor: float = 1e-3,
) -> np.ndarray:
    """log Gamma (q,) at (q, 2) points, finite where Gamma underflows.

    The arguments are those of :func:`local_penalty`.
    """
    z = _arguments(
        points_m, peer_waypoints_m, peer_mean, peer_std, max_signal, lipschitz, std_floor
    )
    return np.sum(log_ndtr(math.sqrt(2.0) * z), axis=1)


def _arguments(
    points_m: np.ndarray,
    peer_waypoints_m: np.ndarray,
    peer_mean: np.ndarray,
    peer_std: np.ndarray,
    max_signal: float,
    lipschitz: float,
    std_floor: float,
) -> np.ndarray:
    """z (q, p) of every point and peer: gamma = 0.5 erfc(-z) = Phi(sqrt(2) z)."""
    pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
    peers = np.asarray(peer_waypoints_m, dtype=float).reshape(-1, 2)
    dist = np.hypot(pts[:, None, 0] - peers[None, :, 0], pts[:, None, 1] - peers[None, :, 1])
    std = np.maximum(np.asarray(peer_std, dtype=float), std_floor)
    return (lipschitz * dist - max_signal + np.asarray(peer_mean, dtype=float)) / (
        math.sqrt(2.0) * std
    )
