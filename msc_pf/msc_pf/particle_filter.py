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

Particle positions are stored as float32 (x and y in separate (targets, N) arrays, the
millimetre resolution is far below the metre-scale spread), the work arrays are
preallocated, and a filter's several samples of one step are evaluated together. One step
of 20 targets x 5041 particles costs about 3 ms of CPU (docs/msc_pf.md, "Benchmark"); most
of it is the resampling (cumulative sum, copy counts, gather), whose float32 arithmetic is
kept exactly so that seeded runs stay reproducible across versions.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from msc_pf.errors import ObservationError
from msc_pf.settings import ParticleFilterConfig, RadioConfig

__all__ = [
    'ParticleFilterBank',
    'TargetEstimate',
    'estimates_converged',
    'lattice',
    'systematic_counts',
]

# exp(x) of a float64 is 0 or subnormal below this: "all weights zero" in the paper's form.
_LOG_TINY = math.log(np.finfo(np.float64).tiny)


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
    if spread_m > r_conv_m:
        return False
    deviation = np.hypot(*(window_m - window_m.mean(axis=0)).T)
    return bool(np.all(deviation <= r_err_m))


def systematic_counts(
    weights: np.ndarray,
    offsets: np.ndarray,
    out: np.ndarray | None = None,
    work: np.ndarray | None = None,
) -> np.ndarray:
    """Copies of each particle under systematic resampling, row by row.

    Row r draws N points at (u_r + m) / N, m = 0..N-1; particle j is copied as many times as
    points fall in its slice of the cumulative weights, i.e. ``F_j - F_(j-1)`` with
    ``F_j = ceil(N c_j - u_r)``. Rounding of the float32 cumulative sum can move a copy
    between neighbouring particles but never changes the total: c is capped at 1 and the
    last F is exactly N.

    Args:
        weights: (k, N) normalised weights (float32).
        offsets: (k, 1) offsets u_r in [0, 1).
        out: optional (k, N) int32 array to write the counts to.
        work: optional (k, N) float32 scratch array (saves an allocation).

    Returns:
        (k, N) int32 copy counts, each row summing to N.
    """
    k, n = weights.shape
    c = np.cumsum(weights, axis=1, dtype=np.float32, out=work)
    # Rows are non-decreasing, so only rows whose total exceeds 1 need the cap.
    if c[:, -1].max() > 1.0:
        for row in np.flatnonzero(c[:, -1] > np.float32(1.0)):
            np.minimum(c[row], np.float32(1.0), out=c[row])
    c *= np.float32(n)
    c -= offsets.astype(np.float32)
    np.ceil(c, out=c)
    c[:, -1] = n
    counts = np.empty((k, n), np.int32) if out is None else out
    counts[:, 0] = c[:, 0]
    np.subtract(c[:, 1:], c[:, :-1], out=counts[:, 1:], casting='unsafe')
    return counts


_CENSOR_STEP_DB = 0.01
_CENSOR_U_MAX = 6.0  # Phi(6) = 1 - 1e-9: no correction beyond
_CENSOR_U_MIN = -8.0  # the squared error term dominates beyond


