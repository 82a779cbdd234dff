"""Box-constrained L-BFGS-B for small problems: scipy's routine without its per-call set-up.

Eq. 5 (the argmax of the GP mean) runs scipy's L-BFGS-B from two to four starts at every
decision. In two dimensions the objective is cheap, and
``scipy.optimize.minimize(method='L-BFGS-B')`` spends most of each call in its Python layers
(option checks, bounds conversion, the ``ScalarFunction`` wrapper and its finite-difference
machinery, which an analytic gradient never uses); docs/bayes_swarm.md gives the cost.

:func:`minimize_box` drives scipy's own compiled L-BFGS-B iteration (``setulb``) with the
same options and the same evaluation rule as ``minimize`` (the objective is evaluated at the
clipped start first, and again only where the iterate changed), so it returns the same point
and value, bit for bit. ``setulb`` is not public scipy API: the first call checks the
driver against ``minimize`` on a test problem, and if the routine is missing, its signature
changed or the results differ, every call goes through ``minimize`` instead.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.optimize import minimize

__all__ = ['minimize_box']

#: f(x, *args) -> (value, gradient (n,)).
Objective = Callable[..., tuple[float, np.ndarray]]

# scipy's L-BFGS-B defaults (``minimize`` with no options).
_MAXCOR = 10
_FTOL = 2.2204460492503131e-09
_GTOL = 1e-5
_MAX_LINE_SEARCH = 20
_MAX_ITERATIONS = 15000
_MAX_EVALUATIONS = 15000
# setulb's task codes: 3 asks for f and g at x, 1 starts a new iteration; anything else
# (convergence 4, a warning 2, an error) ends the run. 5 with 504 stops it (iteration limit).
_TASK_EVALUATE = 3
_TASK_NEW_ITERATION = 1
_TASK_STOP = 5
_STOP_ITERATIONS = 504


def minimize_box(
    fun: Objective,
    x0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    args: tuple[Any, ...] = (),
) -> tuple[np.ndarray, float]:
    """Minimise ``fun`` (value and gradient) within finite bounds from ``x0``.

    The result of ``scipy.optimize.minimize(fun, x0, args, jac=True, method='L-BFGS-B',
    bounds=list(zip(lower, upper)))``: its point (n,) and value.
    """
    if _driver_matches_scipy():
        return _setulb_driver(fun, x0, lower, upper, args)
    return _scipy_minimize(fun, x0, lower, upper, args)


def _scipy_minimize(
    fun: Objective, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, args: tuple[Any, ...]
) -> tuple[np.ndarray, float]:
    result = minimize(
        fun,
        x0,
        args=args,
        jac=True,
        method='L-BFGS-B',
        bounds=list(zip(lower, upper, strict=True)),
    )
    return np.asarray(result.x, dtype=float), float(result.fun)


def _setulb_driver(
    fun: Objective, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, args: tuple[Any, ...]
) -> tuple[np.ndarray, float]:
    """scipy's ``_minimize_lbfgsb`` loop for finite bounds and an analytic gradient."""
    from scipy.optimize import _lbfgsb  # not public API: see _driver_matches_scipy

    low = np.asarray(lower, dtype=np.float64)
    high = np.asarray(upper, dtype=np.float64)
    x = np.clip(np.asarray(x0, dtype=np.float64).ravel(), low, high)
    n = x.shape[0]
    m = _MAXCOR
    bound_kinds = np.full(n, 2, dtype=np.int32)  # both bounds finite
    work = np.zeros(2 * m * n + 5 * n + 11 * m * m + 8 * m, dtype=np.float64)
    int_work = np.zeros(3 * n, dtype=np.int32)
    task = np.zeros(2, dtype=np.int32)
    line_task = np.zeros(2, dtype=np.int32)
    l_save = np.zeros(4, dtype=np.int32)
    i_save = np.zeros(44, dtype=np.int32)
    d_save = np.zeros(29, dtype=np.float64)
    factr = _FTOL / np.finfo(float).eps
    # As scipy's ScalarFunction: evaluated at the start, re-evaluated only where x changed.
    evaluated_at = x.copy()
    value, gradient = fun(evaluated_at.copy(), *args)
    evaluations = 1
    f: Any = np.array(0.0)
    g = np.zeros(n, dtype=np.float64)
    iterations = 0
    while True:
        _lbfgsb.setulb(
            m,
            x,
            low,
            high,
            bound_kinds,
            f,
            g,
            factr,
            _GTOL,
            work,
            int_work,
            task,
            l_save,
            i_save,
            d_save,
            _MAX_LINE_SEARCH,
            line_task,
        )
        if task[0] == _TASK_EVALUATE:
            if not np.array_equal(x, evaluated_at):
                evaluated_at = x.copy()
                value, gradient = fun(evaluated_at.copy(), *args)
                evaluations += 1
            f = float(value)
            g = np.array(gradient, dtype=np.float64).reshape(n)
        elif task[0] == _TASK_NEW_ITERATION:
            iterations += 1
            if iterations >= _MAX_ITERATIONS or evaluations > _MAX_EVALUATIONS:
                task[0], task[1] = _TASK_STOP, _STOP_ITERATIONS
        else:
            return x, float(f)


def _check_objective(x: np.ndarray) -> tuple[float, np.ndarray]:
    """A smooth, non-quadratic test problem with its minimum at (1.50, 0.59)."""
    a, b = float(x[0]), float(x[1])
    value = (a - 1.3) ** 2 + 0.5 * (b + 0.2) ** 4 + np.sin(3.0 * a) * b
    gradient = np.array([2.0 * (a - 1.3) + 3.0 * np.cos(3.0 * a) * b, 2.0 * (b + 0.2) ** 3])
    gradient[1] += np.sin(3.0 * a)
    return float(value), gradient


@functools.cache
def _driver_matches_scipy() -> bool:
    """True if the setulb driver runs and reproduces ``minimize`` exactly (checked once).

    Three starts in a box holding the minimum and one in a box that puts it on a bound.
    """
    cases = (
        ((0.3, 1.1), (-2.0, 0.0), (2.0, 1.5)),
        ((-1.7, 0.4), (-2.0, 0.0), (2.0, 1.5)),
        ((1.9, 1.5), (-2.0, 0.0), (2.0, 1.5)),
        ((0.3, 1.1), (-2.0, 0.7), (2.0, 1.5)),
    )
    try:
        for start, lower, upper in cases:
            box = (np.array(start), np.array(lower), np.array(upper))
            mine = _setulb_driver(_check_objective, *box, ())
            theirs = _scipy_minimize(_check_objective, *box, ())
            if not (np.array_equal(mine[0], theirs[0]) and mine[1] == theirs[1]):
                return False
    except (ImportError, AttributeError, TypeError, ValueError):
        return False
    return True
