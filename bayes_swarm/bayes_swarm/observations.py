"""Time-ordered store of signal observations (own and received from peers)."""

from __future__ import annotations

import numpy as np

from bayes_swarm.errors import ObservationError

__all__ = ['ObservationStore', 'finite_samples']


def finite_samples(
    points_m: np.ndarray,
    values: np.ndarray,
    *,
    max_abs_value: float = np.inf,
    lower_m: np.ndarray | None = None,
    upper_m: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Check shapes and drop rows with a non-finite coordinate or value, or an implausible one.

    Args:
        points_m: (k, 2) sample locations [m].
        values: (k,) signal values.
        max_abs_value: rows whose value exceeds it in magnitude are dropped too.
        lower_m: (2,) lower-left corner [m]; rows with a location below it are dropped.
        upper_m: (2,) upper-right corner [m]; rows with a location above it are dropped.

    Returns:
        The kept rows as float arrays ((j, 2), (j,)).

    Raises:
        ObservationError: if the shapes do not match.
    """
    pts = (
        np.asarray(points_m, dtype=float).reshape(-1, 2) if np.size(points_m) else np.zeros((0, 2))
    )
    vals = np.asarray(values, dtype=float).reshape(-1)
    if pts.shape[0] != vals.shape[0]:
        msg = f'{pts.shape[0]} sample locations but {vals.shape[0]} values'
        raise ObservationError(msg)
    keep = np.isfinite(vals) & np.all(np.isfinite(pts), axis=1)
    if max_abs_value < np.inf:
        keep &= np.abs(vals) <= max_abs_value
    if lower_m is not None:
        keep &= np.all(pts >= lower_m, axis=1)
    if upper_m is not None:
        keep &= np.all(pts <= upper_m, axis=1)
    return pts[keep], vals[keep]


class ObservationStore:
    """Append-only (location, value) samples in arrival order, concatenated lazily."""

    def __init__(self) -> None:
        self._points: list[np.ndarray] = []
        self._values: list[np.ndarray] = []
        self._cache: tuple[np.ndarray, np.ndarray] | None = None
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def extend(self, points_m: np.ndarray, values: np.ndarray) -> None:
        """Append (k, 2) finite locations [m] and (k,) values (already validated)."""
        if values.shape[0] == 0:
            return
        self._points.append(points_m)
        self._values.append(values)
        self._count += values.shape[0]
        self._cache = None

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """All samples as ((n, 2) locations [m], (n,) values) in arrival order."""
        if self._cache is None:
            if self._count == 0:
                self._cache = (np.zeros((0, 2)), np.zeros(0))
            else:
                pts = np.vstack(self._points)
                vals = np.concatenate(self._values)
                self._points, self._values = [pts], [vals]
                self._cache = (pts, vals)
        return self._cache
