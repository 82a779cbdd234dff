"""Compiled particle-filter update: the arithmetic of :class:`msc_pf.particle_filter.
ParticleFilterBank` in a few numba loops instead of some forty numpy passes.

Optional (``particle_filter.backend``): numba is a dependency of the simulation install, not
of the robot package; a robot without it runs the numpy code, which stays the reference. The
kernels cover the distances and the censored misfit, and the resampling with its gather and
the roughening. What stays numpy in both backends: ``log10`` of the squared distances and
``exp`` of the misfits (numpy's vectorised float32 versions, which the C library's, called
once per particle from a loop, neither equal nor match in speed), and the sums and weighted
sums of the estimate (shared code; their summation order is numpy's).

Equality to the numpy path: every kernel performs the same float32 operations, in the same
order and with the same rounding of constants, as the numpy code it replaces, so the
particles, misfits, weights, estimates and resampling indices are bit-identical and seeded
runs give the same results with either backend (``test_pf_kernel.py`` compares them; a
platform where numba contracted a multiply and an add into one instruction would fail it —
numba does not without ``fastmath``). In detail:

* the misfit is ``(slope * log10 d^2 + offset)^2`` minus the censoring table entry at the
  truncated ``log10 d^2 * bins_per_log``, with the table looked up for a whole block of
  samples exactly when numpy's does (when some ``log10 d^2`` of the block is not below the
  table's start, compared in float32); a filter's later samples add their misfits in
  observation order;
* systematic resampling: the float32 cumulative sum is sequential, as ``np.cumsum``; comb
  end ``e_j = trunc(c_j * (N (1 - 2^-20) / c_N) + (1 - u))``, the last set to N, and output m
  copies particle ``#{j : e_j <= m}`` (:func:`msc_pf.particle_filter.systematic_index`);
* multinomial resampling copies particle j ``counts_j`` times in particle order
  (``np.repeat``);
* roughening: jitter ``noise * max(scale * (max - min), floor)`` per coordinate and row, then
  the clip to the field (always applied: where the numpy code skips it, it changes nothing).

NaN follows numpy's ``maximum`` and ``clip`` (NaN stays NaN). Kernels are compiled on first
use and cached next to this module (``cache=True``); :func:`warm_up` compiles (or loads)
them for the bank's array types so that the first update does not pay for it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = [
    'add_misfit',
    'resample_roughen',
    'squared_distances',
    'systematic_index_kernel',
    'warm_up',
]

# As particle_filter._COMB_SHRINK (repeated here so that the kernels need no import cycle).
_COMB_SHRINK = 1.0 - 2.0**-20


@njit(cache=True, error_model='numpy')
def squared_distances(
    x: np.ndarray,
    y: np.ndarray,
    rows: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    clamped: np.ndarray,
    dx: np.ndarray,
    dy: np.ndarray,
    d2: np.ndarray,
    keep_offsets: bool,
) -> None:  # pragma: no cover - compiled
    """Squared distances of the particles of row ``rows[i]`` from observer i.

    ``clamped[i]`` gets ``max(d^2, 1)`` (NaN stays NaN, as ``np.maximum``); with
    ``keep_offsets`` also ``dx[i]``, ``dy[i]`` (particle minus observer) and ``d2[i]``. All
    float32; ``x``, ``y`` (rows, N), the outputs (len(rows), N).
    """
    one = np.float32(1.0)
    n = x.shape[1]
    for i in range(rows.size):
        r = rows[i]
        cx = ox[i]
        cy = oy[i]
        if keep_offsets:
            for j in range(n):
                a = x[r, j] - cx
                b = y[r, j] - cy
                s = a * a + b * b
                dx[i, j] = a
                dy[i, j] = b
                d2[i, j] = s
                clamped[i, j] = one if s < one else s
        else:
            for j in range(n):
                a = x[r, j] - cx
                b = y[r, j] - cy
                s = a * a + b * b
                clamped[i, j] = one if s < one else s


@njit(cache=True, error_model='numpy')
def add_misfit(
    logs: np.ndarray,
    rows: np.ndarray,
    offsets: np.ndarray,
    slope: np.float32,
    table: np.ndarray,
    bins_per_log: np.float32,
    table_from_log: np.float32,
    q: np.ndarray,
    assign: bool,
) -> None:  # pragma: no cover - compiled
    """Misfit of sample i, ``(slope * logs[i] + offsets[i])^2 - C``, into row ``rows[i]`` of
    ``q`` (assigned, or added in sample order).

    ``logs`` holds ``log10 max(d^2, 1)``; ``C`` is ``table[trunc(logs * bins_per_log)]``
    (clipped to the table; NaN to its first bin, as ``np.take(mode='clip')`` after numpy's
    cast), looked up for the whole block when some ``logs`` value is not below
    ``table_from_log``, and 0 otherwise or when the table is empty. float32 throughout.
    """
    m, n = logs.shape
    lookup = False
    if table.size:
        for i in range(m):
            for j in range(n):
                if not logs[i, j] < table_from_log:
                    lookup = True
                    break
            if lookup:
                break
    # Bins past the table clip to its end, below its start to 0 (np.take(mode='clip')). NaN
    # and inf logs (non-finite particles) give NaN or inf whatever the bin: the last here.
    top = np.float32(table.size - 1)
    zero = np.float32(0.0)
    for i in range(m):
        target = q[rows[i]]
        source = logs[i]
        c = offsets[i]
        for j in range(n):
            v = source[j]
            t = v * slope + c
            t = t * t
            if lookup:
                p = v * bins_per_log
                p = p if p < top else top
                p = p if p > zero else zero
                t = t - table[int(p)]
            if assign:
                target[j] = t
            else:
                target[j] += t


@njit(cache=True)
def _cumulate(weights: np.ndarray, cumulative: np.ndarray) -> np.float32:  # pragma: no cover
    """Sequential float32 cumulative sum of one row (``np.cumsum``'s order); returns the
    total."""
    acc = np.float32(0.0)
    for j in range(weights.size):
        acc += weights[j]
        cumulative[j] = acc
    return acc


@njit(cache=True)
def _comb_starts(
    weights: np.ndarray, offset: np.float32, cumulative: np.ndarray, starts: np.ndarray
) -> None:  # pragma: no cover - compiled
    """``starts[m]`` = j for the particle j whose copies start at output m, -1 where none
    starts (the outputs copying the particle started before).

    The comb end of particle j is ``e_j = trunc(c_j * factor + (1 - u))``, with
    ``factor = float32(N (1 - 2^-20) / c_N)``, both rounded as the numpy code rounds them; the
    last particle's end is N. Particle j covers the outputs ``e_(j-1) .. e_j - 1``: written
    in particle order, ``starts[e_(j-1)] = j`` ends with the one particle that covers
    ``e_(j-1)`` (those without copies come before it). Stores only, no branch per particle.
    Ends that cannot occur with a positive finite total (not finite, past N) are clamped.
    """
    n = weights.size
    factor = np.float32(n * _COMB_SHRINK / np.float64(_cumulate(weights, cumulative)))
    shift = np.float32(1.0) - offset
    limit = np.float32(n)
    starts[:] = -1
    start = 0
    for j in range(n - 1):
        starts[start] = j
        v = cumulative[j] * factor + shift
        v = v if v < limit else limit  # non-negative: truncation is the floor
        v = v if v > 0.0 else np.float32(0.0)
        start = int(v)
    starts[start] = n - 1


@njit(cache=True)
def _count_starts(counts: np.ndarray, starts: np.ndarray) -> None:  # pragma: no cover
    """:func:`_comb_starts` for particle j copied ``counts[j]`` times (each row's counts sum
    to N: its end is their cumulative sum, clamped to N)."""
    n = counts.size
    starts[:] = -1
    start = 0
    for j in range(n - 1):
        starts[start] = j
        start = min(start + counts[j], n)
    starts[start] = n - 1


@njit(cache=True)
def _fill(starts: np.ndarray, m: int, index: int) -> int:  # pragma: no cover - compiled
    """Particle that output m copies, given the one output m - 1 copies."""
    j = starts[m]
    return j if j >= 0 else index


@njit(cache=True)
def _value_range(a: np.ndarray) -> tuple:  # pragma: no cover - compiled
    """Least and largest value of a non-empty row (four running pairs: no long latency
    chain). A row with NaN may give any of its values (only degenerate filters have NaN,
    and they are re-initialised)."""
    n = a.size
    l0 = l1 = l2 = l3 = h0 = h1 = h2 = h3 = a[0]
    full = n - n % 4
    for j in range(0, full, 4):
        v0, v1, v2, v3 = a[j], a[j + 1], a[j + 2], a[j + 3]
        l0 = v0 if v0 < l0 else l0
        l1 = v1 if v1 < l1 else l1
        l2 = v2 if v2 < l2 else l2
        l3 = v3 if v3 < l3 else l3
        h0 = v0 if v0 > h0 else h0
        h1 = v1 if v1 > h1 else h1
        h2 = v2 if v2 > h2 else h2
        h3 = v3 if v3 > h3 else h3
    for j in range(full, n):
        v = a[j]
        l0 = v if v < l0 else l0
        h0 = v if v > h0 else h0
    return min(min(l0, l1), min(l2, l3)), max(max(h0, h1), max(h2, h3))


@njit(cache=True)
def _roughen_row(
    row: np.ndarray, noise: np.ndarray, scale: np.float32, floor: np.float32, field: np.float32
) -> None:  # pragma: no cover - compiled
    """``row += noise * max(scale * (max - min), floor)``, then clipped to [0, field] as
    ``np.clip`` does (NaN stays NaN, -0.0 becomes 0.0)."""
    lo, hi = _value_range(row)
    spread = scale * (hi - lo)
    sigma = spread if spread > floor else floor
    zero = np.float32(0.0)
    for j in range(row.size):
        v = row[j] + noise[j] * sigma
        v = v if not v <= zero else zero
        row[j] = v if not v >= field else field


@njit(cache=True, error_model='numpy')
def systematic_index_kernel(
    weights: np.ndarray,
    offsets: np.ndarray,
    cumulative: np.ndarray,
    starts: np.ndarray,
    out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """:func:`msc_pf.particle_filter.systematic_index` (the same flat indices) for weights
    whose rows all have a positive finite sum (not checked here).

    ``weights`` (k, N) float32, ``offsets`` (k, 1) float32, scratch ``cumulative`` (N,)
    float32 and ``starts`` (N + 1,) int32, ``out`` (k, N) integer.
    """
    k, n = weights.shape
    for r in range(k):
        _comb_starts(weights[r], offsets[r, 0], cumulative, starts)
        index = 0
        for m in range(n):
            index = _fill(starts, m, index)
            out[r, m] = r * n + index


@njit(cache=True, error_model='numpy')
def resample_roughen(
    weights: np.ndarray,
    offsets: np.ndarray,
    counts: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    noise: np.ndarray,
    scale: np.float32,
    floor: np.float32,
    field: np.float32,
    cumulative: np.ndarray,
    starts: np.ndarray,
    new_x: np.ndarray,
    new_y: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Resample each row of ``x``, ``y`` into ``new_x``, ``new_y`` and roughen the result.

    With an empty ``counts``, systematic resampling of ``weights`` (rows with a positive
    finite sum) with the offsets ``offsets[:, 0]``; otherwise particle j of row r is copied
    ``counts[r, j]`` times (each row's counts sum to N). Output m copies particle
    ``#{j : e_j <= m}``: the last particle whose copies start at or before m (no branch per
    particle). Then each coordinate gets ``noise[c] * max(scale * (max - min), floor)`` (max
    and min over the row's new particles) and is clipped to ``[0, field]``. Scratch:
    ``cumulative`` (N,) float32, ``starts`` (N + 1,) int32.
    """
    k, n = x.shape
    for r in range(k):
        if counts.shape[0] == 0:
            _comb_starts(weights[r], offsets[r, 0], cumulative, starts)
        else:
            _count_starts(counts[r], starts)
        index = 0
        for m in range(n):
            index = _fill(starts, m, index)
            new_x[r, m] = x[r, index]
            new_y[r, m] = y[r, index]
        _roughen_row(new_x[r], noise[0, r], scale, floor, field)
        _roughen_row(new_y[r], noise[1, r], scale, floor, field)


def warm_up() -> None:
    """Compile (or load from the cache) every kernel for the array types the bank passes."""
    f32, i64 = np.float32, np.int64
    x = np.zeros((1, 4), f32)
    rows = np.zeros(1, i64)
    point = np.zeros(1, f32)
    work = [np.zeros((1, 4), f32) for _ in range(4)]
    squared_distances(x, x, rows, point, point, *work, True)
    table = np.zeros(2, f32)
    table.flags.writeable = False  # the bank's censoring tables are read-only
    one = f32(1.0)
    add_misfit(work[0], rows, point, one, table, one, one, work[1], True)
    offsets = np.zeros((1, 1), f32)
    cumulative = np.zeros(4, f32)
    starts = np.zeros(5, np.int32)
    weights = work[0] + one
    systematic_index_kernel(weights, offsets, cumulative, starts, np.zeros((1, 4), np.intp))
    noise = np.zeros((2, 1, 4), f32)
    for counts in (np.zeros((0, 0), i64), np.full((1, 4), 1, i64)):
        resample_roughen(
            weights, offsets, counts, x, x, noise, one, one, one, cumulative, starts, *work[2:]
        )
