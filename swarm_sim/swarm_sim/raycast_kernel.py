"""Compiled lidar kernel: the ranges :class:`swarm_sim.geometry.RayCaster` computes, in one
numba-compiled loop instead of a few dozen numpy calls per scan.

Simulation only (numba, like pybullet, is a dependency of the simulation install, never of a
robot). The numpy caster (:meth:`~swarm_sim.geometry.RayCaster.scan_reference`) stays the
reference: the kernel performs the same floating-point operations in the same order for every
(robot, face) pair and every bin, so the ranges are bit-identical (``test_geometry_raycaster.py``
checks this on random walls and on a generated site). It relies on two things the tests would
catch if a platform broke them:

* the C library's ``cos``, ``sin``, ``atan2`` and ``asin`` give numpy's values (numpy calls
  the same functions for float64 here; a vectorised numpy build could differ in the last
  place). ``cos`` and ``sin`` of the yaws rotate the bins' fixed directions (precomputed by
  the caster) into the ray directions; ``atan2`` and ``asin`` only decide which
  bins a face's interval covers, so a difference would matter only for a face end within about
  1e-15 rad of a ray;
* no fused multiply-add (numba does not contract without ``fastmath``).

Faces within ``near_range_m`` and the other robots' discs are cast first, then the farther
faces that may still be visible, with the numpy caster's conservative sector test. The kernel
is compiled on first use and cached next to this module (``cache=True``): a process pays the
numba import and the cache load once (docs/notes/simulation.md).

A consumer that reads no range beyond some distance (the OA-Bug batch path) uses the near
cast, :func:`horizon_scan_kernel`: the walls near each robot, cast with the same operations,
and for the other rays only whether they end within the maximum range (which decides the
noise draws), shown by one face each; :func:`horizon_noise_kernel` then draws the noise as
for the full scan. ``test_near_scan.py`` compares both with the full scan.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    'BEYOND_CUT',
    'EXACT',
    'NO_RETURN',
    'crossings_kernel',
    'grid_cell',
    'horizon_noise_kernel',
    'horizon_scan_kernel',
    'lidar_noise_kernel',
    'nearest_kernel',
    'path_hits',
    'scan_kernel',
]

_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def _wrap(angle: float) -> float:  # pragma: no cover - compiled
    """:func:`swarm_sim.geometry.wrap_angle` of one angle (Python's float ``%`` is
    numpy's ``mod``: ``fmod``, moved to the divisor's sign)."""
    wrapped = (angle + math.pi) % _TWO_PI - math.pi
    if wrapped <= -math.pi:
        wrapped += _TWO_PI
    return wrapped


@njit(cache=True)
def _arc(
    yaw: float, angle_a: float, angle_b: float, angle_min: float, inc: float
) -> tuple[int, int]:  # pragma: no cover - compiled
    """First bin and bin count of the shorter arc between two world angles."""
    ua = (angle_a - yaw - angle_min) / inc
    du = _wrap(angle_b - angle_a) / inc
    lo = min(ua, ua + du)
    hi = max(ua, ua + du)
    first = math.ceil(lo)
    return first, math.floor(hi) - first + 1


@njit(cache=True, error_model='numpy')
def _lower(
    best: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    lo: int,
    hi: int,
    nx: float,
    ny: float,
    face: float,
) -> None:  # pragma: no cover - compiled
    """Lower ``best[lo:hi]`` with the hits on a face ``face`` metres away along its unit
    normal (nx, ny); written branch-free so that it compiles to vector instructions."""
    for f in range(lo, hi):
        along = cos_t[f] * nx + sin_t[f] * ny
        r = face / along
        r = r if along > 1e-9 else np.inf
        old = best[f]
        best[f] = r if r < old else old


@njit(cache=True)
def _cast_face(
    best: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    base: int,
    nb: int,
    first: int,
    count: int,
    nx: float,
    ny: float,
    face: float,
) -> None:  # pragma: no cover - compiled
    """Lower the bins ``first .. first + count - 1`` (mod ``nb``, ``count <= nb``) with the
    hits on a face."""
    end = first + count
    _lower(best, cos_t, sin_t, base + first, base + min(end, nb), nx, ny, face)
    if end > nb:
        _lower(best, cos_t, sin_t, base, base + end - nb, nx, ny, face)


@njit(cache=True, error_model='numpy')
def _lower_tracked(
    best: np.ndarray,
    arg: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    lo: int,
    hi: int,
    nx: float,
    ny: float,
    face: float,
    face_id: int,
) -> None:  # pragma: no cover - compiled
    """:func:`_lower` (the same values) that also records in ``arg`` which face lowered
    each bin last."""
    for f in range(lo, hi):
        along = cos_t[f] * nx + sin_t[f] * ny
        r = face / along
        r = r if along > 1e-9 else np.inf
        if r < best[f]:
            best[f] = r
            arg[f] = face_id


@njit(cache=True)
def _cast_face_tracked(
    best: np.ndarray,
    arg: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    base: int,
    nb: int,
    first: int,
    count: int,
    nx: float,
    ny: float,
    face: float,
    face_id: int,
) -> None:  # pragma: no cover - compiled
    """:func:`_cast_face` with :func:`_lower_tracked`."""
    end = first + count
    _lower_tracked(
        best, arg, cos_t, sin_t, base + first, base + min(end, nb), nx, ny, face, face_id
    )
    if end > nb:
        _lower_tracked(best, arg, cos_t, sin_t, base, base + end - nb, nx, ny, face, face_id)


@njit(cache=True)
def _ray_directions(
    yaw: np.ndarray,
    cos_offsets: np.ndarray,
    sin_offsets: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Every robot's ray directions, as the reference computes them: every bin's fixed
    direction rotated by the robot's yaw (bin-major per robot)."""
    nb = cos_offsets.shape[0]
    for i in range(yaw.shape[0]):
        cy = math.cos(yaw[i])
        sy = math.sin(yaw[i])
        for k in range(nb):
            cos_t[i * nb + k] = cy * cos_offsets[k] - sy * sin_offsets[k]
            sin_t[i * nb + k] = sy * cos_offsets[k] + cy * sin_offsets[k]


