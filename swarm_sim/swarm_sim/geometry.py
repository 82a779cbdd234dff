"""Planar geometry kernels shared by the world and the sensor models (numpy, vectorized).

Walls are line segments given as an (M, 2, 2) array: ``walls[m] = [[x0, y0], [x1, y1]]`` in
metres. Robots are discs. Everything here is pure and deterministic.

The lidar caster works per (robot, wall) pair on the angular interval the wall covers as seen
from the robot, so its cost grows with the number of bins actually hit (a few thousand per
robot in a room-and-corridor site) rather than with bins x walls, which makes it much faster
than pybullet's ``rayTestBatch`` for the same rays (docs/notes/simulation.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.angles import wrap_angle

from swarm_sim.errors import WorldGeometryError
from swarm_sim.raycast_kernel import (
    NEAR_MARGIN_M,
    crossings_kernel,
    horizon_scan_kernel,
    nearest_kernel,
    scan_kernel,
)

__all__ = [
    'RayCaster',
    'WallGrid',
    'as_segments',
    'count_crossings',
    'point_segment_distance',
]

TWO_PI = 2.0 * math.pi


def as_segments(walls: object) -> np.ndarray:
    """Return wall segments as a float (M, 2, 2) array, rejecting malformed input."""
    segments = np.asarray(walls, dtype=float)
    if segments.size == 0:
        return np.zeros((0, 2, 2))
    if segments.ndim != 3 or segments.shape[1:] != (2, 2):
        msg = f'wall segments must have shape (M, 2, 2), got {segments.shape}'
        raise WorldGeometryError(msg)
    if not np.all(np.isfinite(segments)):
        raise WorldGeometryError('wall segments contain NaN or inf coordinates')
    lengths = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    if np.any(lengths <= 0.0):
        bad = int(np.flatnonzero(lengths <= 0.0)[0])
        msg = f'wall segment {bad} has zero length: {segments[bad].tolist()}'
        raise WorldGeometryError(msg)
    return segments


def point_segment_distance(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Distance [m] from each point to each segment.

    Args:
        points: (K, 2) array of x, y [m].
        segments: (M, 2, 2) array of segment end points [m].

    Returns:
        (K, M) array of Euclidean distances [m].
    """
    ax, ay = segments[:, 0, 0], segments[:, 0, 1]
    return _distance_to(points, ax, ay, segments[:, 1, 0] - ax, segments[:, 1, 1] - ay)


def _distance_to(
    points: np.ndarray, ax: np.ndarray, ay: np.ndarray, abx: np.ndarray, aby: np.ndarray
) -> np.ndarray:
    """Distance [m] from each of the (K, 2) points to segments from (ax, ay) along (abx, aby),
    given as (M,) arrays shared by every point or as (K, W) arrays, one row per point."""
    inv_len2 = 1.0 / (abx * abx + aby * aby)
    apx = points[:, 0, None] - ax
    apy = points[:, 1, None] - ay
    t = np.clip((apx * abx + apy * aby) * inv_len2, 0.0, 1.0)
    dx = apx - t * abx
    dy = apy - t * aby
    return np.sqrt(dx * dx + dy * dy)


def count_crossings(
    starts: np.ndarray,
    ends: np.ndarray,
    segments: np.ndarray,
    candidates: np.ndarray | None = None,
) -> np.ndarray:
    """Number of wall segments each straight path crosses.

    Args:
        starts: (K, 2) path start points [m].
        ends: (K, 2) path end points [m].
        segments: (M, 2, 2) wall segments [m].
        candidates: optional (K, W) indices into ``segments`` of the only walls path k can
            cross (e.g. from :meth:`WallGrid.candidates`); index M means "no wall".

    Returns:
        (K,) int array: how many segments each path properly intersects.
    """
    if len(segments) == 0 or len(starts) == 0:
        return np.zeros(len(starts), dtype=int)
    q, s = padded_walls(segments)
    if candidates is None:
        candidates = np.broadcast_to(np.arange(len(segments)), (len(starts), len(segments)))
    return _count_hits(starts, ends, q, s, candidates)


