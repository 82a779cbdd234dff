"""Where a straight move first enters a disc: continuous detection of a source or target."""

from __future__ import annotations

import math

import numpy as np

__all__ = ['first_entry_fraction']


def first_entry_fraction(
    start_m: np.ndarray, end_m: np.ndarray, centre_m: np.ndarray, radius_m: float
) -> float | None:
    """First s in [0, 1] with |start + s (end - start) - centre| <= radius, else None.

    Args:
        start_m: (2,) start of the segment [m].
        end_m: (2,) end of the segment [m].
        centre_m: (2,) centre of the disc [m].
        radius_m: radius of the disc [m].

    Returns:
        0.0 when the start is already inside, the fraction of the way at which the segment
        first reaches the disc's edge, or None when it never does.
    """
    d = np.asarray(end_m, dtype=float) - start_m
    f = np.asarray(start_m, dtype=float) - centre_m
    c = float(f @ f) - radius_m * radius_m
    if c <= 0.0:
        return 0.0
    a = float(d @ d)
    if a <= 0.0:
        return None
    b = 2.0 * float(f @ d)
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return None
    s = (-b - math.sqrt(disc)) / (2.0 * a)
    return s if 0.0 <= s <= 1.0 else None
