"""SIR particle filters for many static RSSI targets, updated together (eqs. 2-7).

One :class:`ParticleFilterBank` holds one robot's filters, one per target ID it has heard.
An update takes one observation point (the robot that took the samples) and the RSSI of
every target it heard there, and updates all those filters in one vectorised pass:

1. likelihood, eq. (3)-(4): ``w_j = exp(-(P - R_j)^2 / sigma^2)``, ``R_j = P0 - 10 K log10 d_j``
   (optionally the Gaussian ``2 sigma^2``), divided by default by the chance
   ``Phi((R_j - gamma_D) / s)`` that the sample would have been heard at all (the receiver
   reports nothing below gamma_D, so samples near the detection edge are biased upward);
2. normalisation, eq. (2); estimate, eq. (5); spread sigma_k and the largest-weight particle,
   all from these post-update, pre-resampling weights;
3. systematic (or multinomial) resampling and roughening (Gordon, Salmond and Smith 1993).

If every weight of a filter is numerically zero (no particle explains the sample) or not
finite, that filter is re-initialised on the lattice around the observer and reported.

Convergence (eqs. 6-7) is tested once per control step by :meth:`end_step`: the spread is at
most R_conv and each of the last n estimates lies within R_err of their mean. A converged
filter stays converged (its estimate keeps being refined).

Speed (docs/msc_pf.md, "The particle filter"): particle positions are float32 (x and y in
separate (targets, N) arrays; the millimetre resolution is far below the metre-scale spread),
every work array is preallocated and written with ``out=``, and a filter's several samples of
one step are evaluated together. The likelihood is kept as the misfit ``q = -log w`` and
the weights ``exp(min q - q)`` are never normalised in place: the estimate divides by their
sum, the resampling scales the cumulative sum. Systematic resampling counts the comb points
up to each particle's end and takes the gather index as the cumulative sum of a histogram of
those counts: no per-particle loop (``np.repeat``), no binary search.

Backends (``ParticleFilterConfig.backend``): this numpy code is the reference and runs
everywhere; where numba can be imported, :mod:`msc_pf.pf_kernel` computes the distances, the
misfits, the resampling and the roughening in compiled loops with bit-identical results
('auto', the default, picks it then).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from msc_pf.errors import ConfigError, ObservationError
from msc_pf.settings import ParticleFilterConfig, RadioConfig

__all__ = [
    'ParticleFilterBank',
    'TargetEstimate',
    'estimates_converged',
    'lattice',
    'resolve_backend',
    'systematic_index',
    'windows_converged',
]

# exp(x) of a float64 is 0 or subnormal below this: "all weights zero" in the paper's form.
_LOG_TINY = math.log(np.finfo(np.float64).tiny)
# The comb is scaled by slightly less than N / sum(w) so that float32 rounding can never
# put a comb point past the last particle (relative bias 1e-6, far below one copy).
_COMB_SHRINK = 1.0 - 2.0**-20


@dataclass(frozen=True)
class TargetEstimate:
    """Current belief about one target.

    Attributes:
        target_id: emitter ID.
        position_m: (2,) weighted mean of the particles, eq. (5) [m].
        spread_m: sigma_k, weighted RMS distance of the particles from the estimate [m].
        best_particle_m: (2,) position of the particle with the largest weight [m].
        converged: eqs. (6) and (7) held at some control step since the filter started.
        n_updates: observations folded in since the (re)initialisation.
    """

    target_id: int
    position_m: np.ndarray
    spread_m: float
    best_particle_m: np.ndarray
    converged: bool
    n_updates: int


def lattice(
    center_xy: np.ndarray, half_width_m: float, field_size_m: float, n_points: int
) -> tuple[np.ndarray, np.ndarray]:
    """Evenly spaced points on the square of half width ``half_width_m`` around ``center_xy``.

    The square is clipped to the field [0, field_size_m]^2. With ``n_points`` a perfect square
    (5041 = 71^2) this is a full lattice; otherwise the next larger lattice is thinned evenly.

    Returns:
        x and y, each an (n_points,) float32 array [m].
    """
    x0 = min(max(center_xy[0] - half_width_m, 0.0), field_size_m)
    x1 = min(max(center_xy[0] + half_width_m, 0.0), field_size_m)
    y0 = min(max(center_xy[1] - half_width_m, 0.0), field_size_m)
    y1 = min(max(center_xy[1] + half_width_m, 0.0), field_size_m)
    side = math.isqrt(n_points)
    if side * side < n_points:
        side += 1
    gx, gy = np.meshgrid(np.linspace(x0, x1, side), np.linspace(y0, y1, side))
    keep = np.linspace(0, side * side - 1, n_points).round().astype(np.int64)
    return gx.ravel()[keep].astype(np.float32), gy.ravel()[keep].astype(np.float32)


def windows_converged(
    spread_m: np.ndarray, windows_m: np.ndarray, r_conv_m: float, r_err_m: float
) -> np.ndarray:
    """Eqs. (6) and (7) for several filters: spread at most R_conv, every estimate near the mean.

    Args:
        spread_m: (k,) sigma_k of each filter's latest update [m].
        windows_m: (k, n, 2) each filter's n most recent estimates [m].
        r_conv_m: R_conv [m].
        r_err_m: R_err [m].

    Returns:
        (k,) bool: both conditions hold.
    """
    offset = windows_m - windows_m.mean(axis=1, keepdims=True)
    deviation = np.hypot(offset[..., 0], offset[..., 1])
    return (spread_m <= r_conv_m) & np.all(deviation <= r_err_m, axis=1)


def estimates_converged(
    spread_m: float, window_m: np.ndarray, r_conv_m: float, r_err_m: float
) -> bool:
    """Eqs. (6) and (7): ``spread <= R_conv`` and every windowed estimate within R_err of the mean.

    Args:
        spread_m: sigma_k of the latest update [m].
        window_m: (n, 2) the most recent n estimates [m].
        r_conv_m: R_conv [m].
        r_err_m: R_err [m].
    """
    spread = np.array([spread_m], dtype=np.float64)
    return bool(windows_converged(spread, window_m[None], r_conv_m, r_err_m)[0])


def systematic_index(
    weights: np.ndarray,
    offsets: np.ndarray,
    out: np.ndarray | None = None,
    work: np.ndarray | None = None,
    work_int32: np.ndarray | None = None,
) -> np.ndarray:
    """Gather index of systematic resampling, row by row, into the flattened ``weights``.

    Row r draws N comb points at ``(m + u_r) / N``, m = 0..N-1, of its total weight; the
    point falls on particle j when ``c_(j-1) < (m + u_r) / N <= c_j`` (c: cumulative weights
    over their sum). With ``e_j`` the number of points at or before the end of particle j,
    ``e_j = floor(N c_j + 1 - u_r)``, output m of the row is the particle count
    ``#{j : e_j <= m}``: a histogram of the ends and its cumulative sum, both linear in the
    number of particles and free of branches. The last end is set to N, so every row draws
    exactly N points whatever the float32 rounding of its cumulative sum.

    Args:
        weights: (k, N) non-negative weights (float32), not necessarily normalised; every row
            must have a positive finite sum.
        offsets: (k, 1) offsets u_r in [0, 1).
        out: optional (k, N) intp array to write the index to.
        work: optional (k, N) float32 scratch array (saves an allocation).
        work_int32: optional (k, N) int32 scratch array (saves an allocation).

    Returns:
        (k, N) intp: ``out[r, m]`` is the flat index (``r * N + j``) of the particle that
        output m of row r copies; each row's indices are non-decreasing.

    Raises:
        ValueError: a row's weights do not have a positive finite sum, or k * N >= 2^31.
    """
    k, n = weights.shape
    if k * n >= 2**31:
        raise ValueError('at most 2^31 - 1 particles in all rows together')
    cumulative = np.cumsum(weights, axis=1, dtype=np.float32, out=work)
    last = cumulative[:, -1].astype(np.float64)
    if not (last.min() > 0.0 and last.max() < math.inf):  # NaN fails both
        raise ValueError('every row of weights needs a positive finite sum')
    cumulative *= (n * _COMB_SHRINK / last).astype(np.float32)[:, None]
    cumulative += (1.0 - offsets).astype(np.float32)
    # float32 -> int32 -> intp: two fast conversions instead of one slow one. Truncation is
    # the floor here: every value is positive.
    ends32 = np.empty((k, n), np.int32) if work_int32 is None else work_int32
    ends32[...] = cumulative
    ends32[:, -1] = n
    if k > 1:
        ends32 += np.arange(0, k * n, n, dtype=np.int32)[:, None]
    ends = np.empty((k, n), np.intp) if out is None else out
    ends[...] = ends32
    histogram = np.bincount(ends.reshape(-1), minlength=k * n + 1)
    np.cumsum(histogram[: k * n], out=ends.reshape(-1))
    return ends


@functools.lru_cache(maxsize=1)
def _compiled_kernel() -> tuple[ModuleType | None, str]:
    """:mod:`msc_pf.pf_kernel`, or None and why numba cannot be imported here."""
    try:
        import numba  # noqa: F401  (missing, or installed against another numpy)
    except ImportError as exc:
        return None, f'{type(exc).__name__}: {exc}'
    from msc_pf import pf_kernel

    return pf_kernel, ''


def resolve_backend(backend: str) -> str:
    """The backend ``particle_filter.backend`` selects on this machine: 'numpy' or 'numba'.

    Raises:
        ConfigError: ``backend`` is not 'auto', 'numpy' or 'numba', or it is 'numba' and numba
            cannot be imported.
    """
    if backend == 'numpy':
        return 'numpy'
    if backend not in ('auto', 'numba'):
        raise ConfigError(
            f"particle_filter.backend must be 'auto', 'numpy' or 'numba', got {backend!r}"
        )
    kernel, why_not = _compiled_kernel()
    if kernel is not None:
        return 'numba'
    if backend == 'numba':
        raise ConfigError(
            "particle_filter.backend 'numba' needs the numba package, which cannot be imported"
            f" here ({why_not}); install numba or use backend 'numpy' or 'auto'"
        )
    return 'numpy'


_CENSOR_STEP_DB = 0.01
_CENSOR_U_MAX = 6.0  # Phi(6) = 1 - 1e-9: no correction beyond
_CENSOR_U_MIN = -8.0  # the squared error term dominates beyond


def _neg_log_phi(u: float) -> float:
    """``-log Phi(u)`` of the standard normal distribution, also far in the lower tail."""
    if u > -30.0:
        return -math.log(0.5 * math.erfc(-u / math.sqrt(2.0)))
    # Mills ratio: Phi(u) ~ phi(u) / |u| (relative error below 1e-3 here).
    return 0.5 * u * u + math.log(-u) + 0.5 * math.log(2.0 * math.pi)


@functools.lru_cache(maxsize=8)
def _censoring_table(noise_std_db: float, margin_db: float) -> np.ndarray:
    """``-log Phi((margin - L) / s)`` over the path loss ``L = P0 - R`` [dB], bin i at i * step.

    ``margin`` is the path loss at which ``R = gamma_D``; ``s`` the noise standard deviation
    the likelihood of eq. (3) implies. Bin i covers ``[i, i + 1) * step`` and holds the value
    at its centre; the table ends where ``(margin - L) / s = U_MIN`` (a look-up beyond clips
    to its last bin). Shared by every bank with the same radio model (read-only).
    """
    count = math.ceil((margin_db - _CENSOR_U_MIN * noise_std_db) / _CENSOR_STEP_DB)
    loss = (np.arange(count) + 0.5) * _CENSOR_STEP_DB
    u = (margin_db - loss) / noise_std_db
    table = np.array(
        [0.0 if v > _CENSOR_U_MAX else _neg_log_phi(v) for v in u.tolist()],
        np.float32,
    )
    table.flags.writeable = False
    return table


@functools.lru_cache(maxsize=8)
def _miss_table(noise_std_db: float, margin_db: float) -> np.ndarray:
    """``-log Phi((L - margin) / s)``, the chance of not hearing, over the path loss L [dB].

    The complement of :func:`_censoring_table`, on the same bins; the table ends where the
    chance of not hearing exceeds Phi(U_MAX) (a look-up beyond clips to its last bin, 0).
    """
    count = math.ceil((margin_db + _CENSOR_U_MAX * noise_std_db) / _CENSOR_STEP_DB) + 1
    loss = (np.arange(count) + 0.5) * _CENSOR_STEP_DB
    u = (loss - margin_db) / max(noise_std_db, 1e-9)
    table = np.array(
        [0.0 if v > _CENSOR_U_MAX else _neg_log_phi(v) for v in u.tolist()], np.float64
    )
    table[-1] = 0.0
    table.flags.writeable = False
    return table


class ParticleFilterBank:
    """The particle filters of one robot, one per tracked target ID."""

    def __init__(
        self,
        config: ParticleFilterConfig,
        radio: RadioConfig,
        field_size_m: float,
        rng: np.random.Generator,
        capacity: int = 8,
    ) -> None:
        """Create an empty bank.

        Args:
            config: filter parameters.
            radio: path-loss model of eq. (4) (P0, K) and the detection range.
            field_size_m: the field is [0, field_size_m]^2; particles are kept inside.
            rng: the bank's own random generator (resampling offsets, roughening).
            capacity: initial number of target slots (at least 8; grows as needed).

        Raises:
            ConfigError: ``config.backend`` is 'numba' and numba cannot be imported.
        """
        self._backend = resolve_backend(config.backend)
        self._kernel = _compiled_kernel()[0] if self._backend == 'numba' else None
        if self._kernel is not None:
            self._kernel.warm_up()
        self._cfg = config
        self._radio = radio
        self._field_size_m = float(field_size_m)
        self._rng = rng
        self._n = config.n_particles
        self._half_width_m = (
            config.init_half_width_m
            if config.init_half_width_m is not None
            else radio.detection_range_m
        )
        denominator = config.noise_variance_db2 * (2.0 if config.gaussian_likelihood else 1.0)
        # Misfit q = ((P - P0) + 5 K log10 d^2)^2 / denominator = (a log10 d^2 + b)^2.
        root = 1.0 / math.sqrt(denominator)
        self._misfit_slope = np.float32(5.0 * radio.path_loss_exponent * root)
        self._misfit_root = root
        if config.censored_likelihood:
            margin = radio.rssi_at_1m_dbm - radio.detection_threshold_dbm  # L at R = gamma_D
            self._censor_table = _censoring_table(math.sqrt(denominator / 2.0), margin)
        else:
            self._censor_table = np.empty(0, np.float32)
            self._censor_table.flags.writeable = False  # as the shared tables (one kernel type)
        # Table bin of log10 d^2: L / step = 5 K log10 d^2 / step.
        self._censor_bins_per_log = np.float32(5.0 * radio.path_loss_exponent / _CENSOR_STEP_DB)
        # Below this log10 d^2 every table entry is 0 (Phi > 1 - 1e-9): no look-up needed.
        nonzero_bins = np.flatnonzero(self._censor_table)
        self._censor_from_log = (
            float(nonzero_bins[0]) / float(self._censor_bins_per_log)
            if nonzero_bins.size
            else math.inf
        )
        # float32 as numpy compares the float32 logs with it
        self._censor_from_log32 = np.float32(self._censor_from_log)
        # Non-detections (update_unheard): the noise standard deviation the likelihood implies.
        self._miss_table = _miss_table(
            math.sqrt(denominator / 2.0), radio.rssi_at_1m_dbm - radio.detection_threshold_dbm
        )
        self._pool = (
            rng.standard_normal(config.noise_pool_size, dtype=np.float32)
            if config.noise_pool_size
            else np.empty(0, np.float32)
        )
        self._pool_abs_max = float(np.abs(self._pool).max()) if self._pool.size else math.inf
        self._ids: list[int] = []
        self._any_updated = False
        self._slot_of: dict[int, int] = {}
        self._allocate(max(8, capacity))

    # ----------------------------------------------------------------- bookkeeping
    def _allocate(self, capacity: int) -> None:
        n, w = self._n, self._cfg.window
        old = getattr(self, '_capacity', 0)
        used = len(self._ids)

        def grow(arr: np.ndarray | None, shape: tuple[int, ...], dtype: type) -> np.ndarray:
            new: np.ndarray = np.zeros(shape, dtype=dtype)
            if arr is not None and used:
                new[:used] = arr[:used]
            return new

        get = self.__dict__.get
        self._x = grow(get('_x'), (capacity, n), np.float32)
        self._y = grow(get('_y'), (capacity, n), np.float32)
        self._estimate = grow(get('_estimate'), (capacity, 2), np.float64)
        self._best = grow(get('_best'), (capacity, 2), np.float64)
        self._spread = grow(get('_spread'), (capacity,), np.float64)
        self._window = grow(get('_window'), (capacity, w, 2), np.float64)
        self._window_count = grow(get('_window_count'), (capacity,), np.int64)
        self._converged = grow(get('_converged'), (capacity,), np.bool_)
        self._updated = grow(get('_updated'), (capacity,), np.bool_)
        self._n_updates = grow(get('_n_updates'), (capacity,), np.int64)
        # Work arrays, sized for updating every slot at once.
        shape = (capacity, n)
        self._w_q, self._w_dx, self._w_dy, self._w_d2, self._w_tmp, self._w_cum = (
            np.empty(shape, np.float32) for _ in range(6)
        )
        self._w_x, self._w_y = np.empty(shape, np.float32), np.empty(shape, np.float32)
        self._w_index = np.empty(shape, np.intp)  # censoring table bins, resampling index
        # The new particles (swapped with the storage when every filter was updated).
        self._buf_nx = np.empty((capacity, n), np.float32)
        self._buf_ny = np.empty((capacity, n), np.float32)
        self._flat_index = np.arange(capacity * n, dtype=np.intp)
        self._row_numbers = np.arange(capacity, dtype=np.int64)
        self._no_offsets = np.zeros((capacity, 1), np.float32)  # kernel arguments of the
        self._no_counts = np.zeros((0, 0), np.int64)  # resampling scheme not in use
        self._starts = np.empty(n + 1, np.int32)  # kernel scratch
        self._capacity = max(capacity, old)

    @property
    def backend(self) -> str:
        """'numpy' or 'numba': how this bank computes its updates."""
        return self._backend

    @property
    def tracked_ids(self) -> tuple[int, ...]:
        """IDs of the targets that have a filter, in the order they were first tracked."""
        return tuple(self._ids)

    def is_tracked(self, target_id: int) -> bool:
        """True when ``target_id`` has a filter."""
        return target_id in self._slot_of

    def track(self, target_id: int, center_xy: Sequence[float] | np.ndarray) -> None:
        """Start a filter for ``target_id`` on the initial lattice around ``center_xy`` [m]."""
        if target_id in self._slot_of:
            return
        if len(self._ids) == self._capacity:
            self._allocate(2 * self._capacity)
        slot = len(self._ids)
        self._ids.append(int(target_id))
        self._slot_of[int(target_id)] = slot
        self._reinitialise(slot, np.asarray(center_xy, dtype=np.float64))

    def forget(self, target_id: int) -> None:
        """Drop the filter of ``target_id`` (e.g. it was captured); unknown IDs are ignored."""
        slot = self._slot_of.pop(target_id, None)
        if slot is None:
            return
        last = len(self._ids) - 1
        if slot != last:
            moved = self._ids[last]
            for arr in (
                self._x,
                self._y,
                self._estimate,
                self._best,
                self._spread,
                self._window,
                self._window_count,
                self._converged,
                self._updated,
                self._n_updates,
            ):
                arr[slot] = arr[last]
            self._ids[slot] = moved
            self._slot_of[moved] = slot
        self._ids.pop()

    def _reinitialise(self, slot: int, center_xy: np.ndarray) -> None:
        if self._cfg.initial_prior == 'field':
            half = self._field_size_m / 2.0
            center = np.array([half, half])
        else:
            half, center = self._half_width_m, center_xy
        x, y = lattice(center, half, self._field_size_m, self._n)
        self._x[slot] = x
        self._y[slot] = y
        ex, ey = float(x.mean(dtype=np.float64)), float(y.mean(dtype=np.float64))
        self._estimate[slot] = (ex, ey)
        self._best[slot] = (ex, ey)
        spread2 = np.mean((x - ex) ** 2 + (y - ey) ** 2, dtype=np.float64)
        self._spread[slot] = math.sqrt(spread2)
        self._window_count[slot] = 0
        self._converged[slot] = False
        self._updated[slot] = False
        self._n_updates[slot] = 0

    # ----------------------------------------------------------------- update
    def _validate(
        self,
        observer_xy: Sequence[float] | np.ndarray,
        target_ids: Sequence[int],
        rssi_dbm: Sequence[float] | np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        obs = np.asarray(observer_xy, dtype=np.float64)
        values = np.asarray(rssi_dbm, dtype=np.float64)
        if obs.shape != (2,) or not (math.isfinite(obs[0]) and math.isfinite(obs[1])):
            raise ObservationError(f'observer position must be 2 finite numbers, got {obs!r}')
        if values.shape != (len(target_ids),):
            raise ObservationError(f'{len(target_ids)} target IDs but RSSI of shape {values.shape}')
        if not all(math.isfinite(v) for v in values.tolist()):
            raise ObservationError(f'RSSI values must be finite, got {values!r}')
        if len(set(target_ids)) != len(target_ids):
            raise ObservationError(f'target IDs repeat within one observation: {target_ids}')
        return obs, values

    def update(
        self,
        observer_xy: Sequence[float] | np.ndarray,
        target_ids: Sequence[int],
        rssi_dbm: Sequence[float] | np.ndarray,
    ) -> list[int]:
        """Fold in the RSSI of several targets sampled at one observation point.

        Targets without a filter get one, centred on ``observer_xy``.

        Args:
            observer_xy: (2,) position of the robot that took the samples [m].
            target_ids: IDs of the sampled targets, no repeats.
            rssi_dbm: (len(target_ids),) sampled RSSI [dBm].

        Returns:
            IDs whose filter degenerated (all weights zero or not finite) and was
            re-initialised around ``observer_xy``.

        Raises:
            ObservationError: non-finite observer position or RSSI, shape mismatch, repeats.
        """
        return self.update_joint([(observer_xy, target_ids, rssi_dbm)])

    def update_joint(
        self,
        observations: Sequence[
            tuple[Sequence[float] | np.ndarray, Sequence[int], Sequence[float] | np.ndarray]
        ],
    ) -> list[int]:
        """Fold in samples from several observation points at once (one control step).

        Each filter multiplies the likelihoods of all its samples (eq. 3 per sample), then
        normalises, estimates and resamples once. This is the same posterior as one update
        per sample, with one resampling instead of many.

        Args:
            observations: (observer (2,) [m], target IDs, RSSI [dBm]) per observation point;
                targets without a filter get one centred on their first observer.

        Returns:
            IDs whose filter degenerated and was re-initialised around its first observer.

        Raises:
            ObservationError: as :meth:`update`, for any observation (nothing is updated).
        """
        checked = [(self._validate(o, ids, v), ids) for o, ids, v in observations]
        # The samples of each filter, in observation order: (observer x, observer y, RSSI).
        samples: dict[int, list[tuple[float, float, float]]] = {}
        skip_converged = not self._cfg.update_after_convergence
        for (obs, values), ids in checked:
            ox, oy = obs.tolist()
            for tid, value in zip(ids, values.tolist(), strict=True):
                tid = int(tid)
                self.track(tid, obs)
                slot = self._slot_of[tid]
                if skip_converged and self._converged[slot]:
                    continue
                samples.setdefault(slot, []).append((ox, oy, value))
        if not samples:
            return []
        slots = sorted(samples)
        first = np.array([samples[slot][0] for slot in slots])
        first[:, 2] -= self._radio.rssi_at_1m_dbm
        # Later samples, level by level (a filter's second samples, then its third...), each
        # level in row order: the misfits add up in observation order.
        extra: list[tuple[int, float, float, float]] = []
        level = 1
        while True:
            start = len(extra)
            for row, slot in enumerate(slots):
                if len(samples[slot]) > level:
                    extra.append((row, *samples[slot][level]))
            if len(extra) == start:
                break
            level += 1
        later = np.array(extra).reshape(-1, 4)
        later[:, 3] -= self._radio.rssi_at_1m_dbm
        return self._update_slots(np.array(slots, dtype=np.int64), first, later)

    def _misfit(self, d2: np.ndarray, excess: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Minus the log-likelihood of eqs. (3)-(4), ``((P - P0) + 5 K log10 d^2)^2 / sigma^2``.

        ``d2`` holds the squared distances (float32, at most ``capacity`` rows, unchanged),
        ``excess`` the (rows, 1) column of P - P0 [dB]; the result goes to ``out`` (float32,
        the shape of ``d2``).

        With the censoring correction, ``log Phi((R_j - gamma_D) / s)`` is added (the
        likelihood is divided by Phi), looked up in a table indexed by the path loss
        ``10 K log10 d`` (bins of 0.01 dB from 0 dB).
        """
        np.maximum(d2, np.float32(1.0), out=out)  # d < 1 m counts as 1 m
        np.log10(out, out=out)
        censor = None
        # Skipped when no particle is far enough for the correction (all bins hold 0).
        if self._censor_table.size and not out.max() < self._censor_from_log:
            rows, cols = out.shape
            bins = self._w_index[:rows, :cols]  # free until resampling
            # Truncation: the log is non-negative. Bins past the table clip to its end.
            np.multiply(out, self._censor_bins_per_log, out=bins, casting='unsafe')
            censor = np.take(self._censor_table, bins, out=self._w_tmp[:rows, :cols], mode='clip')
        out *= self._misfit_slope
        out += (np.asarray(excess, dtype=np.float64) * self._misfit_root).astype(np.float32)
        np.multiply(out, out, out=out)
        if censor is not None:
            out -= censor
        return out

    def _add_extra_samples(
        self, q: np.ndarray, x: np.ndarray, y: np.ndarray, extra: np.ndarray
    ) -> None:
        """Add the misfits of the later samples to ``q`` (rows of the first samples).

        ``extra`` holds (row, observer x, observer y, P - P0) per sample, level by level; the
        samples are evaluated in blocks as large as the work buffers.
        """
        k = q.shape[0]
        block = self._capacity
        rows_all = extra[:, 0].astype(np.int64)
        for start in range(0, len(extra), block):
            rows = rows_all[start : start + block]
            chunk = extra[start : start + block]
            m = len(rows)
            # The new-particle buffers are free until the resampling.
            ex, ey, qe = self._buf_nx[:m], self._buf_ny[:m], self._w_cum[:m]
            chunk32 = chunk.astype(np.float32)
            ox, oy = chunk32[:, 1:2], chunk32[:, 2:3]
            if k == 1:
                np.subtract(x[0], ox, out=ex)
                np.subtract(y[0], oy, out=ey)
            elif m == k and rows[0] == 0 and rows[-1] == k - 1 and np.all(rows[1:] > rows[:-1]):
                np.subtract(x, ox, out=ex)  # one sample for every row, in order: no gather
                np.subtract(y, oy, out=ey)
            else:
                np.subtract(np.take(x, rows, axis=0, out=ex), ox, out=ex)
                np.subtract(np.take(y, rows, axis=0, out=ey), oy, out=ey)
            ex *= ex
            ey *= ey
            ex += ey
            self._misfit(ex, chunk[:, 3:], out=qe)
            # One level has each row at most once and in order; a row's levels come in order.
            i = 0
            while i < m:
                j = i + 1
                while j < m and rows[j] > rows[j - 1]:
                    j += 1
                if j - i == k:
                    q += qe[i:j]
                elif j - i == 1:
                    q[rows[i]] += qe[i]
                else:
                    q[rows[i:j]] += qe[i:j]
                i = j

    def _update_slots(self, slots: np.ndarray, first: np.ndarray, extra: np.ndarray) -> list[int]:
        """Update the filters in ``slots`` (sorted) with their samples.

        ``first`` holds each filter's first sample (observer x, observer y, P - P0), ``extra``
        the later ones as in :meth:`_add_extra_samples`.
        """
        k = slots.size
        n = self._n
        contiguous = bool(slots[-1] == k - 1)  # slots are sorted and distinct
        if contiguous:
            x, y = self._x[:k], self._y[:k]
        else:
            x = np.take(self._x, slots, axis=0, out=self._w_x[:k])
            y = np.take(self._y, slots, axis=0, out=self._w_y[:k])
        q, dx, dy, d2 = self._w_q[:k], self._w_dx[:k], self._w_dy[:k], self._w_d2[:k]
        # Offsets from each filter's first observer; the estimate is accumulated relative to
        # it so float32 keeps millimetres.
        if self._kernel is not None:
            self._misfits_compiled(x, y, first, extra, q, dx, dy, d2)
        else:
            first32 = first.astype(np.float32)
            np.subtract(x, first32[:, 0:1], out=dx)
            np.subtract(y, first32[:, 1:2], out=dy)
            np.multiply(dx, dx, out=d2)
            np.multiply(dy, dy, out=q)
            d2 += q
            self._misfit(d2, first[:, 2:], out=q)
            if len(extra):
                self._add_extra_samples(q, x, y, extra)
        least = q.min(axis=1)
        best = q.argmin(axis=1)
        degenerate = ~(least <= -_LOG_TINY)  # also catches NaN
        # Eq. (2) up to the normalisation: exp(min q - q); each row's largest weight is 1, so
        # its sum is at least 1. Degenerate rows are re-initialised below.
        w = np.subtract(least[:, None], q, out=q)
        np.exp(w, out=w)
        total = w.sum(axis=1, dtype=np.float32).astype(np.float64)
        # Eq. (5), the spread and the largest-weight particle (pre-resampling weights).
        mx = np.einsum('kn,kn->k', w, dx).astype(np.float64) / total
        my = np.einsum('kn,kn->k', w, dy).astype(np.float64) / total
        spread2 = np.einsum('kn,kn->k', w, d2).astype(np.float64) / total - (mx * mx + my * my)
        rows = np.arange(k)
        self._best[slots] = np.column_stack((x[rows, best], y[rows, best]))
        self._estimate[slots] = first[:, :2] + np.column_stack((mx, my))
        self._spread[slots] = np.sqrt(np.maximum(spread2, 0.0))
        any_degenerate = bool(degenerate.any())
        if any_degenerate:
            w[degenerate] = np.float32(1.0)  # re-initialised below; keeps the resampling defined

        new_x, new_y = self._buf_nx[:k], self._buf_ny[:k]
        offsets, counts = self._resampling_draws(w)
        if self._kernel is not None:
            cfg = self._cfg
            self._kernel.resample_roughen(
                w,
                self._no_offsets if offsets is None else offsets,
                self._no_counts if counts is None else counts,
                x,
                y,
                self._jitter_noise(k)[0],
                np.float32(cfg.roughening_kappa / math.sqrt(n)),
                np.float32(cfg.roughening_floor_m),
                np.float32(self._field_size_m),
                self._w_cum[0],
                self._starts,
                new_x,
                new_y,
            )
        else:
            if offsets is not None:
                # dx is free now: the int32 scratch.
                index = systematic_index(
                    w, offsets, self._w_index[:k], self._w_cum[:k], dx.view(np.int32)
                ).reshape(-1)
            else:
                assert counts is not None  # one of the two draws is set
                index = np.repeat(self._flat_index[: k * n], counts.ravel())
            # 'clip' writes straight to out (the default mode buffers); the index is in range.
            np.take(x.reshape(-1), index, out=new_x.reshape(-1), mode='clip')
            np.take(y.reshape(-1), index, out=new_y.reshape(-1), mode='clip')
            self._roughen(new_x, new_y, *self._jitter_noise(k))

        if contiguous and k == len(self._ids):
            # Every filter was updated: the new particles become the storage (no copy).
            self._x, self._buf_nx = self._buf_nx, self._x
            self._y, self._buf_ny = self._buf_ny, self._y
        elif contiguous:
            self._x[:k] = new_x
            self._y[:k] = new_y
        else:
            self._x[slots] = new_x
            self._y[slots] = new_y
        self._updated[slots] = True
        self._any_updated = True
        self._n_updates[slots] += 1
        if len(extra):
            self._n_updates[slots] += np.bincount(extra[:, 0].astype(np.int64), minlength=k)

        reinitialised: list[int] = []
        if any_degenerate:
            for row in np.flatnonzero(degenerate):
                slot = int(slots[row])
                self._reinitialise(slot, first[row, :2])
                reinitialised.append(self._ids[slot])
        return reinitialised

    def update_unheard(self, target_id: int, observers_xy: np.ndarray) -> float:
        """Fold in that ``target_id`` was *not* heard at the observers (negative information).

        Each particle is weighted by the chance that a target there would have stayed below
        gamma_D at every observer, ``prod_o Phi((gamma_D - R_j,o) / s)`` with R_j,o of eq. (4)
        and s the noise standard deviation the likelihood implies (the complement of the
        censoring correction); then estimate, spread and largest-weight particle are taken
        from these weights, and the filter is resampled and roughened as after a sample.

        Args:
            target_id: a tracked target.
            observers_xy: (M, 2) positions where it was not heard this step [m].

        Returns:
            The weighted share of the filter's belief that the non-detections leave (the mean
            chance of not hearing, 1 when every particle is far out of range, near 0 when the
            observers covered the whole belief). The filter is left unchanged when it is
            below 1e-12 (no particle is compatible with the non-detections).

        Raises:
            KeyError: ``target_id`` is not tracked.
        """
        slot = self._slot_of[target_id]
        observers = np.asarray(observers_xy, dtype=np.float64).reshape(-1, 2)
        x = self._x[slot].astype(np.float64)
        y = self._y[slot].astype(np.float64)
        q = np.zeros(self._n)
        bins_per_log = 5.0 * self._radio.path_loss_exponent / _CENSOR_STEP_DB
        last = len(self._miss_table) - 1
        for ox, oy in observers.tolist():
            d2 = np.maximum((x - ox) ** 2 + (y - oy) ** 2, 1.0)
            bins = np.minimum((np.log10(d2) * bins_per_log).astype(np.intp), last)
            q += self._miss_table[bins]
        least = float(q.min())
        w = np.exp(least - q)
        kept = math.exp(-least) * float(w.sum()) / self._n
        if not kept > 1e-12:
            return kept
        self._fold_weights(slot, x, y, w)
        return kept

    def apply_prior(self, target_id: int, weights: np.ndarray) -> float:
        """Multiply the belief of ``target_id`` by per-particle ``weights`` (a prior).

        Estimate, spread and largest-weight particle are taken from the weights, then the
        filter is resampled and roughened as after a sample (:meth:`particles` gives the
        positions the weights refer to).

        Args:
            target_id: a tracked target.
            weights: (N,) non-negative weights of the current particles.

        Returns:
            The mean weight (the share of the belief the prior keeps). The filter is left
            unchanged when it is not above 1e-12.

        Raises:
            KeyError: ``target_id`` is not tracked.
            ValueError: ``weights`` has the wrong shape or a negative or non-finite value.
        """
        slot = self._slot_of[target_id]
        w = np.asarray(weights, dtype=np.float64)
        if w.shape != (self._n,) or not bool(np.all(np.isfinite(w))) or bool(np.any(w < 0.0)):
            msg = f'prior weights must be {self._n} finite non-negative numbers'
            raise ValueError(msg)
        kept = float(w.mean())
        if not kept > 1e-12:
            return kept
        self._fold_weights(
            slot, self._x[slot].astype(np.float64), self._y[slot].astype(np.float64), w
        )
        return kept

    def _fold_weights(self, slot: int, x: np.ndarray, y: np.ndarray, w: np.ndarray) -> None:
        """Estimate, spread and best particle of slot from float64 weights ``w`` of its
        particles at ``x``, ``y``; then resample and roughen."""
        total = float(w.sum())
        mx = float(w @ x) / total
        my = float(w @ y) / total
        spread2 = float(w @ ((x - mx) ** 2 + (y - my) ** 2)) / total
        best = int(np.argmax(w))
        self._best[slot] = (x[best], y[best])
        self._estimate[slot] = (mx, my)
        self._spread[slot] = math.sqrt(max(spread2, 0.0))
        w32 = w[None, :].astype(np.float32)
        offsets, counts = self._resampling_draws(w32)
        if offsets is not None:
            index = systematic_index(w32, offsets).reshape(-1)
        else:
            assert counts is not None  # one of the two draws is set
            index = np.repeat(np.arange(self._n), counts.ravel())
        new_x = self._x[slot][index][None, :]
        new_y = self._y[slot][index][None, :]
        self._roughen(new_x, new_y, *self._jitter_noise(1))
        self._x[slot] = new_x[0]
        self._y[slot] = new_y[0]
        self._updated[slot] = True
        self._any_updated = True

    def _resampling_draws(self, w: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The random draws of the resampling of the rows of ``w``: (k, 1) float32 offsets
        (systematic) or (k, N) copy counts (multinomial), the other None."""
        if self._cfg.resampling == 'systematic':
            return self._rng.random((w.shape[0], 1), dtype=np.float32), None
        probabilities = w.astype(np.float64)
        probabilities /= probabilities.sum(axis=1, keepdims=True)
        return None, self._rng.multinomial(self._n, probabilities)

    def _misfits_compiled(
        self,
        x: np.ndarray,
        y: np.ndarray,
        first: np.ndarray,
        extra: np.ndarray,
        q: np.ndarray,
        dx: np.ndarray,
        dy: np.ndarray,
        d2: np.ndarray,
    ) -> None:
        """:meth:`_misfit` of the first samples and :meth:`_add_extra_samples`, bit for bit,
        with :mod:`msc_pf.pf_kernel`; the first samples' offsets and squared distances go to
        ``dx``, ``dy``, ``d2``. ``log10`` stays numpy's (one call per block of samples)."""
        kernel = self._kernel
        assert kernel is not None  # only called with the compiled backend
        k = x.shape[0]
        # q holds the first samples' logs until their misfits replace them, element by element.
        blocks = [(self._row_numbers[:k], first[:, 0], first[:, 1], first[:, 2], q)]
        for start in range(0, len(extra), self._capacity):
            chunk = extra[start : start + self._capacity]
            rows = chunk[:, 0].astype(np.int64)
            blocks.append((rows, chunk[:, 1], chunk[:, 2], chunk[:, 3], self._w_cum[: len(rows)]))
        for i, (rows, ox, oy, excess, logs) in enumerate(blocks):
            ox32, oy32 = ox.astype(np.float32), oy.astype(np.float32)
            kernel.squared_distances(x, y, rows, ox32, oy32, logs, dx, dy, d2, i == 0)
            np.log10(logs, out=logs)
            kernel.add_misfit(
                logs,
                rows,
                (excess * self._misfit_root).astype(np.float32),
                self._misfit_slope,
                self._censor_table,
                self._censor_bins_per_log,
                self._censor_from_log32,
                q,
                i == 0,
            )

    def _jitter_noise(self, k: int) -> tuple[np.ndarray, bool]:
        """(2, k, N) standard normals for the roughening and whether they come from the pool."""
        need = 2 * k * self._n
        if need <= self._pool.size:
            start = int(self._rng.integers(0, self._pool.size - need + 1))
            return self._pool[start : start + need].reshape(2, k, self._n), True
        return self._rng.standard_normal((2, k, self._n), dtype=np.float32), False

    def _roughen(self, x: np.ndarray, y: np.ndarray, noise: np.ndarray, bounded: bool) -> None:
        """Add N(0, sigma_r^2) jitter per coordinate, sigma_r = kappa E N^(-1/2), floored.

        ``noise`` holds (2, rows, N) standard normals; ``bounded``: they come from the pool,
        whose largest magnitude is known.
        """
        cfg = self._cfg
        scale = cfg.roughening_kappa / math.sqrt(self._n)
        x_lo, x_hi = x.min(axis=1), x.max(axis=1)  # float32, as the jitter scale
        y_lo, y_hi = y.min(axis=1), y.max(axis=1)
        sx = np.maximum(scale * (x_hi - x_lo), cfg.roughening_floor_m)
        sy = np.maximum(scale * (y_hi - y_lo), cfg.roughening_floor_m)
        b = self._w_tmp[: x.shape[0]]
        np.multiply(noise[0], sx[:, None], out=b)
        x += b
        np.multiply(noise[1], sy[:, None], out=b)
        y += b
        # Clipping is skipped when no jitter from the pool can push a particle out (the bound
        # is loose, so a skipped clip would not have changed anything).
        field = self._field_size_m
        reach = 1.001 * self._pool_abs_max * max(float(sx.max()), float(sy.max())) + 0.01
        inside = (
            bounded
            and min(float(x_lo.min()), float(y_lo.min())) - reach >= 0.0
            and max(float(x_hi.max()), float(y_hi.max())) + reach <= field
        )
        if not inside:
            np.clip(x, 0.0, field, out=x)
            np.clip(y, 0.0, field, out=y)

    # ----------------------------------------------------------------- convergence
    def end_step(self) -> None:
        """Record this control step's estimate of every updated filter and test eqs. (6)-(7)."""
        if not self._any_updated:
            return
        self._any_updated = False
        cfg = self._cfg
        slots = np.flatnonzero(self._updated[: len(self._ids)])
        count = self._window_count[slots]
        self._window[slots, count % cfg.window] = self._estimate[slots]
        count += 1
        self._window_count[slots] = count
        self._updated[slots] = False
        # Eq. (6) first: most unconverged filters fail it, and it needs no window.
        ready = (count >= cfg.window) & ~self._converged[slots]
        test = slots[ready & (self._spread[slots] <= cfg.r_conv_m)]
        if test.size:
            ok = windows_converged(
                self._spread[test], self._window[test], cfg.r_conv_m, cfg.r_err_m
            )
            self._converged[test[ok]] = True

    # ----------------------------------------------------------------- queries
    def estimate(self, target_id: int) -> TargetEstimate:
        """Current estimate of ``target_id``; raises KeyError when it is not tracked."""
        slot = self._slot_of[target_id]
        return TargetEstimate(
            target_id=target_id,
            position_m=self._estimate[slot].copy(),
            spread_m=float(self._spread[slot]),
            best_particle_m=self._best[slot].copy(),
            converged=bool(self._converged[slot]),
            n_updates=int(self._n_updates[slot]),
        )

    def estimates(self) -> list[TargetEstimate]:
        """Estimates of every tracked target, in tracking order."""
        return [self.estimate(tid) for tid in self._ids]

    def is_converged(self, target_id: int) -> bool:
        """True when ``target_id`` is tracked and its filter has converged."""
        slot = self._slot_of.get(target_id)
        return slot is not None and bool(self._converged[slot])

    def particles(self, target_id: int) -> np.ndarray:
        """(N, 2) copy of the particle positions of ``target_id`` [m]."""
        slot = self._slot_of[target_id]
        return np.stack([self._x[slot], self._y[slot]], axis=1).astype(np.float64)