def padded_walls(segments: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Wall start points (M + 1, 2) and direction vectors (M + 1, 2) [m]; row M is a
    zero-length "wall" far away that stands for the padding index M."""
    q = np.append(segments[:, 0], [[_FAR, _FAR]], axis=0)
    s = np.append(segments[:, 1] - segments[:, 0], [[0.0, 0.0]], axis=0)
    return q, s


def _count_hits(
    starts: np.ndarray, ends: np.ndarray, q: np.ndarray, s: np.ndarray, candidates: np.ndarray
) -> np.ndarray:
    """Crossings of the (K, 2) paths with their (K, W) candidate walls (``q``, ``s`` as
    :func:`padded_walls` gives them), counted by the compiled kernel."""
    return crossings_kernel(
        np.ascontiguousarray(starts, dtype=float),
        np.ascontiguousarray(ends, dtype=float),
        q,
        s,
        np.asarray(candidates, dtype=np.int64),
    )


def _count_hits_numpy(
    starts: np.ndarray,
    ends: np.ndarray,
    qx: np.ndarray,
    qy: np.ndarray,
    s: np.ndarray,
    candidates: np.ndarray,
) -> np.ndarray:
    """Crossings of the paths with the candidate walls (start ``qx``, ``qy`` per candidate,
    directions ``s`` per wall index): the numpy reference of :func:`_count_hits`."""
    sx, sy = s[:, 0][candidates], s[:, 1][candidates]
    px, py = starts[:, 0, None], starts[:, 1, None]
    rx, ry = (ends[:, 0] - starts[:, 0])[:, None], (ends[:, 1] - starts[:, 1])[:, None]
    denom = rx * sy - ry * sx
    qpx, qpy = qx - px, qy - py
    t_num = qpx * sy - qpy * sx
    u_num = qpx * ry - qpy * rx
    # Proper intersection: 0 <= t <= 1 and 0 <= u <= 1 with t = t_num/denom, u = u_num/denom,
    # tested without dividing (the sign of denom flips both inequalities).
    sign = np.sign(denom)
    t_s, u_s, d_s = t_num * sign, u_num * sign, np.abs(denom)
    hit = (d_s > 0.0) & (t_s >= 0.0) & (t_s <= d_s) & (u_s >= 0.0) & (u_s <= d_s)
    return hit.sum(axis=1)


_FAR = 1e12
# RayCaster.scan_near: the cell size of the grid of the faces near each cell [m].
_NEAR_FACE_CELL_M = 0.5


class WallGrid:
    """Uniform grid telling which walls lie within ``reach_m`` of any point of a cell."""

    def __init__(self, segments: np.ndarray, *, cell_m: float, reach_m: float) -> None:
        """Index ``segments`` ((M, 2, 2) [m]) on square cells of ``cell_m`` metres."""
        segments = as_segments(segments)
        self.cell_m = float(cell_m)
        self.num_segments = len(segments)
        self._q, self._s = padded_walls(segments)
        if len(segments) == 0:
            self._origin = np.zeros(2)
            self._shape = (1, 1)
            self._table = np.zeros((1, 1), dtype=int)
            return
        lo = segments.reshape(-1, 2).min(axis=0) - reach_m
        hi = segments.reshape(-1, 2).max(axis=0) + reach_m
        shape = np.maximum(np.ceil((hi - lo) / self.cell_m).astype(int), 1)
        self._origin = lo
        self._shape = (int(shape[0]), int(shape[1]))
        ix, iy = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing='ij')
        centres = lo + (np.column_stack([ix.ravel(), iy.ravel()]) + 0.5) * self.cell_m
        near = point_segment_distance(centres, segments) <= reach_m + self.cell_m * math.sqrt(0.5)
        counts = near.sum(axis=1)
        width = max(int(counts.max()), 1)
        # Per cell, its walls in index order (a stable sort puts the near ones first), then
        # the padding index.
        first = np.argsort(~near, axis=1, kind='stable')[:, :width]
        self._table = np.where(np.arange(width) < counts[:, None], first, len(segments))

    def candidates(self, points: np.ndarray) -> np.ndarray:
        """(K, W) indices of the walls near each of the (K, 2) points; padding is M."""
        cell = np.floor((np.asarray(points, dtype=float) - self._origin) / self.cell_m).astype(int)
        cx = np.clip(cell[:, 0], 0, self._shape[0] - 1)
        cy = np.clip(cell[:, 1], 0, self._shape[1] - 1)
        return self._table[cx * self._shape[1] + cy]

    def kernel_arguments(
        self,
    ) -> tuple[float, float, float, int, int, np.ndarray, np.ndarray, np.ndarray]:
        """The grid as the compiled kernels take it: origin x, y [m], cell size [m], shape,
        wall table and the padded walls (see :func:`~swarm_sim.raycast_kernel.nearest_kernel`)."""
        return (
            float(self._origin[0]),
            float(self._origin[1]),
            self.cell_m,
            self._shape[0],
            self._shape[1],
            self._table,
            self._q,
            self._s,
        )

    def nearest_distance(self, points: np.ndarray) -> np.ndarray:
        """(K,) distance [m] from each of the (K, 2) points to the nearest wall.

        Exact (the value :func:`point_segment_distance` gives) where it is at most
        ``reach_m``; elsewhere some larger value, since only the walls near a point's cell
        are measured.
        """
        return nearest_kernel(np.ascontiguousarray(points, dtype=float), *self.kernel_arguments())

    def nearest_distance_reference(self, points: np.ndarray) -> np.ndarray:
        """:meth:`nearest_distance` in numpy, the reference of the compiled kernel."""
        candidates = self.candidates(points)
        q = self._q[candidates]
        s = self._s[candidates]
        with np.errstate(divide='ignore', invalid='ignore'):
            # The zero-length padding "wall" lies 1e12 m away; its NaN is dropped below.
            distance = _distance_to(points, q[..., 0], q[..., 1], s[..., 0], s[..., 1])
        return np.fmin.reduce(distance, axis=1, initial=np.inf)

    def count_crossings(
        self, starts: np.ndarray, ends: np.ndarray, candidates: np.ndarray | None = None
    ) -> np.ndarray:
        """Like :func:`count_crossings` for paths that stay within ``reach_m`` of their
        (K, 2) ``starts``: only the walls near each start are tested.

        Args:
            starts: (K, 2) path start points [m].
            ends: (K, 2) path end points [m].
            candidates: ``self.candidates(starts)`` when the caller has it already.
        """
        if self.num_segments == 0 or len(starts) == 0:
            return np.zeros(len(starts), dtype=int)
        if candidates is None:
            candidates = self.candidates(starts)
        return _count_hits(starts, ends, self._q, self._s, candidates)


def _expand_intervals(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Expand integer intervals [start, start + count) into (owner, index) pairs."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    first = np.cumsum(counts) - counts
    offsets = np.arange(total) - np.repeat(first, counts)
    return owner, np.repeat(starts, counts) + offsets


@dataclass(frozen=True)
class _Pairs:
    """(robot, wall face) pairs of one scan and the bins each face covers."""

    robot: np.ndarray
    normal_x: np.ndarray
    normal_y: np.ndarray
    face_m: np.ndarray
    first: np.ndarray
    counts: np.ndarray
    distance_m: np.ndarray

    @classmethod
    def empty(cls) -> _Pairs:
        z = np.zeros(0)
        zi = np.zeros(0, dtype=int)
        return cls(zi, z, z, z, zi, zi, z)

    @property
    def size(self) -> int:
        return len(self.robot)

    def select(self, mask: np.ndarray) -> _Pairs:
        return _Pairs(
            self.robot[mask],
            self.normal_x[mask],
            self.normal_y[mask],
            self.face_m[mask],
            self.first[mask],
            self.counts[mask],
            self.distance_m[mask],
        )


class RayCaster:
    """360-degree planar range caster against thick wall segments and other robots' discs.

    Bin ``k`` of a scan points at ``angle_min_rad + k * 2 pi / num_bins`` in the robot frame
    (REP 103: counter-clockwise from the robot's x axis), ``angle_min_rad = -pi``. Rays start at
    the robot's centre and ignore the robot's own disc.
    """

    def __init__(
        self,
        walls: np.ndarray,
        *,
        wall_thickness_m: float,
        robot_radius_m: float,
        num_bins: int,
        near_range_m: float = 2.0,
    ) -> None:
        """Prepare the caster.

        Args:
            walls: (M, 2, 2) wall centre lines [m].
            wall_thickness_m: full wall thickness [m]; rays stop at the wall's face.
            robot_radius_m: radius of every robot disc [m].
            num_bins: number of equally spaced rays per revolution.
            near_range_m: faces closer than this are cast first; farther faces are skipped
                where the near ones already hide them (a speed-up only: results are exact).
        """
        if num_bins < 4:
            msg = f'num_bins must be at least 4, got {num_bins}'
            raise WorldGeometryError(msg)
        segments = as_segments(walls)
        half = 0.5 * wall_thickness_m
        caps = np.zeros((0, 2, 2))
        if len(segments):
            direction = segments[:, 1] - segments[:, 0]
            direction /= np.linalg.norm(direction, axis=1)[:, None]
            normal = np.column_stack([-direction[:, 1], direction[:, 0]])
            # The wall box reaches half a thickness beyond each end point; its two short end
            # faces are cast as separate zero-thickness segments (rays along the wall hit them).
            segments = np.stack(
                [segments[:, 0] - half * direction, segments[:, 1] + half * direction], axis=1
            )
            if half > 0.0:
                ends = np.concatenate([segments[:, 0], segments[:, 1]])
                side = np.concatenate([normal, normal]) * half
                caps = np.stack([ends - side, ends + side], axis=1)
                # Sign telling on which side of each cap segment its outward face lies.
                cap_ab = caps[:, 1] - caps[:, 0]
                cap_normal = np.column_stack([cap_ab[:, 1], -cap_ab[:, 0]])
                outward = np.concatenate([-direction, direction])
                self._cap_outward = np.sign(np.einsum('ij,ij->i', cap_normal, outward))
                # An end face buried in another wall (corner, T-junction) is never hit.
                centre_ends = np.concatenate([segments[:, 0], segments[:, 1]]) + np.concatenate(
                    [direction, -direction]
                ) * (half * 1.5)
                owner = np.concatenate([np.arange(len(segments)), np.arange(len(segments))])
                reach = point_segment_distance(centre_ends, segments)
                reach[np.arange(len(owner)), owner] = np.inf
                exposed = reach.min(axis=1) > half
                caps = caps[exposed]
                self._cap_outward = self._cap_outward[exposed]
        if len(caps) == 0:
            self._cap_outward = np.zeros(0)
        self._all_segments = np.concatenate([segments, caps]) if len(caps) else segments
        self._all_half = np.concatenate([np.full(len(segments), half), np.zeros(len(caps))])
        self._all_outward = np.concatenate([np.zeros(len(segments)), self._cap_outward])
        # Per-face columns, contiguous, for the per-scan gathers.
        all_segments = self._all_segments
        self._ax, self._ay = all_segments[:, 0, 0].copy(), all_segments[:, 0, 1].copy()
        self._bx, self._by = all_segments[:, 1, 0].copy(), all_segments[:, 1, 1].copy()
        self._one_sided = np.flatnonzero(self._all_outward != 0.0)
        # The same faces as rows for the compiled kernel.
        self._faces = np.column_stack(
            [self._ax, self._ay, self._bx, self._by, self._all_half, self._all_outward]
        )
        self.near_range_m = near_range_m
        self._sector_bins = max(1, num_bins // 36)
        self._half_thickness_m = half
        self._robot_radius_m = float(robot_radius_m)
        self.num_bins = int(num_bins)
        self.angle_min_rad = -math.pi
        self.angle_increment_rad = TWO_PI / self.num_bins
        self._bin_offsets_rad = self.angle_min_rad + self.angle_increment_rad * np.arange(
            self.num_bins
        )
        # A ray's direction is its bin's fixed direction rotated by the robot's yaw.
        self._cos_offsets = np.cos(self._bin_offsets_rad)
        self._sin_offsets = np.sin(self._bin_offsets_rad)
        # scan_near: the faces near each grid cell, per cut, and the robots' certificates.
        self._near_faces: dict[float, tuple[float, float, float, int, int, np.ndarray]] = {}
        self._certificates = np.full((0, self.num_bins), -1, dtype=np.int64)

    @property
    def bin_angles_rad(self) -> np.ndarray:
        """(num_bins,) robot-frame angle of every bin [rad]."""
        return self._bin_offsets_rad.copy()

    def _arc_bins(
        self, yaw: np.ndarray, angle_a: np.ndarray, angle_b: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """First bin and bin count of the shorter arc between two world angles, per pair."""
        inc = self.angle_increment_rad
        ua = (angle_a - yaw - self.angle_min_rad) / inc
        du = (wrap_angle(angle_b - angle_a)) / inc
        lo = np.minimum(ua, ua + du)
        hi = np.maximum(ua, ua + du)
        first = np.ceil(lo).astype(int)
        counts = np.maximum(np.floor(hi).astype(int) - first + 1, 0)
        return first, counts

    def scan(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """Exact ranges [m] of every bin for every robot; ``inf`` where nothing is in range.

        Args:
            poses: (N, 3) array of x [m], y [m], yaw [rad] of every robot; each robot's rays
                also hit the other robots' discs.
            max_range_m: rays longer than this return ``inf``.

        Returns:
            (N, num_bins) float array of ranges [m] from each robot's centre.
        """
        poses = np.asarray(poses, dtype=float)
        n = len(poses)
        nb = self.num_bins
        best = np.full(n * nb, np.inf)
        if n == 0:
            return best.reshape(0, nb)
        scan_kernel(
            np.ascontiguousarray(poses[:, :2]),
            np.ascontiguousarray(poses[:, 2]),
            self._cos_offsets,
            self._sin_offsets,
            self._faces,
            self.angle_min_rad,
            self.angle_increment_rad,
            float(max_range_m),
            float(self.near_range_m),
            self._sector_bins,
            self._robot_radius_m,
            self._robot_radius_m**2,
            best,
        )
        best[best > max_range_m] = np.inf
        return best.reshape(n, nb)

    def scan_near(
        self, poses: np.ndarray, max_range_m: float, cut_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`scan` where only the ranges up to ``cut_m`` are needed.

        Returns the ranges and, per bin, its kind
        (:data:`~swarm_sim.raycast_kernel.NO_RETURN`, ``EXACT`` or ``BEYOND_CUT``): a bin
        is exact (its range equal to :meth:`scan`'s bit for bit) where :meth:`scan` reads at
        most ``cut_m``, "beyond the cut" where :meth:`scan` reads a finite range beyond it
        (the range returned is then meaningless), "no return" where :meth:`scan` reads
        ``inf``. Each robot casts only the walls within ``cut_m`` and decides for its other
        rays whether they end within ``max_range_m`` by testing the faces along them (see
        :func:`~swarm_sim.raycast_kernel.horizon_scan_kernel`).

        Args:
            poses: (N, 3) x [m], y [m], yaw [rad] of every robot.
            max_range_m: rays longer than this return nothing.
            cut_m: the ranges wanted exactly [m], ``0 < cut_m < max_range_m``.

        Returns:
            (N, num_bins) ranges [m] and (N, num_bins) uint8 kinds.
        """
        if not 0.0 < cut_m < max_range_m:
            msg = f'need 0 < cut_m < max_range_m, got {cut_m} and {max_range_m}'
            raise WorldGeometryError(msg)
        poses = np.asarray(poses, dtype=float)
        n = len(poses)
        nb = self.num_bins
        best = np.empty(n * nb)
        kind = np.empty(n * nb, dtype=np.uint8)
        if n == 0:
            return best.reshape(0, nb), kind.reshape(0, nb)
        if len(self._certificates) != n:
            self._certificates = np.full((n, nb), -1, dtype=np.int64)
        horizon_scan_kernel(
            np.ascontiguousarray(poses[:, :2]),
            np.ascontiguousarray(poses[:, 2]),
            self._cos_offsets,
            self._sin_offsets,
            self._faces,
            self.angle_min_rad,
            self.angle_increment_rad,
            float(max_range_m),
            self._robot_radius_m,
            self._robot_radius_m**2,
            float(cut_m),
            self._near_face_grid(float(cut_m)),
            self._certificates,
            best,
            kind,
        )
        return best.reshape(n, nb), kind.reshape(n, nb)

    def _near_face_grid(self, cut_m: float) -> tuple[float, float, float, int, int, np.ndarray]:
        """The faces within ``cut_m`` (plus their half thickness and a margin) of each cell
        of a 0.5 m grid, as :func:`~swarm_sim.raycast_kernel.horizon_scan_kernel` takes them
        (the padding index is the number of faces)."""
        grid = self._near_faces.get(cut_m)
        if grid is None:
            faces = self._all_segments
            if len(faces) == 0:
                table = np.zeros((1, 1), dtype=np.int64)
                grid = (0.0, 0.0, 1.0, 1, 1, table)
            else:
                # A face farther than cut + margin lies beyond cut_m by more than rounding.
                reach = cut_m + self._half_thickness_m + NEAR_MARGIN_M
                wall_grid = WallGrid(faces, cell_m=_NEAR_FACE_CELL_M, reach_m=reach)
                x, y, cell, sx, sy, table, _, _ = wall_grid.kernel_arguments()
                grid = (x, y, cell, sx, sy, np.ascontiguousarray(table, dtype=np.int64))
            self._near_faces[cut_m] = grid
        return grid

    def scan_reference(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """:meth:`scan` in numpy, the reference the compiled kernel is tested against (same
        ranges; see :mod:`swarm_sim.raycast_kernel`)."""
        poses = np.asarray(poses, dtype=float)
        n = len(poses)
        nb = self.num_bins
        best = np.full(n * nb, np.inf)
        if n == 0:
            return best.reshape(0, nb)
        origin = poses[:, :2]
        yaw = poses[:, 2]
        # Every bin's fixed direction rotated by the robot's yaw, in the kernel's order.
        cos_yaw = np.cos(yaw)[:, None]
        sin_yaw = np.sin(yaw)[:, None]
        co = self._cos_offsets[None, :]
        so = self._sin_offsets[None, :]
        ray_dir = ((cos_yaw * co - sin_yaw * so).ravel(), (sin_yaw * co + cos_yaw * so).ravel())
        near, far = self._segment_pairs(origin, yaw, max_range_m)
        self._fill(near, ray_dir, best)
        if n > 1:
            self._scan_discs(origin, yaw, ray_dir, max_range_m, best)
        if far.size:
            self._fill(far.select(self._may_be_visible(far, best)), ray_dir, best)
        best[best > max_range_m] = np.inf
        return best.reshape(n, nb)

    def _segment_pairs(
        self, origin: np.ndarray, yaw: np.ndarray, max_range_m: float
    ) -> tuple[_Pairs, _Pairs]:
        """Every (robot, segment face) pair within range that covers a bin, with the face's
        bin interval: those within ``near_range_m`` and the farther ones."""
        segs = self._all_segments
        if len(segs) == 0:
            return _Pairs.empty(), _Pairs.empty()
        dist = point_segment_distance(origin, segs)
        near = dist <= max_range_m + self._all_half
        # An end face is seen only from in front of it: cull the pairs where it faces away.
        capped = self._one_sided
        if len(capped):
            ax, ay = self._ax[capped], self._ay[capped]
            rel_x = origin[:, 0, None] - ax
            rel_y = origin[:, 1, None] - ay
            side = rel_x * (self._by[capped] - ay) - rel_y * (self._bx[capped] - ax)
            near[:, capped] &= side * self._all_outward[capped] > 0.0
        robot_idx, seg_idx = np.nonzero(near)
        if len(robot_idx) == 0:
            return _Pairs.empty(), _Pairs.empty()
        half = self._all_half[seg_idx]
        ox = origin[robot_idx, 0]
        oy = origin[robot_idx, 1]
        ax = self._ax[seg_idx] - ox
        ay = self._ay[seg_idx] - oy
        bx = self._bx[seg_idx] - ox
        by = self._by[seg_idx] - oy
        # The unit normal of the face, oriented from the robot towards the wall.
        nx = by - ay
        ny = -(bx - ax)
        length = np.sqrt(nx * nx + ny * ny)
        nx /= length
        ny /= length
        offset = ax * nx + ay * ny
        flip = offset < 0.0
        nx[flip] *= -1.0
        ny[flip] *= -1.0
        face = np.maximum(np.abs(offset) - half, 1e-6)
        # The angular interval is the one of the face nearest to the robot.
        first, counts = self._arc_bins(
            yaw[robot_idx],
            np.arctan2(ay - half * ny, ax - half * nx),
            np.arctan2(by - half * ny, bx - half * nx),
        )
        distance = np.maximum(dist[robot_idx, seg_idx] - half, 0.0)
        pairs = _Pairs(
            robot=robot_idx,
            normal_x=nx,
            normal_y=ny,
            face_m=face,
            first=first % self.num_bins,
            counts=counts,
            distance_m=distance,
        )
        covers = counts > 0
        close = distance <= self.near_range_m
        return pairs.select((covers & close).nonzero()[0]), pairs.select(
            (covers & ~close).nonzero()[0]
        )

    def _may_be_visible(self, pairs: _Pairs, best: np.ndarray) -> np.ndarray:
        """Conservative occlusion test: False where every bin of the face's interval is
        already closer than the face can be (checked on sectors of bins)."""
        nb = self.num_bins
        width = self._sector_bins
        sectors = -(-nb // width)
        padded = np.full((len(best) // nb, sectors * width), np.inf)
        padded[:, :nb] = best.reshape(-1, nb)
        sector_max = padded.reshape(len(padded), sectors, width).max(axis=2)
        s0 = pairs.first // width
        s1 = (pairs.first + pairs.counts - 1) // width
        owner, s = _expand_intervals(s0, s1 - s0 + 1)
        values = sector_max[pairs.robot[owner], s % sectors]
        starts = np.cumsum(s1 - s0 + 1) - (s1 - s0 + 1)
        farthest = np.maximum.reduceat(values, starts)
        return farthest >= pairs.distance_m

    def _fill(
        self, pairs: _Pairs, ray_dir: tuple[np.ndarray, np.ndarray], best: np.ndarray
    ) -> None:
        """Lower ``best`` (flat N * num_bins ranges) with the hits on the pairs' faces."""
        if pairs.size == 0:
            return
        owner, k = _expand_intervals(pairs.first, pairs.counts)
        k %= self.num_bins
        flat = pairs.robot[owner] * self.num_bins + k
        along = ray_dir[0][flat] * pairs.normal_x[owner] + ray_dir[1][flat] * pairs.normal_y[owner]
        with np.errstate(divide='ignore'):
            ranges = np.where(along > 1e-9, pairs.face_m[owner] / along, np.inf)
        np.minimum.at(best, flat, ranges)

    def _scan_discs(
        self,
        origin: np.ndarray,
        yaw: np.ndarray,
        ray_dir: tuple[np.ndarray, np.ndarray],
        max_range_m: float,
        best: np.ndarray,
    ) -> None:
        """Lower ``best`` with the hits on the other robots' discs."""
        radius = self._robot_radius_m
        delta = origin[None, :, :] - origin[:, None, :]
        dist = np.linalg.norm(delta, axis=2)
        np.fill_diagonal(dist, np.inf)
        viewer, target = np.nonzero((dist <= max_range_m + radius) & (dist > radius))
        if len(viewer) == 0:
            return
        d = dist[viewer, target]
        centre = np.arctan2(delta[viewer, target, 1], delta[viewer, target, 0])
        half = np.arcsin(np.clip(radius / d, 0.0, 1.0))
        first, counts = self._arc_bins(yaw[viewer], centre - half, centre + half)
        owner, k = _expand_intervals(first, counts)
        k %= self.num_bins
        flat = viewer[owner] * self.num_bins + k
        c = delta[viewer, target][owner]
        s = ray_dir[0][flat] * c[:, 0] + ray_dir[1][flat] * c[:, 1]
        h2 = d[owner] ** 2 - s**2
        inside = (h2 <= radius**2) & (s > 0.0)
        ranges = np.where(inside, s - np.sqrt(np.maximum(radius**2 - h2, 0.0)), np.inf)
        np.minimum.at(best, flat, ranges)
