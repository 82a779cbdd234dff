"""Compiled part of the scent field: which puffs reach which sensors.

Simulation only, like :mod:`swarm_sim.raycast_kernel`. :meth:`ScentField.concentration
<swarm_sim.sensors.scent.ScentField.concentration>` needs, for every sensor, the puffs
within the cut-off distance whose vapour path crosses no wall. The numpy version
(:meth:`~swarm_sim.sensors.scent.ScentField.concentration_reference`) builds the full
(sensors x puffs) distance matrix, then the wall candidates of every pair; this kernel
walks the same pairs in the same (row-major) order with the same operations, so the
selected pairs and their squared distances are bit-identical. The concentration itself is
``ScentField._puff_values``' arithmetic in :func:`puff_exponents`, :func:`puff_spread` and
:func:`puff_sum`, with the same operations, around numpy's ``exp`` (which may differ from
the C library's in the last place).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from swarm_sim.raycast_kernel import grid_cell, path_hits

__all__ = ['open_puff_pairs', 'puff_exponents', 'puff_spread', 'puff_sum', 'pump_release_kernel']


@njit(cache=True)
def open_puff_pairs(
    points: np.ndarray,
    puffs: np.ndarray,
    puff_time_s: np.ndarray,
    time_s: float,
    past_only: bool,
    cutoff2: float,
    walls_block: bool,
    grid: tuple,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """The (sensor, puff) pairs whose vapour reaches the sensor, in row-major order.

    Args:
        points: (K, 2) sensor positions [m].
        puffs: (P, 2) puff positions [m].
        puff_time_s: (P,) deposit times [s].
        time_s: the query time [s].
        past_only: leave out puffs deposited after ``time_s``.
        cutoff2: squared cut-off distance [m^2].
        walls_block: leave out pairs whose straight path crosses a wall of the grid.
        grid: the wall grid, :meth:`swarm_sim.geometry.WallGrid.kernel_arguments`.

    Returns:
        (L,) sensor indices, (L,) puff indices and (L,) squared distances [m^2].
    """
    origin_x, origin_y, cell_m, shape_x, shape_y, table, q, s = grid
    k_points = points.shape[0]
    p_puffs = puffs.shape[0]
    total = 0
    for k in range(k_points):
        for p in range(p_puffs):
            dx = points[k, 0] - puffs[p, 0]
            dy = points[k, 1] - puffs[p, 1]
            if dx * dx + dy * dy <= cutoff2 and not (past_only and puff_time_s[p] > time_s):
                total += 1
    sensor = np.empty(total, dtype=np.int64)
    puff = np.empty(total, dtype=np.int64)
    dist2 = np.empty(total)
    count = 0
    for k in range(k_points):
        px = points[k, 0]
        py = points[k, 1]
        walls = table[grid_cell(px, py, origin_x, origin_y, cell_m, shape_x, shape_y)]
        for p in range(p_puffs):
            dx = px - puffs[p, 0]
            dy = py - puffs[p, 1]
            d2 = dx * dx + dy * dy
            if not d2 <= cutoff2 or (past_only and puff_time_s[p] > time_s):
                continue
            if walls_block and path_hits(px, py, puffs[p, 0], puffs[p, 1], walls, q, s) != 0:
                continue
            sensor[count] = k
            puff[count] = p
            dist2[count] = d2
            count += 1
    return sensor[:count], puff[:count], dist2[:count]


@njit(cache=True)
def puff_exponents(
    puff: np.ndarray,
    puff_time_s: np.ndarray,
    time_s: float,
    spread_time_constant_s: float,
    decay_time_constant_s: float,
) -> np.ndarray:  # pragma: no cover - compiled
    """The exponents of the spreading and of the evaporation of the (L,) puffs ``puff``
    at ``time_s``, ``ScentField._puff_values``' operations: (2L,) the first L
    ``-max(age, 0) / spread_time_constant_s``, then L ``-age / decay_time_constant_s``."""
    count = puff.shape[0]
    out = np.empty(2 * count)
    for m in range(count):
        age = time_s - puff_time_s[puff[m]]
        # np.maximum(age, 0.0): the age unless it is below 0 (NaN and -0.0 kept).
        kept = age if (age >= 0.0 or math.isnan(age)) else 0.0
        out[m] = -kept / spread_time_constant_s
        out[count + m] = -age / decay_time_constant_s
    return out


@njit(cache=True)
def puff_spread(
    exp_spread: np.ndarray, initial_var: float, var_growth: float, d2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """From ``exp`` of the spreading exponents (the first L of :func:`puff_exponents`):
    (L,) the puffs' variances [m^2] (``spread_m(age) ** 2``: the square root squared) and
    (L,) the exponents of their Gaussians at squared distances ``d2``."""
    count = d2.shape[0]
    sigma2 = np.empty(count)
    gauss = np.empty(count)
    for m in range(count):
        spread = math.sqrt(initial_var + var_growth * (1.0 - exp_spread[m]))
        s2 = spread * spread
        sigma2[m] = s2
        gauss[m] = -d2[m] / (2.0 * s2)
    return sigma2, gauss


@njit(cache=True)
def puff_sum(
    sensor: np.ndarray,
    puff: np.ndarray,
    mass: np.ndarray,
    exp_decay: np.ndarray,
    sigma2: np.ndarray,
    exp_gauss: np.ndarray,
    two_pi: float,
    num_sensors: int,
) -> np.ndarray:  # pragma: no cover - compiled
    """(K,) concentrations [ppm]: per pair, ``mass * decay / (2 pi sigma2) * gauss``, summed
    per sensor in pair order (``np.bincount``'s sums)."""
    out = np.zeros(num_sensors)
    for m in range(sensor.shape[0]):
        out[sensor[m]] += mass[puff[m]] * exp_decay[m] / (two_pi * sigma2[m]) * exp_gauss[m]
    return out


@njit(cache=True)
def pump_release_kernel(
    on_time_s: np.ndarray,
    pump_on: np.ndarray,
    nozzle_xy: np.ndarray,
    dt_s: float,
    full_s: float,
    rate: float,
) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - compiled
    """``PumpDepositor.step``'s accounting: add ``dt_s`` to the pumping time of the pumps
    on, then release every puff that is full (pumping time at least ``full_s``) or whose
    pump stopped, resetting its time.

    Returns:
        The places (the robots' nozzles, in robot order) and masses (``rate`` times the
        pumping time) of the released puffs that ``ScentField.deposit`` keeps: finite
        places, positive masses.
    """
    n = on_time_s.shape[0]
    xy = np.empty((n, 2))
    mass = np.empty(n)
    count = 0
    for i in range(n):
        if pump_on[i]:
            on_time_s[i] += dt_s
        t = on_time_s[i]
        if t >= full_s or (not pump_on[i] and t > 0.0):
            on_time_s[i] = 0.0
            m = rate * t
            x = nozzle_xy[i, 0]
            y = nozzle_xy[i, 1]
            if math.isfinite(x) and math.isfinite(y) and m > 0.0:
                xy[count, 0] = x
                xy[count, 1] = y
                mass[count] = m
                count += 1
    return xy[:count], mass[:count]