@njit(cache=True)
def _face_distance(ox: float, oy: float, faces: np.ndarray, j: int) -> tuple:  # pragma: no cover
    """Distance [m] from (ox, oy) to face ``j``'s segment, and the vectors from its start
    to the point and to its end (x, y of each)."""
    fax = faces[j, 0]
    fay = faces[j, 1]
    abx = faces[j, 2] - fax
    aby = faces[j, 3] - fay
    inv_len2 = 1.0 / (abx * abx + aby * aby)
    apx = ox - fax
    apy = oy - fay
    t = min(max((apx * abx + apy * aby) * inv_len2, 0.0), 1.0)
    dx = apx - t * abx
    dy = apy - t * aby
    return math.sqrt(dx * dx + dy * dy), apx, apy, abx, aby


@njit(cache=True)
def _face_interval(
    ox: float,
    oy: float,
    yaw: float,
    faces: np.ndarray,
    j: int,
    max_range_m: float,
    angle_min: float,
    inc: float,
    nb: int,
) -> tuple:  # pragma: no cover - compiled
    """Face ``j`` as a robot at (ox, oy) heading ``yaw`` sees it: (first bin, bin count,
    unit normal x, y towards the face, the face's distance along that normal [m], its
    distance from the robot [m]). The count is 0 when the face is out of range, faces away
    (a one-sided end face) or covers no bin."""
    fax = faces[j, 0]
    fay = faces[j, 1]
    fbx = faces[j, 2]
    fby = faces[j, 3]
    half = faces[j, 4]
    outward = faces[j, 5]
    dist, apx, apy, abx, aby = _face_distance(ox, oy, faces, j)
    if not dist <= max_range_m + half:
        return 0, 0, 0.0, 0.0, 0.0, 0.0
    if outward != 0.0 and not (apx * aby - apy * abx) * outward > 0.0:
        return 0, 0, 0.0, 0.0, 0.0, 0.0
    ax = fax - ox
    ay = fay - oy
    bx = fbx - ox
    by = fby - oy
    nx = by - ay
    ny = -(bx - ax)
    length = math.sqrt(nx * nx + ny * ny)
    nx /= length
    ny /= length
    offset = ax * nx + ay * ny
    if offset < 0.0:
        nx = -nx
        ny = -ny
    face = max(abs(offset) - half, 1e-6)
    first, count = _arc(
        yaw,
        math.atan2(ay - half * ny, ax - half * nx),
        math.atan2(by - half * ny, bx - half * nx),
        angle_min,
        inc,
    )
    if count <= 0:
        return 0, 0, 0.0, 0.0, 0.0, 0.0
    return first % nb, count, nx, ny, face, max(dist - half, 0.0)


