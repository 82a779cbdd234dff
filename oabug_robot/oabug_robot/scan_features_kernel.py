"""Scan features of many robots in one compiled call: what
:meth:`oabug_robot.scan_features.ScanFeatureExtractor.extract` returns for each of them.

numba is optional: the simulation install compiles these loops, a robot install (no numba)
runs the same Python loops uncompiled, with the same results; the robots themselves run the
numpy extractor, which stays the reference. The batch sweep path
(:func:`oabug_robot.robot_loop.extract_features`) hands every scan of a control step to
:func:`extract_many_flat` instead of calling the extractor once per robot. The features are
bit-identical (``test_scan_features_kernel.py`` compares them on random scans with NaN and
+-inf ranges, empty scans and peers with NaN bearings and distances):

* the transcendental functions stay in numpy (``arctan2``, ``sin``, ``cos``), computed for
  all robots at once: numpy's vectorised ``arctan2`` differs from the C library's in the last
  place for about 1 % of arguments, and its value of an element does not depend on the
  array around it;
* the kernel does only comparisons, products, sums of two terms and minima, in the same
  order as the numpy code: the ray selection, the peer mask, the front corridor and cone,
  and the returns of the followed side's window (nearest band, abeam flag);
* the line fit of the side wall
  (:meth:`~oabug_robot.scan_features.ScanFeatureExtractor.wall_from_points`) is done here
  too: its sums are numpy's pairwise sums (the extractor uses no BLAS dot product), which
  :func:`pairwise_sum` reproduces addition by addition, and its ``atan2``, ``sin`` and
  ``cos`` are the C library's (``math``) in both.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from functools import lru_cache
from typing import TypeVar

import numpy as np

from oabug_robot.errors import ScanError
from oabug_robot.scan_features import (
    MIN_FIT_SPREAD_M,
    LaserScanData,
    ScanFeatureExtractor,
    ScanFeatures,
    SideWall,
)

_F = TypeVar('_F', bound=Callable[..., object])

try:
    from numba import njit

    HAVE_NUMBA = True
except ImportError:  # a robot install: the same loops run uncompiled (slowly), same results
    HAVE_NUMBA = False

    def njit(*_args: object, **_kwargs: object) -> Callable[[_F], _F]:
        """Stand-in for numba's decorator when numba is not installed: no compilation."""

        def keep(function: _F) -> _F:
            return function

        return keep


__all__ = [
    'HAVE_NUMBA',
    'extract_held',
    'extract_many',
    'extract_many_flat',
    'features_kernel',
    'pairwise_sum',
    'select_kernel',
    'side_wall_fit',
]

_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def _in_window(angle: float, direction: float, half_width: float) -> bool:  # pragma: no cover
    """The ray at ``angle`` lies in the window of a peer bearing ``direction`` [rad]."""
    offset = abs(angle - direction)
    return min(offset, _TWO_PI - offset) <= half_width


# numpy's pairwise summation: blocks up to this many elements are added with 8 accumulators.
_PAIRWISE_BLOCK = 128


