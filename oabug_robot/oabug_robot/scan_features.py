"""What the controller needs from one lidar scan: wall ahead, robot ahead, the side walls.

The scan is read the way REP 117 defines it: NaN is an erroneous reading (ignored), +inf is
"nothing within range" (free space), -inf is "closer than range_min" (an obstacle at
range_min), and finite values outside [range_min, range_max] are ignored. Returns that
belong to a peer robot are recognised with the peers' AoA bearings: within the angular
window a bearing defines (its tolerance plus the angle a peer's body spans), the nearest
return and everything within one body diameter behind it belong to the peer. Those returns
count as "another robot", never as wall, so wall following and wall hits ignore peers and
robot hits ignore walls.

Only returns within the feature range (``PerceptionConfig.feature_range_m``, at least the
capture and hit distances) are looked at: nothing farther changes what the controller
does, and the arrays stay short. Everything is vectorized over the rays.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from oabug_robot.errors import ScanError
from oabug_robot.settings import PerceptionConfig

__all__ = [
    'MIN_ANGLE_INCREMENT_RAD',
    'LaserScanData',
    'ScanFeatureExtractor',
    'ScanFeatures',
    'SideWall',
    'check_scan_frame',
]

_NO_ANGLES = np.zeros(0)
# Returns spread less than this along the robot [m] give no line fit: the side wall is then
# taken parallel at the nearest return.
MIN_FIT_SPREAD_M = 0.05


class LaserScanData(NamedTuple):
    """The parts of a sensor_msgs/LaserScan the controller reads (a named tuple: one is built
    per scan and robot, several times faster than a frozen dataclass).

    Attributes:
        ranges_m: (N,) ranges [m], NaN/inf allowed (REP 117).
        angle_min_rad: angle of the first ray in the lidar frame [rad].
        angle_increment_rad: angle between rays [rad], non-zero.
        range_min_m: smallest valid range [m].
        range_max_m: largest valid range [m].
    """

    ranges_m: np.ndarray
    angle_min_rad: float
    angle_increment_rad: float
    range_min_m: float
    range_max_m: float


#: Finest angle step a scan may have [rad]: 62,832 rays a revolution (the RPLidar A1 gives
#: about 1,450; its driver at most 4,096).
MIN_ANGLE_INCREMENT_RAD = 1e-4


def check_scan_frame(scan: LaserScanData, angle_max_rad: float) -> None:
    """Check that a received scan describes (part of) one lidar revolution.

    A scan whose limits cannot be read would otherwise pass as free space: with a NaN
    ``range_max`` every return is filtered out, and no return reads as no wall.

    Raises:
        ScanError: no rays; an angle that is not finite; an increment finer than
            :data:`MIN_ANGLE_INCREMENT_RAD` or rays spanning more than a revolution; a ray
            count that disagrees with ``angle_max`` by more than one ray; range limits that
            are not finite or not ``0 <= range_min < range_max``; every range NaN (no valid
            sample, REP 117).
    """
    ranges = scan.ranges_m
    count = len(ranges)
    if count == 0:
        raise ScanError('the scan has no ranges')
    angle_min, increment = scan.angle_min_rad, scan.angle_increment_rad
    if not all(math.isfinite(v) for v in (angle_min, angle_max_rad, increment)):
        raise ScanError('scan angles must be finite')
    step = abs(increment)
    if count > 1 and step < MIN_ANGLE_INCREMENT_RAD:
        msg = f'scan angle_increment {increment:g} rad is finer than {MIN_ANGLE_INCREMENT_RAD:g}'
        raise ScanError(msg)
    if count > 1 and (count - 1) * step > 2.0 * math.pi + 1e-6:
        msg = f'{count} rays of {increment:g} rad span more than a revolution'
        raise ScanError(msg)
    implied = (angle_max_rad - angle_min) / increment + 1.0
    if count > 1 and abs(implied - count) > 1.0 + 1e-6:
        msg = (
            f'{count} ranges, but angle_min {angle_min:g}, angle_max {angle_max_rad:g} and '
            f'angle_increment {increment:g} rad give {implied:.0f}'
        )
        raise ScanError(msg)
    low, high = scan.range_min_m, scan.range_max_m
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 <= low < high):
        msg = f'scan range limits must be finite, 0 <= range_min < range_max: {low:g}, {high:g}'
        raise ScanError(msg)
    if np.isnan(ranges).all():
        raise ScanError('every range of the scan is NaN (no valid sample)')


class SideWall(NamedTuple):
    """The wall beside the robot on one side, from the returns abeam and just behind.

    Attributes:
        distance_m: perpendicular distance from the lidar to the wall line [m]; inf when no
            wall return lies beside the robot within capture range.
        angle_rad: direction of the wall relative to the robot's heading [rad], in
            (-pi/2, pi/2]: 0 when parallel, positive when the wall runs away to the left
            ahead (counter-clockwise); 0 when there is no wall.
        abeam: a wall return lies right beside the lidar (the abeam strip), i.e. the robot
            has not yet passed the end of the wall on this side.
    """

    distance_m: float = math.inf
    angle_rad: float = 0.0
    abeam: bool = False

    @property
    def found(self) -> bool:
        """True when a wall lies on this side within capture range."""
        return math.isfinite(self.distance_m)


class ScanFeatures(NamedTuple):
    """Features of one scan in the robot frame (x forward, y left).

    A named tuple rather than a frozen dataclass: a control step builds one per robot and
    scan, and a tuple is built several times faster.

    Attributes:
        front_wall_m: forward distance [m] to the nearest wall return inside the corridor the
            robot sweeps; inf when the corridor is clear up to the feature range.
        front_robot_m: range [m] of the nearest peer return inside the front cone, or inside
            the contact sector within the contact distance; inf if none.
        left: nearest wall return on the left, abeam or behind (not ahead: a wall ahead
            across a door gap must not pull the follower past the door).
        right: the same on the right.
        near_returns: number of rays that hit something within the feature range.
        peer_returns: number of those attributed to peers.
    """

    front_wall_m: float = math.inf
    front_robot_m: float = math.inf
    left: SideWall = SideWall()
    right: SideWall = SideWall()
    near_returns: int = 0
    peer_returns: int = 0

    def side(self, side: int) -> SideWall:
        """Return the wall on ``side`` (+1 left, -1 right)."""
        return self.left if side > 0 else self.right


class _RayTable:
    """cos/sin of every ray, cached for one scan geometry (it rarely changes)."""

    def __init__(self, angle_min_rad: float, angle_increment_rad: float, count: int) -> None:
        self.key = (angle_min_rad, angle_increment_rad, count)
        self.angles_rad = angle_min_rad + angle_increment_rad * np.arange(count, dtype=float)
        self.angles_rad = np.mod(self.angles_rad + math.pi, 2.0 * math.pi) - math.pi
        self.cos = np.cos(self.angles_rad)
        self.sin = np.sin(self.angles_rad)


class ScanFeatureExtractor:
    """Turns scans (plus the peers' bearings) into :class:`ScanFeatures`."""

    def __init__(self, config: PerceptionConfig) -> None:
        self._config = config
        self._table: _RayTable | None = None
        self._feature_range_m = max(
            config.follow_capture_m,
            config.robot_hit_distance_m,
            config.wall_hit_distance_m,
            config.feature_range_m,
        )

    @property
    def config(self) -> PerceptionConfig:
        """The perception configuration."""
        return self._config

    @property
    def feature_range_m(self) -> float:
        """Returns farther than this [m] change no feature."""
        return self._feature_range_m

    def ray_directions(
        self, scan: LaserScanData, count: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(count,) angles [rad] in the robot frame, in [-pi, pi), and their cos and sin.

        Raises:
            ScanError: the scan's angles are not finite or its increment is zero.
        """
        table = self._rays(scan, count)
        return table.angles_rad, table.cos, table.sin

    def _rays(self, scan: LaserScanData, count: int) -> _RayTable:
        angle_min = scan.angle_min_rad + self._config.lidar_yaw_offset_rad
        key = (angle_min, scan.angle_increment_rad, count)
        if self._table is None or self._table.key != key:
            if not (math.isfinite(angle_min) and math.isfinite(scan.angle_increment_rad)):
                raise ScanError('scan angles must be finite')
            if scan.angle_increment_rad == 0.0 and count > 1:
                raise ScanError('scan angle_increment is zero')
            self._table = _RayTable(angle_min, scan.angle_increment_rad, count)
        return self._table

    def extract(
        self,
        scan: LaserScanData,
        peer_azimuths_rad: np.ndarray = _NO_ANGLES,
        peer_distances_m: np.ndarray | None = None,
        sides: tuple[int, ...] = (1, -1),
    ) -> ScanFeatures:
        """Return the features of ``scan``.

        Args:
            scan: the scan; its ranges may contain NaN and +-inf.
            peer_azimuths_rad: (B,) bearings of the peers heard, robot frame [rad].
            peer_distances_m: (B,) their coarse distances [m], NaN where unknown; None when
                no distance is known at all.
            sides: the sides whose wall is wanted (+1 left, -1 right); a side left out
                reads as "no wall". A robot that follows no wall needs none.

        Raises:
            ScanError: the scan has no rays or its angles are not finite.
        """
        cfg = self._config
        ranges = np.asarray(scan.ranges_m, dtype=float)
        if ranges.ndim != 1 or ranges.size == 0:
            raise ScanError(f'scan must have at least one range, got shape {ranges.shape}')
        rays = self._rays(scan, ranges.size)
        range_min = max(float(scan.range_min_m), 0.0)
        range_max = float(scan.range_max_m)
        too_close = ranges == -math.inf
        if np.count_nonzero(too_close):
            # REP 117: -inf means "too close to measure", i.e. an obstacle at range_min.
            ranges = np.where(too_close, range_min, ranges)
        # Nothing farther than the feature range changes a feature; NaN and +inf fail both tests
        # (NaN compares False without a warning).
        limit = min(range_max, self._feature_range_m)
        keep = ranges >= range_min
        keep &= ranges <= limit
        index = keep.nonzero()[0]
        if index.size == 0:
            return ScanFeatures()
        r = ranges[index]
        cos = rays.cos[index]
        x = r * cos
        y = r * rays.sin[index]

        azimuths = np.asarray(peer_azimuths_rad, dtype=float)
        is_peer = None
        if azimuths.size:
            if peer_distances_m is None:
                distances = np.full(azimuths.size, math.nan)
            else:
                distances = np.asarray(peer_distances_m, dtype=float)
            is_peer = self._peer_mask(r, rays.angles_rad[index], azimuths, distances)
        front = x > 0.0
        front &= np.abs(y) <= cfg.front_half_width_m
        captured = r <= cfg.follow_capture_m
        front_robot = math.inf
        peer_returns = 0
        if is_peer is not None:
            peer_returns = int(np.count_nonzero(is_peer))
            if peer_returns:
                # Peers in the front cone, and peers touching the body ahead of abeam.
                ahead = cos >= math.cos(cfg.robot_cone_half_angle_rad)
                touching = cos >= math.cos(cfg.robot_contact_half_angle_rad)
                touching &= r <= cfg.robot_contact_distance_m
                if cfg.robot_contact_in_path:
                    touching &= np.abs(y) <= cfg.front_half_width_m
                ahead |= touching
                cone = is_peer & ahead
                if np.count_nonzero(cone):
                    front_robot = float(r[cone].min())
                is_wall = ~is_peer
                front &= is_wall
                captured &= is_wall
        front_wall = float(x[front].min()) if np.count_nonzero(front) else math.inf
        beside = captured
        beside &= x <= cfg.side_lookahead_m
        beside &= x >= -cfg.side_window_behind_m
        left = right = SideWall()
        if 1 in sides:
            left = self._side_wall(x, y, beside & (y > 0.0))
        if -1 in sides:
            right = self._side_wall(x, -y, beside & (y < 0.0))
            right = SideWall(right.distance_m, -right.angle_rad, right.abeam)
        return ScanFeatures(
            front_wall_m=front_wall,
            front_robot_m=front_robot,
            left=left,
            right=right,
            near_returns=int(index.size),
            peer_returns=peer_returns,
        )

    def _peer_mask(
        self, r: np.ndarray, angles: np.ndarray, azimuths: np.ndarray, distances: np.ndarray
    ) -> np.ndarray:
        """Return a (K,) mask of the returns that belong to the peers at ``azimuths``.

        Per bearing: the returns within its angular window (tolerance plus the angle a body
        spans at that range), the nearest of them and everything within one body diameter
        behind it. A bearing whose coarse distance is far beyond that nearest return is a
        peer heard through a wall: the wall stays a wall. The node passes only the peers
        that may be near, so the loop is short.

        Args:
            r: (K,) ranges of the returns [m].
            angles: (K,) their directions in the robot frame, in [-pi, pi) [rad].
            azimuths: (B,) peer bearings [rad]; NaN entries are skipped.
            distances: (B,) peer distances [m]; NaN where unknown.
        """
        cfg = self._config
        is_peer = np.zeros(r.size, dtype=bool)
        near = (r <= cfg.peer_mask_range_m).nonzero()[0]
        finite = np.isfinite(azimuths)
        if near.size == 0 or not np.count_nonzero(finite):
            return is_peer
        r_near = r[near]
        half_width = cfg.peer_bearing_tolerance_rad + np.arctan2(cfg.robot_radius_m, r_near)
        # (B, K): which returns lie in the angular window of each bearing.
        azimuths = azimuths[finite]
        bearing = np.arctan2(np.sin(azimuths), np.cos(azimuths))
        offset = np.abs(angles[near] - bearing[:, None])
        window = np.minimum(offset, 2.0 * math.pi - offset) <= half_width
        nearest = np.where(window, r_near, math.inf).min(axis=1)
        # A peer heard far beyond its nearest return is behind a wall: the wall stays a wall
        # (NaN distances compare False: kept).
        heard = np.isfinite(nearest)
        heard &= ~(distances[finite] > cfg.peer_distance_factor * (nearest + cfg.robot_radius_m))
        if not np.count_nonzero(heard):
            return is_peer
        body_m = 2.0 * cfg.robot_radius_m
        mine = window[heard] & (r_near <= (nearest[heard] + body_m)[:, None])
        is_peer[near] = np.logical_or.reduce(mine, axis=0)
        return is_peer

    def _side_wall(self, x: np.ndarray, lateral: np.ndarray, mask: np.ndarray) -> SideWall:
        """Fit the wall beside the robot on one side.

        Args:
            x: (K,) forward coordinates of the returns [m].
            lateral: (K,) their distance towards this side [m] (y on the left, -y on the
                right), so the fit is the same for both sides.
            mask: (K,) the returns of this side's window.

        Returns:
            The wall with its angle as seen on the left; the caller mirrors the right side.
        """
        cfg = self._config
        if not np.count_nonzero(mask):
            return SideWall()
        xs = x[mask]
        ls = lateral[mask]
        # Only the nearest wall: drop returns well beyond the closest lateral distance
        # (a perpendicular wall behind, the far side of a door).
        near = ls <= ls.min() + cfg.side_wall_band_m
        xs = xs[near]
        ls = ls[near]
        abeam = bool(np.count_nonzero((xs >= -cfg.abeam_behind_m) & (ls <= cfg.abeam_reach_m)))
        return self.wall_from_points(xs, ls, abeam)

    def wall_from_points(self, xs: np.ndarray, ls: np.ndarray, abeam: bool) -> SideWall:
        """The wall through the returns of one side's window, nearest band only.

        Args:
            xs: (K,) forward coordinates of the returns [m], K >= 1.
            ls: (K,) their distance towards the side [m].
            abeam: one of them lies abeam (see :class:`SideWall`).

        Returns:
            The wall with its angle as seen on the left; the caller mirrors the right side.
        """
        cfg = self._config
        if xs.size < 3 or xs.max() - xs.min() < MIN_FIT_SPREAD_M:
            return SideWall(distance_m=float(ls.min()), angle_rad=0.0, abeam=abeam)
        angle, distance = _fit_line(xs, ls)
        # Once more without the returns off that line (a corner inside the window). The
        # residual |x sin - l cos + distance| is formed in place (the same operations).
        residual = xs * math.sin(angle)
        residual -= ls * math.cos(angle)
        residual += distance
        on_line = np.abs(residual, out=residual) <= cfg.side_wall_fit_tolerance_m
        if 3 <= np.count_nonzero(on_line) < xs.size:
            angle, distance = _fit_line(xs[on_line], ls[on_line])
        return SideWall(distance_m=distance, angle_rad=angle, abeam=abeam)


def _fit_line(xs: np.ndarray, ls: np.ndarray) -> tuple[float, float]:
    """Least-squares line through (x, lateral) points: (direction [rad], distance [m]).

    The direction is in (-pi/2, pi/2] from the x axis; the distance is from the origin.
    """
    # sum / size is what mean() computes, without its Python-level overhead. Every sum is
    # numpy's (pairwise) sum, no BLAS dot product, so that a compiled copy (the simulator's
    # batch path) can add in the same order and get the same line.
    mx = float(xs.sum()) / xs.size
    ml = float(ls.sum()) / ls.size
    dx = xs - mx
    dl = ls - ml
    angle = math.atan2(float((dx * dl).sum()), float((dx * dx).sum()))
    return angle, abs(mx * math.sin(angle) - ml * math.cos(angle))
