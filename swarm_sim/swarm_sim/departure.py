"""Where the robots start: the paper's fan of preferred directions around a departure point,
placed in the site's free space.

Directions (paper Sec. II-B; the same formulas the OA-Bug node uses for its preferred
directions, so a robot's first heading is its preferred direction):

* centre departure: phi_i = bias + i * 360 deg / n, the paper's formula; the bias "can be an
  arbitrary value, but it is the same for all robots that depart simultaneously". It is drawn
  from the run's seed, uniform over the full circle (the authors' statistics runner draws an
  integer degree in [-179, 180]).
* edge departure: a half circle into the building, phi_i = bias + (i + 1/2) * 180 deg / n
  with bias = (direction into the building) - 90 deg + offset. The paper gives no edge
  formula; the seeded offset is uniform in [-90 / n, +90 / n] deg, the widest turn of the fan
  that keeps every direction in the half-plane into the building. The authors' statistics
  runner draws its edge bias over the full circle, so part of its fan faces the outer wall
  2.5 cells away; their deterministic runner uses a fixed 0..180 deg fan.

Places: robot i's nominal start is ``start_radius_m`` from the departure point along phi_i
(the authors' simulator: 2 cells, 0.53 m), facing phi_i. :func:`place_starts` keeps every
nominal start that is in free space: a robot's radius plus half a wall's thickness from every
wall, at least two radii from the robots placed before, and reachable from the departure
point along a straight line that keeps the departure point's own clearance from every wall
(so no robot starts behind a wall). The others move to the nearest such place on a grid of
a fifth of a radius, in robot order. On a generated site's edge departure the nominal half
circle of 10 robots puts neighbours 0.17 m apart, closer than the 0.2 m of two bodies, so
about half of them move, by up to a few decimetres; in a narrow corridor the fan becomes
rows along it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Final

import numpy as np

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import count_crossings, point_segment_distance
from swarm_sim.sites.errors import SiteError
from swarm_sim.sites.model import DeparturePoint, Site
from swarm_sim.sites.validation import free_space_raster, point_segment_distances
from swarm_sim.world import BodyConfig

__all__ = [
    'DEFAULT_START_RADIUS_M',
    'StartPlacement',
    'departure_poses',
    'fan_bias_rad',
    'fan_kind',
    'free_space_capacity',
    'place_starts',
    'preferred_directions',
]

DEFAULT_START_RADIUS_M: Final = 2 * 4.0 / 15.0
"""Distance of the nominal starts from the departure point [m] (authors: 2 cells)."""

_BIAS_STREAM: Final = 0xB1A5
_SEARCH_STEP_FRACTION: Final = 0.2
_SEARCH_GROWTHS: Final = 4


def preferred_directions(departure: str, robot_count: int, bias_rad: float) -> np.ndarray:
    """(n,) preferred directions phi_i [rad] in (-pi, pi] for 'center' or 'edge'."""
    if robot_count < 1:
        msg = f'robot_count must be >= 1, got {robot_count}'
        raise ConfigurationError(msg)
    i = np.arange(robot_count, dtype=float)
    if departure == 'center':
        phi = bias_rad + i * 2.0 * math.pi / robot_count
    elif departure == 'edge':
        phi = bias_rad + (i + 0.5) * math.pi / robot_count
    else:
        msg = f"departure must be 'center' or 'edge', got {departure!r}"
        raise ConfigurationError(msg)
    return np.mod(phi + math.pi, 2.0 * math.pi) - math.pi


def departure_poses(
    departure_xy: tuple[float, float],
    departure: str,
    robot_count: int,
    bias_rad: float,
    start_radius_m: float = DEFAULT_START_RADIUS_M,
) -> np.ndarray:
    """(n, 3) nominal start poses x [m], y [m], yaw [rad] on the fan around ``departure_xy``,
    whatever the walls (:func:`place_starts` moves them into free space)."""
    phi = preferred_directions(departure, robot_count, bias_rad)
    x = departure_xy[0] + start_radius_m * np.cos(phi)
    y = departure_xy[1] + start_radius_m * np.sin(phi)
    return np.column_stack([x, y, phi])


def fan_kind(point: DeparturePoint) -> str:
    """'edge' (half circle) for a departure point with a direction into the building, else
    'center' (full circle)."""
    return 'edge' if point.heading_rad is not None else 'center'


def fan_bias_rad(
    fan: str, robot_count: int, seed: int, into_site_rad: float | None = None
) -> float:
    """The fan's common bias [rad] for a run seed (see the module docstring).

    Centre: uniform in [-pi, pi). Edge: ``into_site_rad`` - pi/2 plus a seeded offset uniform
    in [-pi/(2n), pi/(2n)], so every direction points into the building; without
    ``into_site_rad`` an edge fan is drawn like a centre one.
    """
    if robot_count < 1:
        msg = f'robot_count must be >= 1, got {robot_count}'
        raise ConfigurationError(msg)
    rng = np.random.default_rng(np.random.SeedSequence([seed, _BIAS_STREAM]))
    if fan == 'edge' and into_site_rad is not None:
        offset = float(rng.uniform(-1.0, 1.0)) * 0.5 * math.pi / robot_count
        return float(into_site_rad) - 0.5 * math.pi + offset
    if fan not in ('center', 'edge'):
        msg = f"fan must be 'center' or 'edge', got {fan!r}"
        raise ConfigurationError(msg)
    return float(rng.uniform(-math.pi, math.pi))


@dataclass(frozen=True)
class FreeSpaceCapacity:
    """How many robots the free space around a departure point could hold at most.

    Attributes:
        departure: name of the departure point.
        area_m2: free area [m^2] reachable from it with the entrance sealed, less the walls'
            half thickness.
        max_robots: an upper bound on the robots whose bodies fit in that area without
            overlapping (the densest disc packing, pi / (2 sqrt 3) of the area).
    """

    departure: str
    area_m2: float
    max_robots: int


def free_space_capacity(
    site: Site, departure: str, *, body: BodyConfig | None = None
) -> FreeSpaceCapacity:
    """An upper bound on the robots that fit around departure point ``departure``, quick to
    compute for any count (:func:`place_starts` takes seconds for a hundred robots).

    Robot bodies (radius r) centred at least r + half a wall's thickness from every wall lie
    in the free area A reachable from the point, less half the walls' thickness; discs cover
    at most pi / (2 sqrt 3) of a plane, so at most A / (2 sqrt 3 r^2) fit. The area is
    counted on the free-space raster of the site's validation, one cell generous.

    Raises:
        ConfigurationError: no departure point of that name.
    """
    from scipy import ndimage

    body = body or BodyConfig()
    try:
        point = site.departure(departure)
    except SiteError as err:
        raise ConfigurationError(str(err)) from err
    raster = free_space_raster(site)
    label = raster.label_at(point.xy)
    if label == 0:
        return FreeSpaceCapacity(point.name, 0.0, 0)
    region = raster.labels == label
    res = raster.resolution_m
    distance_m = ndimage.distance_transform_edt(region) * res
    usable = region & (distance_m >= 0.5 * body.wall_thickness_m - res)
    area = float(np.count_nonzero(usable)) * res * res
    radius = body.robot_radius_m
    return FreeSpaceCapacity(point.name, area, int(area / (2.0 * math.sqrt(3.0) * radius**2)))


@dataclass(frozen=True)
class StartPlacement:
    """Start poses of a swarm at one departure point.

    Attributes:
        poses: (n, 3) x [m], y [m], yaw [rad]; robot i faces its preferred direction phi_i.
        fan: 'center' or 'edge'.
        bias_rad: the fan's common bias [rad].
        moved: indices of the robots not at their nominal place on the fan.
        moved_by_m: (n,) distance of each robot from its nominal place [m].
    """

    poses: np.ndarray
    fan: str
    bias_rad: float
    moved: tuple[int, ...]
    moved_by_m: np.ndarray


def place_starts(
    site: Site,
    departure: str,
    robot_count: int,
    *,
    seed: int = 0,
    bias_rad: float | None = None,
    body: BodyConfig | None = None,
    start_radius_m: float = DEFAULT_START_RADIUS_M,
) -> StartPlacement:
    """Start poses of ``robot_count`` robots on the fan of the site's departure point
    ``departure``, each in free space (see the module docstring).

    Args:
        site: the site; robots collide with its walls with the entrance sealed.
        departure: name of the departure point.
        robot_count: n.
        seed: run seed the bias is drawn from (:func:`fan_bias_rad`).
        bias_rad: the bias to use instead of drawing one.
        body: the robots' body (radius, wall thickness); defaults to :class:`BodyConfig`.
        start_radius_m: distance of the nominal starts from the departure point [m].

    Raises:
        ConfigurationError: no departure point of that name, a bad count or radius, or too
            little free space around the departure point for the robots.
    """
    body = body or BodyConfig()
    if not (math.isfinite(start_radius_m) and start_radius_m >= 0.0):
        msg = f'start_radius_m must be >= 0, got {start_radius_m!r}'
        raise ConfigurationError(msg)
    try:
        point = site.departure(departure)
    except SiteError as err:  # it lists the names the site has
        raise ConfigurationError(str(err)) from err
    fan = fan_kind(point)
    if bias_rad is None:
        bias_rad = fan_bias_rad(fan, robot_count, seed, point.heading_rad)
    nominal = departure_poses(point.xy, fan, robot_count, bias_rad, start_radius_m)
    clearance = body.robot_radius_m + 0.5 * body.wall_thickness_m
    spacing = 2.0 * body.robot_radius_m
    walls = np.asarray(site.sealed_walls, dtype=np.float64).reshape(-1, 4)
    reach = start_radius_m + spacing * (math.ceil(math.sqrt(robot_count)) + 2)
    for _ in range(_SEARCH_GROWTHS):
        places = _FreePlaces(point.xy, walls, clearance, reach, body.robot_radius_m)
        xy = _place(nominal[:, :2], places, spacing)
        if xy is not None:
            break
        reach *= 2.0
    else:
        x, y = point.xy
        msg = (
            f'{robot_count} robots of radius {body.robot_radius_m} m do not fit around '
            f'departure point {point.name!r} at ({x:.3f}, {y:.3f}) m without touching a wall '
            f'or each other (searched {reach / 2.0:.2f} m around it)'
        )
        raise ConfigurationError(msg)
    moved_by = np.hypot(*(xy - nominal[:, :2]).T)
    poses = np.column_stack([xy, nominal[:, 2]])
    moved = tuple(int(i) for i in np.flatnonzero(moved_by > 0.0))
    return StartPlacement(poses, fan, float(bias_rad), moved, moved_by)


class _FreePlaces:
    """Places around a departure point where a robot's centre is free: a square grid of
    candidates at least ``clearance`` from every wall that a robot could drive to in a
    straight line from the departure point (the swept disc of the way there touches no
    wall), so no start lies behind a wall, even one with a door further along."""

    def __init__(
        self,
        centre: tuple[float, float],
        walls: np.ndarray,
        clearance: float,
        reach: float,
        robot_radius_m: float,
    ) -> None:
        self.centre = np.asarray(centre, dtype=np.float64)
        self.clearance = clearance
        self.walls = _walls_near(walls, self.centre, reach + clearance)
        # The way out may be as narrow as the departure point's own clearance.
        own = float(_nearest_wall(self.centre[None, :], self.walls)[0])
        self.way_clearance = min(clearance, own)
        self._reach = reach
        self._step = _SEARCH_STEP_FRACTION * robot_radius_m

    @cached_property
    def points(self) -> np.ndarray:
        """(K, 2) the free candidates [m], on a square grid within the reach (worked out
        when first asked for: most placements need none)."""
        reach, step = self._reach, self._step
        offsets = np.arange(-math.ceil(reach / step), math.ceil(reach / step) + 1) * step
        gx, gy = np.meshgrid(offsets, offsets)
        grid = self.centre + np.column_stack([gx.ravel(), gy.ravel()])
        grid = grid[np.hypot(gx.ravel(), gy.ravel()) <= reach]
        return grid[self.free(grid)]

    def free(self, points: np.ndarray) -> np.ndarray:
        """(N,) True where a robot centred there keeps its clearance from every wall and can
        be reached in a straight line from the departure point."""
        clear = _nearest_wall(points, self.walls) >= self.clearance - 1e-9
        way = _nearest_wall_to_ways(self.centre, points, self.walls)
        return clear & (way >= self.way_clearance - 1e-9)


def _place(nominal: np.ndarray, places: _FreePlaces, spacing: float) -> np.ndarray | None:
    """Centres for every robot: nominal ones that are free first, the others at the free
    candidate nearest their nominal place; None when the candidates run out."""
    n = len(nominal)
    xy = np.full((n, 2), np.nan)
    placed: list[int] = []

    def apart(candidate: np.ndarray) -> np.ndarray:
        if not placed:
            return np.ones(len(candidate), dtype=bool)
        others = xy[placed]
        gaps = np.hypot(*(candidate[:, None, :] - others[None, :, :]).transpose(2, 0, 1))
        return np.all(gaps >= spacing - 1e-9, axis=1)

    nominal_free = places.free(nominal)
    for i in range(n):
        if nominal_free[i] and bool(apart(nominal[i][None, :])[0]):
            xy[i] = nominal[i]
            placed.append(i)
    for i in range(n):
        if i in placed:
            continue
        free = places.points[apart(places.points)] if len(places.points) else places.points
        if len(free) == 0:
            return None
        best = int(np.argmin(np.hypot(*(free - nominal[i]).T)))
        xy[i] = free[best]
        placed.append(i)
    return xy


def _walls_near(walls: np.ndarray, centre: np.ndarray, distance: float) -> np.ndarray:
    """The (M, 4) walls within ``distance`` of ``centre``, as (M', 2, 2) segments."""
    near = walls[point_segment_distances((float(centre[0]), float(centre[1])), walls) <= distance]
    return near.reshape(-1, 2, 2)


def _nearest_wall(points: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """(N,) distance [m] from each of the (N, 2) points to the nearest of the (M, 2, 2)
    walls."""
    if len(walls) == 0:
        return np.full(len(points), np.inf)
    return point_segment_distance(points, walls).min(axis=1)


def _nearest_wall_to_ways(start: np.ndarray, ends: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """(N,) distance [m] from each straight way ``start`` -> ``ends[k]`` to the nearest of
    the (M, 2, 2) walls (0 where a way crosses one)."""
    if len(walls) == 0:
        return np.full(len(ends), np.inf)
    starts = np.broadcast_to(start, ends.shape)
    # A way of zero length is the point itself; keep its direction finite.
    ends = np.where(np.all(ends == start, axis=1)[:, None], ends + 1e-12, ends)
    ways = np.stack([starts, ends], axis=1)
    nearest = np.minimum(_nearest_wall(ends, walls), float(_nearest_wall(start[None, :], walls)[0]))
    tips = point_segment_distance(walls.reshape(-1, 2), ways).min(axis=0)
    nearest = np.minimum(nearest, tips)
    nearest[count_crossings(starts, ends, walls) > 0] = 0.0
    return nearest
