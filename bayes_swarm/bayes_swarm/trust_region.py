"""Projected trust-region Newton step in two variables, shared by the GP's two solvers.

Both the likelihood fit (two log-hyperparameters) and Eq. 5 (a point in the plane) minimise
a smooth function of two variables inside a box, with an analytic gradient and Hessian, many
times per decision. At this size a step is a few float operations, far cheaper than setting up
a general-purpose optimiser for every call.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ['projected_newton_step']


def projected_newton_step(
    x: Sequence[float] | np.ndarray,
    grad: np.ndarray,
    hess: np.ndarray,
    lower: tuple[float, float] | np.ndarray,
    upper: tuple[float, float] | np.ndarray,
    radius: float,
) -> tuple[float, float]:
    """Step (2,) that decreases a function with ``grad`` (2,) and ``hess`` (2, 2) at ``x``.

    A coordinate held at a bound whose descent direction points out of the box stays fixed
    (the active set); on the remaining coordinates the step is the Newton step where the
    Hessian is positive definite, else steepest descent of length ``radius``. The step is
    clipped to length ``radius``; the caller projects ``x + step`` into the box and decides
    whether to accept it.
    """
    g0, g1 = float(grad[0]), float(grad[1])
    free0 = not ((x[0] <= lower[0] and g0 > 0.0) or (x[0] >= upper[0] and g0 < 0.0))
    free1 = not ((x[1] <= lower[1] and g1 > 0.0) or (x[1] >= upper[1] and g1 < 0.0))
    h00, h01, h11 = float(hess[0, 0]), float(hess[0, 1]), float(hess[1, 1])
    if free0 and free1:
        det = h00 * h11 - h01 * h01
        if h00 > 0.0 and det > 0.0:
            s0, s1 = -(h11 * g0 - h01 * g1) / det, -(h00 * g1 - h01 * g0) / det
        else:
            norm = math.hypot(g0, g1)
            s0, s1 = -g0 * radius / max(norm, 1e-300), -g1 * radius / max(norm, 1e-300)
    else:
        s0 = _one_dimensional_step(g0, h00, radius) if free0 else 0.0
        s1 = _one_dimensional_step(g1, h11, radius) if free1 else 0.0
    norm = math.hypot(s0, s1)
    if norm > radius:
        s0, s1 = s0 * radius / norm, s1 * radius / norm
    return s0, s1


def _one_dimensional_step(g: float, h: float, radius: float) -> float:
    return -g / h if h > 0.0 else -math.copysign(radius, g)