@njit(cache=True)
def _cast_discs(
    i: int,
    origin: np.ndarray,
    yaw: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    angle_min: float,
    inc: float,
    max_range_m: float,
    robot_radius_m: float,
    radius2: float,
    best: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Lower robot ``i``'s bins with its hits on the other robots' discs."""
    n = origin.shape[0]
    nb = best.shape[0] // n
    base = i * nb
    ox = origin[i, 0]
    oy = origin[i, 1]
    for j in range(n):
        if j == i:
            continue
        cx = origin[j, 0] - ox
        cy = origin[j, 1] - oy
        d = math.sqrt(cx * cx + cy * cy)
        if not (d <= max_range_m + robot_radius_m and d > robot_radius_m):
            continue
        centre = math.atan2(cy, cx)
        half_angle = math.asin(min(max(robot_radius_m / d, 0.0), 1.0))
        first, count = _arc(yaw[i], centre - half_angle, centre + half_angle, angle_min, inc)
        first %= nb
        d2 = d * d
        for o in range(count):
            f = base + (first + o) % nb
            s = cos_t[f] * cx + sin_t[f] * cy
            h2 = d2 - s * s
            if h2 <= radius2 and s > 0.0:
                r = s - math.sqrt(max(radius2 - h2, 0.0))
                if r < best[f]:
                    best[f] = r


@njit(cache=True)
def _cast_robot(
    i: int,
    origin: np.ndarray,
    yaw: np.ndarray,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    faces: np.ndarray,
    angle_min: float,
    inc: float,
    max_range_m: float,
    near_range_m: float,
    sector_bins: int,
    robot_radius_m: float,
    radius2: float,
    best: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Lower robot ``i``'s bins with every face and disc hit (see :func:`scan_kernel`)."""
    nb = cos_t.shape[0] // origin.shape[0]
    num_faces = faces.shape[0]
    far_first = np.empty(num_faces, dtype=np.int64)
    far_count = np.empty(num_faces, dtype=np.int64)
    far_nx = np.empty(num_faces)
    far_ny = np.empty(num_faces)
    far_face = np.empty(num_faces)
    far_distance = np.empty(num_faces)
    sectors = -(-nb // sector_bins)
    sector_max = np.empty(sectors)
    ox = origin[i, 0]
    oy = origin[i, 1]
    base = i * nb
    num_far = 0
    for j in range(num_faces):
        first, count, nx, ny, face, distance = _face_interval(
            ox, oy, yaw[i], faces, j, max_range_m, angle_min, inc, nb
        )
        if count <= 0:
            continue
        if distance <= near_range_m:
            _cast_face(best, cos_t, sin_t, base, nb, first, count, nx, ny, face)
        else:
            far_first[num_far] = first
            far_count[num_far] = count
            far_nx[num_far] = nx
            far_ny[num_far] = ny
            far_face[num_far] = face
            far_distance[num_far] = distance
            num_far += 1
    _cast_discs(
        i, origin, yaw, cos_t, sin_t, angle_min, inc, max_range_m, robot_radius_m, radius2, best
    )
    if num_far == 0:
        return
    for sector in range(sectors):
        # Bins past the last one (a partial last sector) count as empty (inf).
        top = -np.inf if (sector + 1) * sector_bins <= nb else np.inf
        for k in range(sector * sector_bins, min((sector + 1) * sector_bins, nb)):
            top = max(top, best[base + k])
        sector_max[sector] = top
    for p in range(num_far):
        first = far_first[p]
        s0 = first // sector_bins
        s1 = (first + far_count[p] - 1) // sector_bins
        farthest = -np.inf
        for sector in range(s0, s1 + 1):
            farthest = max(farthest, sector_max[sector % sectors])
        if farthest >= far_distance[p]:
            _cast_face(
                best,
                cos_t,
                sin_t,
                base,
                nb,
                first,
                far_count[p],
                far_nx[p],
                far_ny[p],
                far_face[p],
            )


@njit(cache=True, error_model='numpy')
def scan_kernel(
    origin: np.ndarray,
    yaw: np.ndarray,
    cos_offsets: np.ndarray,
    sin_offsets: np.ndarray,
    faces: np.ndarray,
    angle_min: float,
    inc: float,
    max_range_m: float,
    near_range_m: float,
    sector_bins: int,
    robot_radius_m: float,
    radius2: float,
    best: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Lower ``best`` ((N * B,) ranges [m], bin-major per robot) with every face and disc hit.

    As in the numpy caster, faces within ``near_range_m`` and the other robots' discs are cast
    first; a farther face is skipped when every sector of ``sector_bins`` bins its interval
    touches already holds only ranges shorter than the face's distance (exact: it could not
    lower any of them).

    Args:
        origin: (N, 2) robot centres [m].
        yaw: (N,) robot headings [rad].
        cos_offsets: (B,) cosine of the robot-frame angle of every bin.
        sin_offsets: (B,) sine of the robot-frame angle of every bin.
        faces: (F, 6) per face: start x, y, end x, y [m], half thickness [m] and the outward
            sign of a one-sided end face (0 for a two-sided wall).
        angle_min: robot-frame angle of bin 0 [rad].
        inc: angle between bins [rad].
        max_range_m: faces farther than this (plus their half thickness) are skipped.
        near_range_m: faces up to this distance [m] are cast before the occlusion test.
        sector_bins: bins per sector of the occlusion test.
        robot_radius_m: radius of the robots' discs [m].
        radius2: ``robot_radius_m ** 2`` as the reference computes it.
        best: ranges to lower in place.
    """
    n = origin.shape[0]
    nb = cos_offsets.shape[0]
    cos_t = np.empty(n * nb)
    sin_t = np.empty(n * nb)
    _ray_directions(yaw, cos_offsets, sin_offsets, cos_t, sin_t)
    for i in range(n):
        _cast_robot(
            i,
            origin,
            yaw,
            cos_t,
            sin_t,
            faces,
            angle_min,
            inc,
            max_range_m,
            near_range_m,
            sector_bins,
            robot_radius_m,
            radius2,
            best,
        )


#: Kinds of bin of :func:`horizon_scan_kernel`: no return within the maximum range, a
#: return whose exact range is given, a return beyond the cut (its range not computed).
NO_RETURN, EXACT, BEYOND_CUT = 0, 1, 2
#: A face this much farther than the cut [m] cannot end a ray within it (by far more than
#: the rounding of a range).
NEAR_MARGIN_M = 0.05


@njit(cache=True)
def _certifies(
    k: int,
    base: int,
    first: int,
    count: int,
    nx: float,
    ny: float,
    face: float,
    cos_t: np.ndarray,
    sin_t: np.ndarray,
    nb: int,
    max_range_m: float,
) -> bool:  # pragma: no cover - compiled
    """The face (its interval and normal from :func:`_face_interval`) lowers bin ``k`` to
    at most ``max_range_m``, with :func:`_lower`'s operations: the full cast's range of that
    bin is then finite."""
    if count <= 0 or (k - first) % nb >= count:
        return False
    f = base + k
    along = cos_t[f] * nx + sin_t[f] * ny
    return along > 1e-9 and face / along <= max_range_m


@njit(cache=True)
def _misses(
    j: int, faces: np.ndarray, ox: float, oy: float, dx: float, dy: float
) -> bool:  # pragma: no cover - compiled
    """The line through (ox, oy) along the unit direction (dx, dy) passes both ends of face
    ``j`` on the same side, farther than its half thickness plus 1 nm: no ray along it
    can lie in the face's bin interval (:func:`_face_interval`'s arc between the ends of
    the face's near side, each within the half thickness of an end)."""
    margin = faces[j, 4] + 1e-9
    side_a = dx * (faces[j, 1] - oy) - dy * (faces[j, 0] - ox)
    side_b = dx * (faces[j, 3] - oy) - dy * (faces[j, 2] - ox)
    return (side_a > margin and side_b > margin) or (side_a < -margin and side_b < -margin)


@njit(cache=True)
def _face_view(
    j: int,
    i: int,
    ox: float,
    oy: float,
    yaw: float,
    faces: np.ndarray,
    max_range_m: float,
    angle_min: float,
    inc: float,
    nb: int,
    view: np.ndarray,
    view_int: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """Hold :func:`_face_interval` of face ``j`` for robot ``i`` in ``view`` (normal x, y,
    face distance) and ``view_int`` (robot, first bin, count), unless it is held already."""
    if view_int[j, 0] == i:
        return
    first, count, nx, ny, face, _ = _face_interval(
        ox, oy, yaw, faces, j, max_range_m, angle_min, inc, nb
    )
    view_int[j, 0] = i
    view_int[j, 1] = first
    view_int[j, 2] = count
    view[j, 0] = nx
    view[j, 1] = ny
    view[j, 2] = face


@njit(cache=True, error_model='numpy')
def horizon_scan_kernel(
    origin: np.ndarray,
    yaw: np.ndarray,
    cos_offsets: np.ndarray,
    sin_offsets: np.ndarray,
    faces: np.ndarray,
    angle_min: float,
    inc: float,
    max_range_m: float,
    robot_radius_m: float,
    radius2: float,
    cut_m: float,
    grid: tuple,
    certificates: np.ndarray,
    best: np.ndarray,
    kind: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """:func:`scan_kernel` where only ranges up to ``cut_m`` are needed: per bin, its kind
    (:data:`NO_RETURN`, :data:`EXACT` or :data:`BEYOND_CUT`) and, where exact, its range,
    both equal to the full cast's: no return, a range up to ``cut_m`` (bit for bit), a
    farther range.

    Per robot, only the faces ``grid`` lists for its cell (every face within ``reach`` of
    a point of the cell, ``reach`` beyond ``cut_m`` by the half thickness and a margin) and
    the discs are cast, with the full cast's operations. A bin they bring to at most
    ``cut_m`` is exact: every other face lies farther than ``cut_m`` and cannot lower it. A
    bin they leave beyond ``max_range_m`` has a return in the full cast if and only if some
    face lowers it to within ``max_range_m`` (:func:`_certifies`, the full cast's test).
    Such a face is looked for first among the faces that ended the same world direction
    (and its neighbours) in earlier scans (``certificates``), then along the ray: from
    ``cut_m`` on, every ``2 cut_m`` up to ``max_range_m``, among the faces the grid lists
    for the point's cell. The face the ray hits lies within ``cut_m < reach`` of one of
    those points, so a bin for which none is found has no return.

    Args:
        origin .. sin_offsets, faces, angle_min, inc, max_range_m, robot_radius_m, radius2:
            as for :func:`scan_kernel`.
        cut_m: ranges up to this are computed exactly [m], ``0 < cut_m < max_range_m``.
        grid: the faces near each cell: origin x, y [m], cell size [m], cells along x and
            y, and the (cells, W) table of face indices (F pads), with reach beyond
            ``cut_m``.
        certificates: (N, B) per robot and world direction bin, the face that ended the
            ray last (-1: none); updated.
        best: (N * B,) output ranges [m], bin-major per robot; read only where exact.
        kind: (N * B,) output kinds.
    """
    n = origin.shape[0]
    nb = cos_offsets.shape[0]
    num_faces = faces.shape[0]
    grid_x, grid_y, cell_m, shape_x, shape_y, table = grid
    width = table.shape[1]
    step = 2.0 * cut_m
    near_m = cut_m + NEAR_MARGIN_M
    cos_t = np.empty(n * nb)
    sin_t = np.empty(n * nb)
    _ray_directions(yaw, cos_offsets, sin_offsets, cos_t, sin_t)
    arg = np.empty(nb, dtype=np.int64)
    # Per face, the robot whose view of it is held (robot, first bin, count; normal, face).
    view_int = np.full((num_faces, 3), -1, dtype=np.int64)
    view = np.empty((num_faces, 3))
    for i in range(n):
        ox = origin[i, 0]
        oy = origin[i, 1]
        base = i * nb
        for k in range(nb):
            best[base + k] = np.inf
            arg[k] = -1
        row = grid_cell(ox, oy, grid_x, grid_y, cell_m, shape_x, shape_y)
        for w in range(width):
            j = table[row, w]
            if j >= num_faces:
                break
            # Only the faces that may end a ray within the cut (the grid lists more).
            if _face_distance(ox, oy, faces, j)[0] - faces[j, 4] > near_m:
                continue
            _face_view(j, i, ox, oy, yaw[i], faces, max_range_m, angle_min, inc, nb, view, view_int)
            if view_int[j, 2] > 0:
                _cast_face_tracked(
                    best[base : base + nb],
                    arg,
                    cos_t[base : base + nb],
                    sin_t[base : base + nb],
                    0,
                    nb,
                    view_int[j, 1],
                    view_int[j, 2],
                    view[j, 0],
                    view[j, 1],
                    view[j, 2],
                    j,
                )
        _cast_discs(
            i,
            origin,
            yaw,
            cos_t,
            sin_t,
            angle_min,
            inc,
            max_range_m,
            robot_radius_m,
            radius2,
            best,
        )
        # The world direction bin of robot bin k is k + shift (mod B).
        shift = round(yaw[i] / inc)
        for k in range(nb):
            if best[base + k] <= max_range_m:
                continue
            direction = (k + shift) % nb
            # Cast the faces that ended this world direction or its neighbours before.
            for attempt in range(3):
                j = certificates[i, (direction + (attempt + 1) // 2 * (1 - 2 * (attempt % 2))) % nb]
                if j < 0 or view_int[j, 0] == i:
                    continue
                _face_view(
                    j, i, ox, oy, yaw[i], faces, max_range_m, angle_min, inc, nb, view, view_int
                )
                if view_int[j, 2] > 0:
                    _cast_face_tracked(
                        best[base : base + nb],
                        arg,
                        cos_t[base : base + nb],
                        sin_t[base : base + nb],
                        0,
                        nb,
                        view_int[j, 1],
                        view_int[j, 2],
                        view[j, 0],
                        view[j, 1],
                        view[j, 2],
                        j,
                    )
                if best[base + k] <= max_range_m:
                    break
            # Along the ray: the face it hits lies within reach of one of these points.
            along = cut_m
            while best[base + k] > max_range_m and along - step < max_range_m:
                px = ox + along * cos_t[base + k]
                py = oy + along * sin_t[base + k]
                cell = grid_cell(px, py, grid_x, grid_y, cell_m, shape_x, shape_y)
                for w in range(width):
                    j = table[cell, w]
                    if j >= num_faces:
                        break
                    if _misses(j, faces, ox, oy, cos_t[base + k], sin_t[base + k]):
                        continue
                    _face_view(
                        j,
                        i,
                        ox,
                        oy,
                        yaw[i],
                        faces,
                        max_range_m,
                        angle_min,
                        inc,
                        nb,
                        view,
                        view_int,
                    )
                    if _certifies(
                        k,
                        base,
                        view_int[j, 1],
                        view_int[j, 2],
                        view[j, 0],
                        view[j, 1],
                        view[j, 2],
                        cos_t,
                        sin_t,
                        nb,
                        max_range_m,
                    ):
                        _cast_face_tracked(
                            best[base : base + nb],
                            arg,
                            cos_t[base : base + nb],
                            sin_t[base : base + nb],
                            0,
                            nb,
                            view_int[j, 1],
                            view_int[j, 2],
                            view[j, 0],
                            view[j, 1],
                            view[j, 2],
                            j,
                        )
                        break
                along += step
        for k in range(nb):
            r = best[base + k]
            if arg[k] >= 0:
                certificates[i, (k + shift) % nb] = arg[k]
            if r <= cut_m:
                kind[base + k] = EXACT
            elif r <= max_range_m:
                kind[base + k] = BEYOND_CUT
            else:
                kind[base + k] = NO_RETURN


@njit(cache=True)
def horizon_noise_kernel(
    exact: np.ndarray,
    kind: np.ndarray,
    normal: np.ndarray,
    uniform: np.ndarray,
    noise_fraction: float,
    noise_min_m: float,
    dropout_probability: float,
    range_min_m: float,
    range_max_m: float,
    horizon_m: float,
    cut_m: float,
    redo: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """:func:`lidar_noise_kernel` of a :func:`horizon_scan_kernel` cast, with every noisy
    range beyond ``horizon_m`` read as ``inf``.

    An exact bin gets :func:`lidar_noise_kernel`'s value. A bin beyond the cut draws its
    normal as a finite range does and reads ``inf`` when even its smallest possible noisy
    range (the exact range being at least ``cut_m``) lies beyond ``horizon_m`` and
    ``range_min_m``; otherwise
    its robot is flagged in ``redo`` (the caller casts it in full and calls again; with
    ``cut_m`` a few noise standard deviations beyond ``horizon_m`` this never happens in
    practice).

    Args:
        exact: (N, B) ranges [m] of the exact bins.
        kind: (N * B,) the bins' kinds.
        normal, uniform, noise_fraction .. range_max_m: as for :func:`lidar_noise_kernel`.
        horizon_m: noisy ranges beyond this read ``inf`` [m]; less than ``cut_m``.
        cut_m: the cut of the cast [m].
        redo: (N,) bool, set for the robots with a bin that needs its exact range.
    """
    noisy = exact.copy()
    flat = noisy.ravel()
    drops = uniform.ravel()
    nb = exact.shape[1]
    # A noisy range above this reads inf with the horizon (and not -inf below range_min).
    floor = max(horizon_m, range_min_m) + 1e-6
    used = 0
    for f in range(flat.shape[0]):
        r = flat[f]
        what = kind[f]
        if what == BEYOND_CUT:
            n_draw = normal[used]
            used += 1
            if n_draw < 0.0:
                # r >= cut: r + n max(a r, b) >= cut (1 + n a) + n b while 1 + n a >= 0.
                low = 1.0 + n_draw * noise_fraction
                if not (low >= 0.0 and cut_m * low + n_draw * noise_min_m > floor):
                    redo[f // nb] = True
            flat[f] = np.inf
            continue
        if what == EXACT:
            r = r + normal[used] * max(noise_fraction * r, noise_min_m)
            used += 1
        else:
            r = np.inf
        if dropout_probability > 0.0 and drops[f] < dropout_probability:
            r = np.inf
        if r > range_max_m:
            r = np.inf
        if r < range_min_m:
            r = -np.inf
        if r > horizon_m:
            r = np.inf
        flat[f] = r
    return noisy


@njit(cache=True)
def path_hits(
    px: float, py: float, ex: float, ey: float, walls: np.ndarray, q: np.ndarray, s: np.ndarray
) -> int:  # pragma: no cover - compiled
    """How many of the walls ``walls`` (indices into ``q``, ``s``) the path from (px, py)
    to (ex, ey) properly crosses: ``geometry._count_hits_numpy``'s test, same operations."""
    rx = ex - px
    ry = ey - py
    hits = 0
    for w in range(walls.shape[0]):
        m = walls[w]
        sx = s[m, 0]
        sy = s[m, 1]
        denom = rx * sy - ry * sx
        qpx = q[m, 0] - px
        qpy = q[m, 1] - py
        t_num = qpx * sy - qpy * sx
        u_num = qpx * ry - qpy * rx
        # The reference multiplies by sign(denom) (-1, 0 or 1) and takes abs(denom).
        sign = 1.0 if denom > 0.0 else (-1.0 if denom < 0.0 else 0.0)
        t_s = t_num * sign
        u_s = u_num * sign
        d_s = abs(denom)
        if d_s > 0.0 and t_s >= 0.0 and t_s <= d_s and u_s >= 0.0 and u_s <= d_s:
            hits += 1
    return hits


@njit(cache=True)
def crossings_kernel(
    starts: np.ndarray,
    ends: np.ndarray,
    q: np.ndarray,
    s: np.ndarray,
    candidates: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """Number of candidate walls each path crosses: ``geometry._count_hits_numpy``'s test,
    same operations, so the same integers.

    Args:
        starts: (K, 2) path start points [m].
        ends: (K, 2) path end points [m].
        q: (M + 1, 2) wall start points [m] (row M: the far padding "wall").
        s: (M + 1, 2) wall direction vectors [m] (row M: zero).
        candidates: (K, W) wall indices per path.
    """
    k_paths = starts.shape[0]
    counts = np.zeros(k_paths, dtype=np.int64)
    for k in range(k_paths):
        counts[k] = path_hits(
            starts[k, 0], starts[k, 1], ends[k, 0], ends[k, 1], candidates[k], q, s
        )
    return counts


@njit(cache=True)
def grid_cell(
    px: float,
    py: float,
    origin_x: float,
    origin_y: float,
    cell_m: float,
    shape_x: int,
    shape_y: int,
) -> int:  # pragma: no cover - compiled
    """Row of ``WallGrid``'s table for the point (px, py): ``WallGrid.candidates``' cell."""
    cx = min(max(math.floor((px - origin_x) / cell_m), 0), shape_x - 1)
    cy = min(max(math.floor((py - origin_y) / cell_m), 0), shape_y - 1)
    return cx * shape_y + cy


@njit(cache=True, error_model='numpy')
def nearest_kernel(
    points: np.ndarray,
    origin_x: float,
    origin_y: float,
    cell_m: float,
    shape_x: int,
    shape_y: int,
    table: np.ndarray,
    q: np.ndarray,
    s: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """``WallGrid.nearest_distance``: per point, the distance to the nearest wall of its
    cell's table row, with the numpy version's operations (the padding "wall", whose NaN
    ``fmin`` drops, is skipped).

    Args:
        points: (K, 2) query points [m].
        origin_x: grid origin x [m].
        origin_y: grid origin y [m].
        cell_m: cell size [m].
        shape_x: number of cells along x.
        shape_y: number of cells along y.
        table: (cells, W) wall indices per cell.
        q: (M + 1, 2) wall start points [m].
        s: (M + 1, 2) wall direction vectors [m].
    """
    k_points = points.shape[0]
    out = np.empty(k_points)
    for k in range(k_points):
        px = points[k, 0]
        py = points[k, 1]
        row = grid_cell(px, py, origin_x, origin_y, cell_m, shape_x, shape_y)
        best = np.inf
        for w in range(table.shape[1]):
            m = table[row, w]
            abx = s[m, 0]
            aby = s[m, 1]
            if abx == 0.0 and aby == 0.0:
                continue  # the padding (walls have non-zero length)
            inv_len2 = 1.0 / (abx * abx + aby * aby)
            apx = px - q[m, 0]
            apy = py - q[m, 1]
            t = (apx * abx + apy * aby) * inv_len2
            t = min(max(t, 0.0), 1.0)
            dx = apx - t * abx
            dy = apy - t * aby
            d = math.sqrt(dx * dx + dy * dy)
            if d < best:
                best = d
        out[k] = best
    return out


@njit(cache=True)
def lidar_noise_kernel(
    exact: np.ndarray,
    normal: np.ndarray,
    uniform: np.ndarray,
    noise_fraction: float,
    noise_min_m: float,
    dropout_probability: float,
    range_min_m: float,
    range_max_m: float,
) -> np.ndarray:  # pragma: no cover - compiled
    """``LidarModel``'s noisy ranges from exact ones, with the numpy version's operations.

    Args:
        exact: (N, B) exact ranges [m] (``inf`` for no return).
        normal: one standard normal draw per finite range, in row-major order.
        uniform: (N, B) uniform draws of the dropouts (unused if the probability is 0).
        noise_fraction: noise standard deviation as a fraction of the range.
        noise_min_m: floor of that standard deviation [m].
        dropout_probability: chance that a sample is lost.
        range_min_m: closer returns read ``-inf``.
        range_max_m: farther returns read ``inf``.
    """
    noisy = exact.copy()
    flat = noisy.ravel()
    drops = uniform.ravel()
    used = 0
    for f in range(flat.shape[0]):
        r = flat[f]
        if math.isfinite(r):
            r = r + normal[used] * max(noise_fraction * r, noise_min_m)
            used += 1
        if dropout_probability > 0.0 and drops[f] < dropout_probability:
            r = np.inf
        if r > range_max_m:
            r = np.inf
        if r < range_min_m:
            r = -np.inf
        flat[f] = r
    return noisy


@njit(cache=True)
def sight_lines_kernel(
    points: np.ndarray, range_m: float, q: np.ndarray, s: np.ndarray, walls: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # pragma: no cover
    """Every ordered pair of distinct points (receiver i, transmitter j) in row-major order,
    with the same operations as ``BearingModel.measure_reference``.

    Args:
        points: (N, 2+) positions [m].
        range_m: walls are counted only on lines up to this long [m].
        q: (M + 1, 2) wall start points, s: (M + 1, 2) wall directions (padded walls).
        walls: (W,) the walls to count (empty: none).

    Returns:
        (L,) receivers, (L,) transmitters, (L, 2) offsets j - i [m], (L,) distances [m] and
        (L,) walls crossed (0 beyond ``range_m``), L = N (N - 1).
    """
    n = points.shape[0]
    pairs = n * (n - 1)
    receiver = np.empty(pairs, dtype=np.int64)
    transmitter = np.empty(pairs, dtype=np.int64)
    delta = np.empty((pairs, 2))
    distance = np.empty(pairs)
    crossed = np.zeros(pairs, dtype=np.int64)
    k = 0
    for i in range(n):
        for j in range(n):
            if i == j:
                continue
            receiver[k] = i
            transmitter[k] = j
            delta[k, 0] = points[j, 0] - points[i, 0]
            delta[k, 1] = points[j, 1] - points[i, 1]
            distance[k] = math.hypot(delta[k, 0], delta[k, 1])
            if walls.shape[0] and distance[k] <= range_m:
                crossed[k] = path_hits(
                    points[i, 0], points[i, 1], points[j, 0], points[j, 1], walls, q, s
                )
            k += 1
    return receiver, transmitter, delta, distance, crossed
