"""Terms of the Bayes-Swarm acquisition function (paper Eqs. 1, 4, 6, 7).

* Source seeking, Eq. 4: ``omega(x) = 1 / (1 + |x - x_star|^2)``.
* Exploration, Eqs. 6-7: the integral of the (extended) posterior std along the straight
  path from the robot's position to the candidate. We integrate with respect to arc length
  (``ds = l du``), so the value is in signal * m and grows with the information a longer leg
  collects; this is what the authors' code computes. The path is discretised at the
  observation spacing V / f_Hz and integrated with the trapezoidal rule.
* The combination, Eq. 1: ``(alpha * omega + (1 - alpha) * sigma) * gamma``.

All functions are vectorised over candidates; ``std_fn`` maps (q, 2) points to (q,) stds.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = [
    'StdFunction',
    'acquisition',
    'omega',
    'path_integral',
    'path_points',
    'planned_path_points',
    'ray_integrals',
]

StdFunction = Callable[[np.ndarray], np.ndarray]


def omega(
    points_m: np.ndarray, expected_source_m: np.ndarray, distance_unit_m: float = 1.0
) -> np.ndarray:
    """Source-seeking term (q,) of Eq. 4 at (q, 2) points for the expected source (2,).

    Distances are measured in ``distance_unit_m`` (the paper: metres).
    """
    diff = np.asarray(points_m, dtype=float).reshape(-1, 2) - np.asarray(expected_source_m)
    return 1.0 / (1.0 + np.einsum('ij,ij->i', diff, diff) / distance_unit_m**2)


def path_points(
    start_m: np.ndarray, end_m: np.ndarray, step_m: float, *, from_origin: bool = False
) -> np.ndarray:
    """Points of the straight path start -> end at spacing ``step_m``, both ends included.

    Returns a (k, 2) array; the last gap may be shorter than ``step_m``. ``from_origin``
    reproduces the authors' defect: the same offsets measured from (0, 0) instead of from
    ``start_m``.
    """
    start = np.asarray(start_m, dtype=float)
    end = np.asarray(end_m, dtype=float)
    delta = end - start
    length = float(np.hypot(delta[0], delta[1]))
    if length <= 0.0:
        return (np.zeros((1, 2)) if from_origin else start.reshape(1, 2)).copy()
    offsets = np.arange(0.0, length, step_m)
    offsets = np.append(offsets, length) if length - offsets[-1] > 1e-12 else offsets
    base = np.zeros(2) if from_origin else start
    return base + offsets[:, None] * (delta / length)


def path_integral(
    std_fn: StdFunction,
    start_m: np.ndarray,
    end_m: np.ndarray,
    step_m: float,
    *,
    from_origin: bool = False,
) -> float:
    """Eq. 7: integral of the posterior std along the path start -> end [signal * m]."""
    pts = path_points(start_m, end_m, step_m, from_origin=from_origin)
    if pts.shape[0] < 2:
        return 0.0
    std = std_fn(pts)
    seg = np.hypot(*np.diff(pts, axis=0).T)
    return float(0.5 * np.sum(seg * (std[1:] + std[:-1])))


def ray_integrals(
    std_fn: StdFunction,
    start_m: np.ndarray,
    headings_rad: np.ndarray,
    step_m: float,
    n_steps: int,
    *,
    from_origin: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 7 for every candidate on a polar grid around ``start_m``, in one std evaluation.

    Candidates lie on rays at ``headings_rad`` (h,) and distances ``k * step_m``,
    k = 0..n_steps. Paths to all candidates of one ray share their points, so the cumulative
    trapezoid along the ray gives every candidate's integral; the common start point is
    evaluated once.

    Returns:
        candidates: (h, n_steps + 1, 2) array of candidate points [m].
        integrals: (h, n_steps + 1) array of path integrals [signal * m].
    """
    start = np.asarray(start_m, dtype=float)
    radii = step_m * np.arange(n_steps + 1)
    directions = np.stack([np.cos(headings_rad), np.sin(headings_rad)], axis=-1)
    offsets = radii[None, :, None] * directions[:, None, :]
    candidates = start + offsets
    samples = offsets if from_origin else candidates
    n_rays = len(headings_rad)
    values = std_fn(np.vstack([samples[0, :1], samples[:, 1:].reshape(-1, 2)]))
    std = np.empty((n_rays, n_steps + 1))
    std[:, 0] = values[0]
    std[:, 1:] = values[1:].reshape(n_rays, n_steps)
    cumulative = np.zeros_like(std)
    cumulative[:, 1:] = np.cumsum(0.5 * step_m * (std[:, 1:] + std[:, :-1]), axis=1)
    return candidates, cumulative


def planned_path_points(
    starts_m: np.ndarray, ends_m: np.ndarray, step_m: float, max_points: int
) -> np.ndarray:
    """Observation locations peers will visit on their planned legs (Eq. 7's X-hat).

    For every leg (starts_m[i] -> ends_m[i], (p, 2) each) the points at ``step_m`` spacing
    after the start are returned, thinned evenly so that at most ``max_points`` remain in
    total. Returns a (k, 2) array.
    """
    starts = np.asarray(starts_m, dtype=float).reshape(-1, 2)
    ends = np.asarray(ends_m, dtype=float).reshape(-1, 2)
    if starts.shape[0] == 0 or max_points <= 0:
        return np.zeros((0, 2))
    chunks = [path_points(s, e, step_m)[1:] for s, e in zip(starts, ends, strict=True)]
    pts = np.vstack(chunks) if chunks else np.zeros((0, 2))
    if pts.shape[0] > max_points:
        keep = np.linspace(0, pts.shape[0] - 1, max_points).round().astype(int)
        pts = pts[np.unique(keep)]
    return pts


def acquisition(
    alpha: float, omega_values: np.ndarray, sigma_values: np.ndarray, gamma_values: np.ndarray
) -> np.ndarray:
    """Eq. 1 objective (to be maximised) from its term values (same shapes)."""
    return (alpha * omega_values + (1.0 - alpha) * sigma_values) * gamma_values