@njit(cache=True)
def _block_sum(a: np.ndarray, lo: int, n: int) -> float:  # pragma: no cover - compiled
    """numpy's sum of ``a[lo:lo + n]`` for ``n <= 128``: fewer than 8 values one after the
    other from 0.0, else 8 interleaved partial sums combined as
    ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)), then the rest one by one."""
    if n < 8:
        total = 0.0
        for i in range(lo, lo + n):
            total += a[i]
        return total
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - n % 8:
        b = lo + i
        r0 += a[b]
        r1 += a[b + 1]
        r2 += a[b + 2]
        r3 += a[b + 3]
        r4 += a[b + 4]
        r5 += a[b + 5]
        r6 += a[b + 6]
        r7 += a[b + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for b in range(lo + i, lo + n):
        total += a[b]
    return total


@njit(cache=True)
def pairwise_sum(a: np.ndarray, lo: int, n: int) -> float:  # pragma: no cover - compiled
    """``np.sum(a[lo:lo + n])`` of float64 values, added in numpy's order: blocks of up to
    128 values as :func:`_block_sum`, longer runs split in two halves (the first a multiple
    of 8 long) whose sums are added. numpy recurses; here the recursion runs on an explicit
    stack (numba's on-disk cache does not load recursive functions reliably)."""
    if n <= _PAIRWISE_BLOCK:
        return _block_sum(a, lo, n)
    # Pending ranges: start, length and how far they are (0 new, 1 left half pushed, 2 both).
    depth = 2 * 64
    starts = np.empty(depth, dtype=np.int64)
    lengths = np.empty(depth, dtype=np.int64)
    stages = np.empty(depth, dtype=np.int64)
    sums = np.empty(depth)
    top = 0
    starts[0], lengths[0], stages[0] = lo, n, 0
    done = 0
    while top >= 0:
        start, length, stage = starts[top], lengths[top], stages[top]
        half = length // 2
        half -= half % 8
        if length <= _PAIRWISE_BLOCK:
            sums[done] = _block_sum(a, start, length)
            done += 1
            top -= 1
        elif stage == 0:
            stages[top] = 1
            top += 1
            starts[top], lengths[top], stages[top] = start, half, 0
        elif stage == 1:
            stages[top] = 2
            top += 1
            starts[top], lengths[top], stages[top] = start + half, length - half, 0
        else:
            done -= 1
            sums[done - 1] = sums[done - 1] + sums[done]
            top -= 1
    return sums[0]


@njit(cache=True)
def _fit_line(
    xs: np.ndarray, ls: np.ndarray, n: int, dx: np.ndarray, dl: np.ndarray
) -> tuple:  # pragma: no cover - compiled
    """``oabug_robot.scan_features._fit_line`` of the first ``n`` points: (direction [rad],
    distance [m]); ``dx`` and ``dl`` are scratch of at least ``n`` values."""
    mx = pairwise_sum(xs, 0, n) / n
    ml = pairwise_sum(ls, 0, n) / n
    for m in range(n):
        dx[m] = xs[m] - mx
        dl[m] = ls[m] - ml
    for m in range(n):
        xs_m = dx[m]
        dx[m] = xs_m * xs_m
        dl[m] = xs_m * dl[m]
    angle = math.atan2(pairwise_sum(dl, 0, n), pairwise_sum(dx, 0, n))
    return angle, abs(mx * math.sin(angle) - ml * math.cos(angle))


@njit(cache=True)
def side_wall_fit(
    xs: np.ndarray,
    ls: np.ndarray,
    n: int,
    tolerance: float,
    min_spread: float,
    scratch: np.ndarray,
) -> tuple:  # pragma: no cover - compiled
    """:meth:`~oabug_robot.scan_features.ScanFeatureExtractor.wall_from_points` of the first
    ``n >= 1`` points, without the abeam flag: (distance [m], angle [rad]). ``scratch`` is
    (4, >= n) float64 work space."""
    lo = xs[0]
    hi = xs[0]
    nearest = ls[0]
    for m in range(1, n):
        lo = min(lo, xs[m])
        hi = max(hi, xs[m])
        nearest = min(nearest, ls[m])
    if n < 3 or hi - lo < min_spread:
        return nearest, 0.0
    angle, distance = _fit_line(xs, ls, n, scratch[0], scratch[1])
    # Once more without the returns off that line, as the extractor does.
    sa = math.sin(angle)
    ca = math.cos(angle)
    kept_x = scratch[2]
    kept_l = scratch[3]
    kept = 0
    for m in range(n):
        if abs(xs[m] * sa - ls[m] * ca + distance) <= tolerance:
            kept_x[kept] = xs[m]
            kept_l[kept] = ls[m]
            kept += 1
    if 3 <= kept < n:
        angle, distance = _fit_line(kept_x, kept_l, kept, scratch[0], scratch[1])
    return distance, angle


@njit(cache=True)
def features_kernel(
    ranges: np.ndarray,
    windows: np.ndarray,
    window_half_width: np.ndarray,
    angles: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    bearing_start: np.ndarray,
    bearing: np.ndarray,
    bearing_distance: np.ndarray,
    sides: np.ndarray,
    params: tuple,
    real_out: np.ndarray,
    int_out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Features of K scans of B rays; the outputs are filled in place.

    Args:
        ranges: (K, B) ranges [m], -inf already replaced by range_min.
        windows: the flat (K * B) indices of the rays whose peer window may be read (the
            returns within the peer mask range near a bearing); every other ray is in no
            peer's window.
        window_half_width: the angular half width of a peer's window at those rays'
            ranges [rad].
        angles, cos_t, sin_t: (B,) ray directions in the robot frame.
        bearing_start: (K + 1,) slice bounds of each scan's peers in ``bearing``.
        bearing: (T,) peer bearings wrapped to [-pi, pi] [rad]; NaN to skip.
        bearing_distance: (T,) their coarse distances [m]; NaN where unknown.
        sides: (K,) the side whose wall is wanted: +1 left, -1 right, 0 none.
        params: range_min, limit, front_half_width, follow_capture, cone_cos,
            peer_mask_range, robot_radius, peer_distance_factor, side_lookahead,
            side_window_behind, side_wall_band, abeam_behind, abeam_reach, fit_tolerance,
            min_spread, robot_contact_distance, contact_cos, contact_in_path (1.0: the
            contact rule counts only returns within front_half_width of the path).
        real_out: (K, 4) output per scan: the wall ahead and the robot ahead [m], the
            distance [m] and angle [rad, as seen on the left] of the wanted side's wall
            (read only where its return count is not 0).
        int_out: (K, 4) output per scan: the returns within range, those of peers, the
            returns of the wanted side's nearest band, and 1 where one of them lies abeam.
    """
    (
        range_min,
        limit,
        front_half_width,
        follow_capture,
        cone_cos,
        peer_mask_range,
        radius,
        distance_factor,
        lookahead,
        behind,
        band,
        abeam_behind,
        abeam_reach,
        fit_tolerance,
        min_spread,
        contact,
        contact_cos,
        contact_in_path,
    ) = params
    body = 2.0 * radius
    num_scans, num_rays = ranges.shape
    # NaN: no window (a ray this far from every bearing is in none).
    half_width = np.full((num_scans, num_rays), np.nan)
    for w in range(windows.shape[0]):
        half_width[windows[w] // num_rays, windows[w] % num_rays] = window_half_width[w]
    index = np.empty(num_rays, dtype=np.int64)
    is_peer = np.empty(num_rays, dtype=np.bool_)
    xs = np.empty(num_rays)
    ls = np.empty(num_rays)
    side_x = np.empty(num_rays)
    side_l = np.empty(num_rays)
    scratch = np.empty((4, num_rays))
    for k in range(num_scans):
        front_wall = np.inf
        front_robot = np.inf
        peers = 0
        abeam = 0
        real_out[k, 2] = np.inf
        real_out[k, 3] = 0.0
        int_out[k, 1] = 0
        int_out[k, 2] = 0
        int_out[k, 3] = 0
        kept = 0
        any_near = False
        for j in range(num_rays):
            r = ranges[k, j]
            if r >= range_min and r <= limit:
                index[kept] = j
                is_peer[kept] = False
                kept += 1
                if r <= peer_mask_range:
                    any_near = True
        int_out[k, 0] = kept
        if kept == 0:
            real_out[k, 0] = np.inf
            real_out[k, 1] = np.inf
            continue
        # The peer mask, bearing by bearing.
        if any_near:
            for b in range(bearing_start[k], bearing_start[k + 1]):
                direction = bearing[b]
                if not math.isfinite(direction):
                    continue
                nearest = np.inf
                for m in range(kept):
                    j = index[m]
                    r = ranges[k, j]
                    if (
                        r <= peer_mask_range
                        and r < nearest
                        and _in_window(angles[j], direction, half_width[k, j])
                    ):
                        nearest = r
                if nearest == np.inf:
                    continue
                if bearing_distance[b] > distance_factor * (nearest + radius):
                    continue  # heard far beyond its nearest return: behind a wall
                reach = nearest + body
                for m in range(kept):
                    j = index[m]
                    r = ranges[k, j]
                    if (
                        r <= peer_mask_range
                        and r <= reach
                        and _in_window(angles[j], direction, half_width[k, j])
                    ):
                        is_peer[m] = True
        side = sides[k]
        count = 0
        for m in range(kept):
            j = index[m]
            r = ranges[k, j]
            c = cos_t[j]
            x = r * c
            y = r * sin_t[j]
            if is_peer[m]:
                peers += 1
                ahead = c >= cone_cos or (
                    c >= contact_cos
                    and r <= contact
                    and (contact_in_path == 0.0 or abs(y) <= front_half_width)
                )
                if ahead and r < front_robot:
                    front_robot = r
                continue
            if x > 0.0 and abs(y) <= front_half_width and x < front_wall:
                front_wall = x
            if side == 0 or not (r <= follow_capture and x <= lookahead and x >= -behind):
                continue
            if side > 0 and y > 0.0:
                xs[count] = x
                ls[count] = y
                count += 1
            elif side < 0 and y < 0.0:
                xs[count] = x
                ls[count] = -y
                count += 1
        real_out[k, 0] = front_wall
        real_out[k, 1] = front_robot
        int_out[k, 1] = peers
        if count == 0:
            continue
        # Only the nearest wall: the returns within the band of the closest one.
        closest = ls[0]
        for m in range(1, count):
            closest = min(closest, ls[m])
        cut = closest + band
        kept_side = 0
        for m in range(count):
            if ls[m] <= cut:
                side_x[kept_side] = xs[m]
                side_l[kept_side] = ls[m]
                if xs[m] >= -abeam_behind and ls[m] <= abeam_reach:
                    abeam = 1
                kept_side += 1
        int_out[k, 2] = kept_side
        int_out[k, 3] = abeam
        real_out[k, 2], real_out[k, 3] = side_wall_fit(
            side_x, side_l, kept_side, fit_tolerance, min_spread, scratch
        )


@njit(cache=True)
def select_kernel(
    ranges: np.ndarray,
    range_min: float,
    limit: float,
    peer_mask_range: float,
    held_azimuths: np.ndarray,
    held_distances: np.ndarray,
    held_start: np.ndarray,
    rotation: np.ndarray,
    max_distance: float,
    angles: np.ndarray,
    widest_window: float,
) -> tuple:  # pragma: no cover - compiled
    """What the features of K scans need before the transcendental functions: the -inf
    ranges replaced by ``range_min`` (in place), the peers that may be near and the rays
    whose peer window is read.

    Args:
        ranges: (K, B) ranges [m]; -inf entries are set to ``range_min``.
        range_min, limit: rays with a range in [range_min, limit] are returns.
        peer_mask_range: only returns up to this range can be a peer's.
        held_azimuths: (H,) held peer bearings [rad], the scans' in order.
        held_distances: (H,) their coarse distances [m] (NaN unknown).
        held_start: (K + 1,) slice bounds of each scan's held bearings.
        rotation: (K,) per scan, the angle added to its bearings (the robot's rotation since
            they were heard, ``yaw_at_stamp - yaw`` [rad]); empty: none is added.
        max_distance: bearings whose distance exceeds this are left out (NaN kept).
        angles: (B,) the rays' directions in the robot frame, in [-pi, pi) [rad].
        widest_window: an upper bound of any peer window's half width [rad].

    Returns:
        The kept bearings [rad] and distances [m], their (K + 1,) slice bounds, the indices
        of the finite kept bearings, the flat (K * B) indices of the rays whose peer
        window may be read: the returns within the peer mask range that lie within
        ``widest_window`` of a finite kept bearing (the bearing wrapped here with ``%``,
        within far less than the margin of the wrapped bearing the features use), and
        those rays' ranges [m].
    """
    num_scans, num_rays = ranges.shape
    total = held_azimuths.shape[0]
    azimuths = np.empty(total)
    distances = np.empty(total)
    start = np.empty(num_scans + 1, dtype=np.int64)
    finite = np.empty(total, dtype=np.int64)
    windows = np.empty(num_scans * num_rays, dtype=np.int64)
    window_ranges = np.empty(num_scans * num_rays)
    directions = np.empty(total)
    reach = widest_window + 1e-6
    kept = 0
    num_finite = 0
    num_windows = 0
    rotate = rotation.shape[0] > 0
    for k in range(num_scans):
        start[k] = kept
        first_finite = num_finite
        for b in range(held_start[k], held_start[k + 1]):
            d = held_distances[b]
            if d > max_distance:
                continue
            a = held_azimuths[b] + rotation[k] if rotate else held_azimuths[b]
            azimuths[kept] = a
            distances[kept] = d
            if math.isfinite(a):
                finite[num_finite] = kept
                directions[num_finite] = (a + math.pi) % _TWO_PI - math.pi
                num_finite += 1
            kept += 1
        for j in range(num_rays):
            r = ranges[k, j]
            if r == -np.inf:
                r = range_min
                ranges[k, j] = r
            if not (r >= range_min and r <= limit and r <= peer_mask_range):
                continue
            for f in range(first_finite, num_finite):
                if _in_window(angles[j], directions[f], reach):
                    windows[num_windows] = k * num_rays + j
                    window_ranges[num_windows] = r
                    num_windows += 1
                    break
    start[num_scans] = kept
    return (
        azimuths[:kept],
        distances[:kept],
        start,
        finite[:num_finite],
        windows[:num_windows],
        window_ranges[:num_windows],
    )


@lru_cache(maxsize=64)
def _constants(
    extractor: ScanFeatureExtractor, range_min_m: float, range_max_m: float
) -> tuple[tuple[float, ...], float]:
    """The kernels' constants for an extractor and a scan's range limits (cached per
    extractor object: its configuration is frozen): :func:`features_kernel`'s parameters
    and an upper bound [rad] of the half width of a peer's window, at the shortest range
    (the extractor's tolerance plus the angle a body spans; 1e-9 rad more than
    ``math.atan2`` gives, far beyond numpy's difference from it)."""
    cfg = extractor.config
    params = tuple(
        float(value)
        for value in (
            range_min_m,
            min(range_max_m, extractor.feature_range_m),
            cfg.front_half_width_m,
            cfg.follow_capture_m,
            math.cos(cfg.robot_cone_half_angle_rad),
            cfg.peer_mask_range_m,
            cfg.robot_radius_m,
            cfg.peer_distance_factor,
            cfg.side_lookahead_m,
            cfg.side_window_behind_m,
            cfg.side_wall_band_m,
            cfg.abeam_behind_m,
            cfg.abeam_reach_m,
            cfg.side_wall_fit_tolerance_m,
            MIN_FIT_SPREAD_M,
            cfg.robot_contact_distance_m,
            math.cos(cfg.robot_contact_half_angle_rad),
            1.0 if cfg.robot_contact_in_path else 0.0,
        )
    )
    widest = cfg.peer_bearing_tolerance_rad + math.atan2(cfg.robot_radius_m, range_min_m) + 1e-9
    return params, widest


def _frame(scan: LaserScanData) -> tuple[float, ...]:
    # angle_min_rad, angle_increment_rad, range_min_m, range_max_m (a tuple slice is cheaper
    # than four attribute reads)
    return scan[1:]


def extract_many(
    extractor: ScanFeatureExtractor,
    scans: Sequence[LaserScanData],
    peers: Sequence[tuple[np.ndarray, np.ndarray | None]],
    sides: Sequence[int],
) -> list[ScanFeatures]:
    """The features ``extractor.extract`` gives for each scan, computed in one call.

    Args:
        extractor: the extractor whose configuration (and ray table) every robot shares.
        scans: K scans with the same angles, limits and number of rays.
        peers: per scan, the peers' bearings [rad] and coarse distances [m] (NaN where
            unknown; None: all unknown), as passed to ``extract``.
        sides: per scan, the side whose wall is wanted (+1 left, -1 right, 0 none): the
            same as ``extract(..., sides=(side,) if side else ())``.

    Raises:
        ScanError: the scans have no rays or their angles are not finite.
        ValueError: the scans differ in angles, limits or number of rays, or the
            argument lengths differ.
    """
    if not len(scans) == len(peers) == len(sides):
        msg = f'{len(scans)} scans, {len(peers)} peer sets and {len(sides)} sides'
        raise ValueError(msg)
    counts = [len(azimuths) for azimuths, _ in peers]
    bearing_start = np.zeros(len(scans) + 1, dtype=np.int64)
    np.cumsum(counts, out=bearing_start[1:])
    azimuths = distances = np.zeros(0)
    if bearing_start[-1]:
        azimuths = np.concatenate([np.asarray(a, dtype=float) for a, _ in peers])
        distances = np.concatenate(
            [
                np.full(len(a), math.nan) if d is None else np.asarray(d, dtype=float)
                for a, d in peers
            ]
        )
    return extract_many_flat(extractor, scans, bearing_start, azimuths, distances, sides)


def extract_many_flat(
    extractor: ScanFeatureExtractor,
    scans: Sequence[LaserScanData],
    bearing_start: np.ndarray,
    azimuths: np.ndarray,
    distances: np.ndarray,
    sides: Sequence[int],
) -> list[ScanFeatures]:
    """:func:`extract_many` with the peers of all scans in flat arrays.

    Args:
        extractor: as for :func:`extract_many`.
        scans: K scans, as for :func:`extract_many`.
        bearing_start: (K + 1,) int64 slice bounds of each scan's peers in the arrays below.
        azimuths: (T,) the peers' bearings [rad] (NaN entries skipped).
        distances: (T,) their coarse distances [m], NaN where unknown.
        sides: per scan, the side whose wall is wanted (+1 left, -1 right, 0 none).

    Raises:
        ScanError: the scans have no rays or their angles are not finite.
        ValueError: the scans differ in angles, limits or number of rays, or the
            argument lengths differ.
    """
    if len(bearing_start) != len(scans) + 1 or len(sides) != len(scans):
        msg = f'{len(scans)} scans, {len(bearing_start) - 1} peer sets and {len(sides)} sides'
        raise ValueError(msg)
    if len(azimuths) != bearing_start[-1] or len(distances) != bearing_start[-1]:
        msg = f'{bearing_start[-1]} peers, {len(azimuths)} azimuths, {len(distances)} distances'
        raise ValueError(msg)
    return _extract(
        extractor,
        scans,
        np.asarray(azimuths, dtype=float),
        np.asarray(distances, dtype=float),
        np.asarray(bearing_start, dtype=np.int64),
        _NO_ROTATION,
        math.inf,
        sides,
    )


def extract_held(
    extractor: ScanFeatureExtractor,
    scans: Sequence[LaserScanData],
    held: Sequence[tuple[np.ndarray, np.ndarray, float] | None],
    sides: Sequence[int],
) -> list[ScanFeatures]:
    """What each robot's control loop computes for its scan
    (:meth:`oabug_robot.robot_loop.RobotLoop.update_features`): ``extractor.extract`` of the
    scan with the near peers of the held bearings
    (:meth:`oabug_robot.sound.PeerBearings.near_peers_now`, the same element-wise
    operations), all scans in one compiled call.

    Args:
        extractor: as for :func:`extract_many`.
        scans: K scans, as for :func:`extract_many`.
        held: per scan, what :meth:`~oabug_robot.robot_loop.RobotLoop.peer_bearings` returns:
            the held bearings [rad], their distances [m] and the rotation since they were
            heard [rad], or None.
        sides: per scan, the side whose wall is wanted (+1 left, -1 right, 0 none).

    Raises:
        ScanError: the scans have no rays or their angles are not finite.
        ValueError: the scans differ in angles, limits or number of rays, or the
            argument lengths differ.
    """
    if not len(scans) == len(held) == len(sides):
        msg = f'{len(scans)} scans, {len(held)} peer sets and {len(sides)} sides'
        raise ValueError(msg)
    # The bounds of each scan's bearings (a cumulative sum in Python: numpy's cumsum of a
    # short list costs more than the list).
    start = np.array(
        [0, *itertools.accumulate(0 if h is None else len(h[0]) for h in held)], dtype=np.int64
    )
    rotation = np.array([0.0 if h is None else h[2] for h in held])
    if start[-1]:
        present = [h for h in held if h is not None]
        azimuths = np.concatenate([h[0] for h in present])
        distances = np.concatenate([h[1] for h in present])
    else:
        azimuths = distances = _NO_ROTATION
    return _extract(
        extractor,
        scans,
        np.asarray(azimuths, dtype=float),
        np.asarray(distances, dtype=float),
        start,
        rotation,
        extractor.config.peer_bearing_max_distance_m,
        sides,
    )


_NO_ROTATION = np.zeros(0)
_NO_WALL = SideWall()
_NO_WALL_RIGHT = SideWall(math.inf, -0.0, False)
_NO_FEATURES = ScanFeatures()


def _extract(
    extractor: ScanFeatureExtractor,
    scans: Sequence[LaserScanData],
    held_azimuths: np.ndarray,
    held_distances: np.ndarray,
    held_start: np.ndarray,
    rotation: np.ndarray,
    max_distance: float,
    sides: Sequence[int],
) -> list[ScanFeatures]:
    """The features of the scans with the peers :func:`select_kernel` keeps of the held
    bearings (rotated by ``rotation``, per scan, unless it is empty)."""
    if not scans:
        return []
    first = scans[0]
    frame = _frame(first)
    for scan in scans[1:]:
        if scan[1:] != frame:  # _frame(scan), inline
            raise ValueError('the scans must share their angles and range limits')
    num_rays = np.shape(first.ranges_m)
    if len(num_rays) != 1 or num_rays[0] == 0:
        msg = f'scans must have at least one range, got shape {num_rays}'
        raise ScanError(msg)
    # Every scan's ranges in one array (the kernel rewrites -inf ranges: a copy).
    ranges = np.empty((len(scans), num_rays[0]))
    for i, scan in enumerate(scans):
        ranges[i] = scan.ranges_m
    angles, cos_t, sin_t = extractor.ray_directions(first, ranges.shape[1])
    cfg = extractor.config
    range_min = max(float(first.range_min_m), 0.0)
    params, widest_window = _constants(extractor, range_min, float(first.range_max_m))
    # REP 117: -inf means "too close to measure", i.e. an obstacle at range_min.
    azimuths, distances, start, finite, windows, window_ranges = select_kernel(
        ranges,
        range_min,
        params[1],
        cfg.peer_mask_range_m,
        held_azimuths,
        held_distances,
        held_start,
        rotation,
        max_distance,
        angles,
        widest_window,
    )
    # The transcendental functions in numpy, as the extractor computes them (numpy's value
    # of an element does not depend on the array around it).
    if finite.size == azimuths.size:  # every bearing finite (the common case)
        bearing = np.arctan2(np.sin(azimuths), np.cos(azimuths))
    else:
        bearing = np.full(azimuths.size, math.nan)
        finite_azimuths = azimuths[finite]
        bearing[finite] = np.arctan2(np.sin(finite_azimuths), np.cos(finite_azimuths))
    window_half_width = cfg.peer_bearing_tolerance_rad + np.arctan2(
        cfg.robot_radius_m, window_ranges
    )
    k = len(scans)
    real_out = np.empty((k, 4))
    int_out = np.empty((k, 4), dtype=np.int64)
    features_kernel(
        ranges,
        windows,
        window_half_width,
        angles,
        cos_t,
        sin_t,
        start,
        bearing,
        distances,
        np.asarray(sides, dtype=np.int64),
        params,
        real_out,
        int_out,
    )
    # The outputs as Python numbers once (the same values), not element by element; the
    # named tuples built from their complete field tuples (``_make`` without its checks).
    result = []
    for side, (wall_ahead, robot_ahead, distance, angle), (near, peers, count, abeam) in zip(
        sides, real_out.tolist(), int_out.tolist(), strict=True
    ):
        if near == 0:
            result.append(_NO_FEATURES)
            continue
        left = right = _NO_WALL
        if side > 0 and count:
            left = SideWall(distance, angle, bool(abeam))
        elif side < 0:
            # The extractor mirrors the right side's wall, "no wall" (angle 0.0) too.
            right = SideWall(distance, -angle, bool(abeam)) if count else _NO_WALL_RIGHT
        result.append(ScanFeatures(wall_ahead, robot_ahead, left, right, near, peers))
    return result