def _censoring_table(
    config: ParticleFilterConfig, radio: RadioConfig, denominator: float
) -> tuple[np.ndarray, float, float]:
    """``-log Phi((R - gamma_D) / s)`` tabulated over the path loss ``L = P0 - R`` [dB].

    ``s = sqrt(denominator / 2)`` is the noise standard deviation the likelihood of eq. (3)
    implies (sigma / sqrt 2 for the paper's form, sigma for the Gaussian one). Returns the
    table (empty when the correction is off), the path loss of its first bin and 1 / bin width.
    """
    if not config.censored_likelihood:
        return np.empty(0, np.float32), 0.0, 1.0
    s = math.sqrt(denominator / 2.0)
    margin = radio.rssi_at_1m_dbm - radio.detection_threshold_dbm  # L at which R = gamma_D
    lo = margin - _CENSOR_U_MAX * s
    count = math.ceil((_CENSOR_U_MAX - _CENSOR_U_MIN) * s / _CENSOR_STEP_DB)
    loss = lo + (np.arange(count) + 0.5) * _CENSOR_STEP_DB
    u = (margin - loss) / s
    table = np.array([-math.log(0.5 * math.erfc(-v / math.sqrt(2.0))) for v in u], np.float32)
    return table, lo, 1.0 / _CENSOR_STEP_DB


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
        """
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
        self._denominator = config.noise_variance_db2 * (2.0 if config.gaussian_likelihood else 1.0)
        self._log_scale = 5.0 * radio.path_loss_exponent  # 10 K log10 d = 5 K log10 d^2
        self._censor_table, self._censor_lo_db, self._censor_inv_step = _censoring_table(
            config, radio, self._denominator
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
            new = np.zeros(shape, dtype=dtype)
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
        # Work buffers, sized for updating every slot at once.
        self._buf_a = np.empty((capacity, n), np.float32)
        self._buf_b = np.empty((capacity, n), np.float32)
        self._buf_c32 = np.empty((capacity, n), np.float32)
        self._buf_d32 = np.empty((capacity, n), np.float32)
        self._buf_censor = np.empty((capacity, n), np.float32)
        self._buf_cum = np.empty((capacity, n), np.float32)
        self._buf_nx = np.empty((capacity, n), np.float32)
        self._buf_ny = np.empty((capacity, n), np.float32)
        self._buf_x = np.empty((capacity, n), np.float32)
        self._buf_y = np.empty((capacity, n), np.float32)
        self._counts = np.empty(
            (capacity, n), np.intp
        )  # index width: no conversion in repeat or take
        self._flat_index = np.arange(capacity * n, dtype=np.intp)
        self._capacity = max(capacity, old)

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
        # level in row order: the log-likelihoods add up in observation order.
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

    def _log_likelihood(self, d2: np.ndarray, excess: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Eqs. (3)-(4) in log form, -((P - P0) + 5 K log10 d^2)^2 / sigma^2, into ``out``.

        ``excess`` is the (rows, 1) float32 column of P - P0 [dB].

        With the censoring correction, ``-log Phi((R_j - gamma_D) / s)`` is added, looked up
        in a table indexed by the path loss ``10 K log10 d``.
        """
        np.maximum(d2, np.float32(1.0), out=out)  # d < 1 m counts as 1 m
        np.log10(out, out=out)
        out *= np.float32(self._log_scale)  # path loss 10 K log10 d = P0 - R_j
        censor = None
        if self._censor_table.size:
            rows, cols = out.shape
            scaled = self._buf_censor[:rows, :cols]
            np.subtract(out, np.float32(self._censor_lo_db), out=scaled)
            scaled *= np.float32(self._censor_inv_step)
            index = self._counts[:rows, :cols]  # free until resampling
            index[...] = scaled  # truncation; the path loss is small enough for int32
            # Clamping the truncated bin equals truncating the clamped value.
            censor = np.take(self._censor_table, index, out=scaled, mode='clip')
        out += excess
        np.multiply(out, out, out=out)
        out *= np.float32(-1.0 / self._denominator)
        if censor is not None:
            out += censor
        return out

    def _add_extra_samples(self, a: np.ndarray, x: np.ndarray, y: np.ndarray, extra: np.ndarray):
        """Add the log-likelihoods of the later samples to ``a`` (rows of the first samples).

        ``extra`` holds (row, observer x, observer y, P - P0) per sample, level by level; the
        samples are evaluated in blocks as large as the work buffers.
        """
        k = a.shape[0]
        block = self._capacity
        rows_all = extra[:, 0].astype(np.int64)
        for start in range(0, len(extra), block):
            rows = rows_all[start : start + block]
            chunk = extra[start : start + block]
            m = len(rows)
            ex, ey, ll = self._buf_nx[:m], self._buf_ny[:m], self._buf_cum[:m]
            chunk32 = chunk.astype(np.float32)
            ox, oy = chunk32[:, 1:2], chunk32[:, 2:3]
            if k == 1:
                np.subtract(x[0], ox, out=ex)
                np.subtract(y[0], oy, out=ey)
            else:
                np.subtract(np.take(x, rows, axis=0, out=ex), ox, out=ex)
                np.subtract(np.take(y, rows, axis=0, out=ey), oy, out=ey)
            ex *= ex
            ey *= ey
            ex += ey
            self._log_likelihood(ex, chunk32[:, 3:], out=ll)
            # One level has each row at most once and in order; a row's levels come in order.
            i = 0
            while i < m:
                j = i + 1
                while j < m and rows[j] > rows[j - 1]:
                    j += 1
                if j - i == k:
                    a += ll[i:j]
                elif j - i == 1:
                    a[rows[i]] += ll[i]
                else:
                    a[rows[i:j]] += ll[i:j]
                i = j

    def _update_slots(self, slots: np.ndarray, first: np.ndarray, extra: np.ndarray) -> list[int]:
        """Update the filters in ``slots`` (sorted) with their samples.

        ``first`` holds each filter's first sample (observer x, observer y, P - P0), ``extra``
        the later ones as in :meth:`_add_extra_samples`.
        """
        k = slots.size
        observers = first[:, :2]
        first32 = first.astype(np.float32)
        contiguous = bool(slots[-1] == k - 1)  # slots are sorted and distinct
        if contiguous:
            x, y = self._x[:k], self._y[:k]
        else:
            x = np.take(self._x, slots, axis=0, out=self._buf_x[:k])
            y = np.take(self._y, slots, axis=0, out=self._buf_y[:k])
        a, dx = self._buf_a[:k], self._buf_b[:k]
        dy, d2 = self._buf_c32[:k], self._buf_d32[:k]

        # Offsets from each filter's first observer; the estimate is accumulated relative to
        # it so float32 keeps millimetres.
        np.subtract(x, first32[:, 0:1], out=dx)
        np.subtract(y, first32[:, 1:2], out=dy)
        np.multiply(dx, dx, out=d2)
        np.multiply(dy, dy, out=a)
        d2 += a
        self._log_likelihood(d2, first32[:, 2:], out=a)
        if len(extra):
            self._add_extra_samples(a, x, y, extra)
        peak = a.max(axis=1)
        degenerate = ~(peak >= _LOG_TINY)  # also catches NaN
        # Eq. (2): normalised weights exp(l - max) / sum (each row's largest is 1, so the sum
        # is at least 1); degenerate rows are re-initialised below.
        a -= peak[:, None]
        np.exp(a, out=a)
        total = a.sum(axis=1, dtype=np.float32).astype(np.float64)
        a *= (1.0 / total).astype(np.float32)[:, None]

        # Eq. (5), the spread and the largest-weight particle (pre-resampling weights).
        mx = np.einsum('kn,kn->k', a, dx).astype(np.float64)
        my = np.einsum('kn,kn->k', a, dy).astype(np.float64)
        spread2 = np.einsum('kn,kn->k', a, d2).astype(np.float64) - (mx * mx + my * my)
        ex, ey = observers[:, 0] + mx, observers[:, 1] + my
        best = a.argmax(axis=1)
        rows = np.arange(k)
        best_x, best_y = x[rows, best], y[rows, best]

        if degenerate.any():
            # Re-initialised below; uniform weights keep the resampling well defined.
            a[degenerate] = np.float32(1.0 / self._n)
        new_x, new_y = self._resample(a, x, y, k)
        self._roughen(new_x, new_y, k)

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
        self._estimate[slots, 0] = ex
        self._estimate[slots, 1] = ey
        self._spread[slots] = np.sqrt(np.maximum(spread2, 0.0))
        self._best[slots, 0] = best_x
        self._best[slots, 1] = best_y
        self._updated[slots] = True
        self._any_updated = True
        self._n_updates[slots] += 1
        if len(extra):
            self._n_updates[slots] += np.bincount(extra[:, 0].astype(np.int64), minlength=k)

        reinitialised: list[int] = []
        if degenerate.any():
            for row in np.flatnonzero(degenerate):
                slot = int(slots[row])
                self._reinitialise(slot, observers[row])
                reinitialised.append(self._ids[slot])
        return reinitialised

    def _resample(
        self, weights: np.ndarray, x: np.ndarray, y: np.ndarray, k: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Draw N particles per row in proportion to ``weights``; return new x, y (k, N)."""
        n = self._n
        counts = self._counts[:k]
        if self._cfg.resampling == 'systematic':
            offsets = self._rng.random((k, 1), dtype=np.float32)
            systematic_counts(weights, offsets, out=counts, work=self._buf_cum[:k])
        else:
            probabilities = weights.astype(np.float64)
            probabilities /= probabilities.sum(axis=1, keepdims=True)
            counts[:] = self._rng.multinomial(n, probabilities)
        index = np.repeat(self._flat_index[: k * n], counts.ravel())
        new_x = self._buf_nx[:k]
        new_y = self._buf_ny[:k]
        np.take(x.ravel(), index, out=new_x.ravel())
        np.take(y.ravel(), index, out=new_y.ravel())
        return new_x, new_y

    def _roughen(self, x: np.ndarray, y: np.ndarray, k: int) -> None:
        """Add N(0, sigma_r^2) jitter per coordinate, sigma_r = kappa E N^(-1/2), floored."""
        cfg = self._cfg
        scale = cfg.roughening_kappa / math.sqrt(self._n)
        x_lo, x_hi = x.min(axis=1), x.max(axis=1)  # float32, as the jitter scale
        y_lo, y_hi = y.min(axis=1), y.max(axis=1)
        sx = np.maximum(scale * (x_hi - x_lo), cfg.roughening_floor_m)
        sy = np.maximum(scale * (y_hi - y_lo), cfg.roughening_floor_m)
        need = 2 * k * self._n
        if need <= self._pool.size:
            start = int(self._rng.integers(0, self._pool.size - need + 1))
            noise = self._pool[start : start + need].reshape(2, k, self._n)
        else:
            noise = self._rng.standard_normal((2, k, self._n), dtype=np.float32)
        b = self._buf_b[:k]
        np.multiply(noise[0], sx[:, None], out=b)
        x += b
        np.multiply(noise[1], sy[:, None], out=b)
        y += b
        # Clipping is skipped when no jitter from the pool can push a particle out (the bound
        # is loose, so a skipped clip would not have changed anything).
        field = self._field_size_m
        reach = 1.001 * self._pool_abs_max * max(float(sx.max()), float(sy.max())) + 0.01
        inside = (
            need <= self._pool.size
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
        for slot in np.flatnonzero(self._updated[: len(self._ids)]):
            window = self._window[slot]
            count = self._window_count[slot]
            window[count % cfg.window] = self._estimate[slot]
            self._window_count[slot] = count + 1
            self._updated[slot] = False
            if self._converged[slot] or count + 1 < cfg.window:
                continue
            if estimates_converged(float(self._spread[slot]), window, cfg.r_conv_m, cfg.r_err_m):
                self._converged[slot] = True

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
