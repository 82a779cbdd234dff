"""The site and the robots as visualization_msgs/MarkerArray, for Foxglove and RViz.

Topics (all in the ``map`` frame unless said otherwise, latched: reliable, transient local,
depth 1, so a viewer started late and a bag recorder get the current state at once):

* ``/sim/markers/site``: walls (ns ``walls``, one LINE_LIST) and room labels
  (``room_labels``); once.
* ``/sim/markers/rooms``: the rooms filled grey, or in the colour of their first visitor
  (``rooms``, TRIANGLE_LISTs); at start and at every first room entry.
* ``/sim/markers/robots``: each robot's body (``bodies``), heading (``headings``) and name
  (``names``) in ``r<i>/base_link``, frame-locked; once.
* ``/sim/markers/paths``: each robot's true path so far, one LINE_STRIP per robot (``paths``,
  id = robot index); every 1 / ``path_rate_hz`` s of sim time.
* ``/sim/markers/targets``: the mission's targets (Bayes-Swarm source, MSC RSSI targets);
  by the mission's extension, at start and when one is found or captured.

Robot colours are matplotlib's tab10 in robot order (r0 blue, r1 orange, ...), as in the
plots of :mod:`swarm_analysis.plots`. Sizes scale with the site (:func:`marker_unit_m`), so
a 15 m site and a 2 km field both render legibly.

Paths are simplified as they are recorded (:class:`PathRecorder`): a sample becomes a vertex
only where the path leaves a straight line by more than a tolerance, so a straight run costs
two points and the repeated full-path messages stay small.

Pure builders; the bridge node and the extensions own the publishers.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from swarm_common.frames import BASE_LINK, MAP_FRAME, robot_frame
from swarm_common.stamps import stamp_from_seconds
from swarm_runtime.ros import QoSDurabilityPolicy, QoSProfile, message_module

__all__ = [
    'MARKER_TOPICS',
    'PATHS_TOPIC',
    'ROBOTS_TOPIC',
    'ROOMS_TOPIC',
    'SITE_TOPIC',
    'TARGETS_TOPIC',
    'PathRecorder',
    'marker_qos',
    'marker_unit_m',
    'path_markers',
    'robot_markers',
    'robot_rgb',
    'room_markers',
    'site_markers',
    'target_markers',
    'triangulate_polygon',
]

SITE_TOPIC = '/sim/markers/site'
ROOMS_TOPIC = '/sim/markers/rooms'
ROBOTS_TOPIC = '/sim/markers/robots'
PATHS_TOPIC = '/sim/markers/paths'
TARGETS_TOPIC = '/sim/markers/targets'
MARKER_TOPICS = (SITE_TOPIC, ROOMS_TOPIC, ROBOTS_TOPIC, PATHS_TOPIC, TARGETS_TOPIC)

# matplotlib's tab10 palette (RGB, 0..255).
_TAB10 = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)
_WALL_RGBA = (0.15, 0.15, 0.15, 1.0)
_UNVISITED_RGBA = (0.6, 0.6, 0.6, 0.25)
_VISITED_ALPHA = 0.35
_LABEL_RGBA = (0.3, 0.3, 0.3, 0.8)
# Heights above the floor [m], so that fills, lines and labels do not fight for a pixel.
_ROOM_Z_M = -0.01
_PATH_Z_M = 0.02


def marker_qos() -> QoSProfile:
    """QoS of every marker topic: reliable, transient local, depth 1 (latched)."""
    return QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)


def robot_rgb(index: int) -> tuple[float, float, float]:
    """The colour of robot ``index`` (0..1 per channel): tab10, repeating after ten."""
    r, g, b = _TAB10[index % len(_TAB10)]
    return r / 255.0, g / 255.0, b / 255.0


def marker_unit_m(points_m: np.ndarray) -> float:
    """A length for marker sizes: 1/150 of the larger side of the points' bounding box
    (0.1 m for a 15 m site), at least 1 cm.

    Args:
        points_m: (K, 2) points spanning the scene (wall ends, room corners, start poses).
    """
    points = np.asarray(points_m, dtype=float).reshape(-1, 2)
    if len(points) == 0:
        return 0.1
    span = float(np.max(points.max(axis=0) - points.min(axis=0)))
    return max(span / 150.0, 0.01)


# --- message helpers ------------------------------------------------------------------------


def _msgs() -> tuple[Any, Any, Any]:
    return (
        message_module('visualization_msgs'),
        message_module('geometry_msgs'),
        message_module('std_msgs'),
    )


def _color(rgba: Sequence[float]) -> Any:
    std_msgs = message_module('std_msgs')
    r, g, b, a = (float(v) for v in rgba)
    return std_msgs.ColorRGBA(r=r, g=g, b=b, a=a)


def _marker(
    ns: str, marker_id: int, marker_type: int, time_s: float, frame_id: str = MAP_FRAME
) -> Any:
    visualization_msgs, _, _ = _msgs()
    builtin_interfaces = message_module('builtin_interfaces')
    marker = visualization_msgs.Marker(ns=ns, id=int(marker_id), type=int(marker_type))
    marker.header.stamp = stamp_from_seconds(time_s, builtin_interfaces.Time)
    marker.header.frame_id = frame_id
    marker.action = visualization_msgs.Marker.ADD
    marker.pose.orientation.w = 1.0
    return marker


def _points(xy: np.ndarray, z_m: float = 0.0) -> list[Any]:
    geometry_msgs = message_module('geometry_msgs')
    return [
        geometry_msgs.Point(x=float(x), y=float(y), z=float(z_m))
        for x, y in np.asarray(xy, dtype=float).reshape(-1, 2)
    ]


def _array(markers: Sequence[Any]) -> Any:
    visualization_msgs = message_module('visualization_msgs')
    return visualization_msgs.MarkerArray(markers=list(markers))


def _text(
    ns: str, marker_id: int, text: str, xy: Sequence[float], height_m: float, time_s: float
) -> Any:
    visualization_msgs = message_module('visualization_msgs')
    marker = _marker(ns, marker_id, visualization_msgs.Marker.TEXT_VIEW_FACING, time_s)
    marker.pose.position.x, marker.pose.position.y = float(xy[0]), float(xy[1])
    marker.pose.position.z = float(height_m)
    marker.scale.z = float(height_m)
    marker.color = _color(_LABEL_RGBA)
    marker.text = text
    return marker


# --- the site -------------------------------------------------------------------------------


def site_markers(
    walls: np.ndarray,
    wall_width_m: float,
    labels: Sequence[tuple[str, tuple[float, float]]],
    unit_m: float,
    time_s: float = 0.0,
) -> Any:
    """The walls as one LINE_LIST and a text label per room.

    Args:
        walls: (M, 2, 2) wall centre lines [m].
        wall_width_m: drawn line width [m].
        labels: (text, (x, y)) per room.
        unit_m: the scene's marker unit (:func:`marker_unit_m`).
        time_s: stamp [s].
    """
    visualization_msgs = message_module('visualization_msgs')
    markers = []
    segments = np.asarray(walls, dtype=float).reshape(-1, 2)
    if len(segments):
        wall = _marker('walls', 0, visualization_msgs.Marker.LINE_LIST, time_s)
        wall.scale.x = float(wall_width_m)
        wall.color = _color(_WALL_RGBA)
        wall.points = _points(segments)
        markers.append(wall)
    for i, (text, xy) in enumerate(labels):
        markers.append(_text('room_labels', i, text, xy, 2.5 * unit_m, time_s))
    return _array(markers)


def triangulate_polygon(polygon: np.ndarray) -> np.ndarray:
    """(T, 3, 2) triangles covering a simple polygon (ear clipping, either winding).

    Raises:
        ValueError: fewer than 3 vertices, or no ear found (an outline without area; some
            self-intersecting ones).
    """
    points = np.asarray(polygon, dtype=float).reshape(-1, 2)
    if len(points) >= 2 and np.allclose(points[0], points[-1]):
        points = points[:-1]
    if len(points) < 3:
        raise ValueError('a polygon needs at least 3 vertices')
    x, y = points[:, 0], points[:, 1]
    area2 = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    order = list(range(len(points))) if area2 > 0.0 else list(range(len(points)))[::-1]

    def cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    triangles = []
    while len(order) > 3:
        n = len(order)
        for k in range(n):
            i0, i1, i2 = order[k - 1], order[k], order[(k + 1) % n]
            a, b, c = points[i0], points[i1], points[i2]
            if cross(a, b, c) <= 0.0:
                continue  # reflex or degenerate corner: not an ear
            inside = any(
                cross(a, b, points[j]) >= 0.0
                and cross(b, c, points[j]) >= 0.0
                and cross(c, a, points[j]) >= 0.0
                for j in order
                if j not in (i0, i1, i2)
            )
            if not inside:
                triangles.append((a, b, c))
                del order[k]
                break
        else:
            raise ValueError('no ear found: the polygon is not simple')
    triangles.append(tuple(points[j] for j in order))
    return np.array(triangles, dtype=float).reshape(-1, 3, 2)


def _rect_triangles(rects: np.ndarray) -> np.ndarray:
    """(2K, 3, 2) triangles of (K, 4) rectangles x_min, y_min, x_max, y_max."""
    r = np.asarray(rects, dtype=float).reshape(-1, 4)
    x0, y0, x1, y1 = r.T
    first = np.stack([np.c_[x0, y0], np.c_[x1, y0], np.c_[x1, y1]], axis=1)
    second = np.stack([np.c_[x0, y0], np.c_[x1, y1], np.c_[x0, y1]], axis=1)
    return np.concatenate([first, second]).reshape(-1, 3, 2)


def room_markers(
    room_rects: Sequence[np.ndarray],
    first_visitor: Mapping[int, int],
    num_robots: int,
    time_s: float,
    polygons: Sequence[np.ndarray | None] = (),
) -> Any:
    """Every room filled (TRIANGLE_LISTs, ns ``rooms``): the rooms nobody entered yet in grey
    (id 0), those robot ``i`` entered first in its colour (id ``i + 1``). A group without
    rooms is sent as a DELETE of its id, so a viewer drops what it showed before.

    Args:
        room_rects: per room, its (K, 4) rectangles x_min, y_min, x_max, y_max [m].
        first_visitor: room index -> index of the robot that entered it first.
        num_robots: number of robots (ids 1..num_robots).
        time_s: stamp [s].
        polygons: per room, an optional (P, 2) outline filled as well (free-form rooms).
    """
    visualization_msgs = message_module('visualization_msgs')
    groups: list[list[np.ndarray]] = [[] for _ in range(num_robots + 1)]
    for index, rects in enumerate(room_rects):
        parts = [_rect_triangles(rects)]
        polygon = polygons[index] if index < len(polygons) else None
        if polygon is not None:
            with contextlib.suppress(ValueError):  # an outline without area: rects only
                parts.append(triangulate_polygon(polygon))
        visitor = first_visitor.get(index)
        groups[0 if visitor is None else visitor + 1] += parts
    markers = []
    for group, parts in enumerate(groups):
        marker = _marker('rooms', group, visualization_msgs.Marker.TRIANGLE_LIST, time_s)
        triangles = np.concatenate(parts).reshape(-1, 2) if parts else np.zeros((0, 2))
        if len(triangles) == 0:
            marker.action = visualization_msgs.Marker.DELETE
        else:
            marker.scale.x = marker.scale.y = marker.scale.z = 1.0
            rgba = _UNVISITED_RGBA if group == 0 else (*robot_rgb(group - 1), _VISITED_ALPHA)
            marker.color = _color(rgba)
            marker.points = _points(triangles, _ROOM_Z_M)
        markers.append(marker)
    return _array(markers)


# --- the robots -----------------------------------------------------------------------------


def robot_markers(robot_names: Sequence[str], radius_m: float, unit_m: float) -> Any:
    """Each robot's disc, heading arrow and name in its own ``base_link``, frame-locked, so
    the viewer moves them with the robot's transform (published once, stamp 0)."""
    visualization_msgs = message_module('visualization_msgs')
    marker_class = visualization_msgs.Marker
    radius = max(float(radius_m), unit_m)
    markers = []
    for i, name in enumerate(robot_names):
        frame = robot_frame(name, BASE_LINK)
        colour = _color((*robot_rgb(i), 1.0))
        body = _marker('bodies', i, marker_class.CYLINDER, 0.0, frame)
        body.scale.x = body.scale.y = 2.0 * radius
        body.scale.z = 0.5 * radius
        body.pose.position.z = 0.25 * radius
        body.color = colour
        heading = _marker('headings', i, marker_class.ARROW, 0.0, frame)
        heading.scale.x, heading.scale.y, heading.scale.z = 2.0 * radius, 0.4 * radius, 0.4 * radius
        heading.pose.position.z = 0.6 * radius
        heading.color = _color((0.1, 0.1, 0.1, 1.0))
        label = _marker('names', i, marker_class.TEXT_VIEW_FACING, 0.0, frame)
        label.scale.z = 2.5 * unit_m
        label.pose.position.z = 2.0 * radius + 2.5 * unit_m
        label.color = colour
        label.text = name
        for marker in (body, heading, label):
            marker.frame_locked = True
            markers.append(marker)
    return _array(markers)


class PathRecorder:
    """Every robot's true path, simplified as it grows.

    A sample closer than ``min_step_m`` to the previous one is dropped (a robot standing
    still adds nothing). A sample becomes a vertex of the kept polyline only when the
    samples since the last vertex stop fitting the straight line from that vertex to the
    newest sample within ``tolerance_m``; the newest sample always ends the path.

    Args:
        start_poses: (N, 2+) start positions [m]; the first vertex of each path.
        tolerance_m: largest distance of a dropped sample from the drawn path [m].
        min_step_m: smallest move that is recorded [m].
    """

    _MAX_PENDING = 256

    def __init__(self, start_poses: np.ndarray, tolerance_m: float, min_step_m: float) -> None:
        starts = np.asarray(start_poses, dtype=float)[:, :2]
        self.tolerance_m = float(tolerance_m)
        self.min_step_m = float(min_step_m)
        self._vertices: list[list[tuple[float, float]]] = [[(x, y)] for x, y in starts]
        self._pending: list[list[tuple[float, float]]] = [[] for _ in starts]

    def add(self, positions: np.ndarray) -> None:
        """Record the (N, 2+) positions of one instant."""
        for i, (x, y) in enumerate(np.asarray(positions, dtype=float)[:, :2]):
            vertices, pending = self._vertices[i], self._pending[i]
            last = pending[-1] if pending else vertices[-1]
            if math.hypot(x - last[0], y - last[1]) < self.min_step_m:
                continue
            if pending and (
                len(pending) >= self._MAX_PENDING or not self._fits(vertices[-1], pending, (x, y))
            ):
                vertices.append(pending[-1])
                pending.clear()
            pending.append((float(x), float(y)))

    def _fits(
        self,
        start: tuple[float, float],
        samples: list[tuple[float, float]],
        end: tuple[float, float],
    ) -> bool:
        """True when every sample lies within the tolerance of the segment start -> end."""
        a = np.asarray(start)
        d = np.asarray(end) - a
        p = np.asarray(samples) - a
        length_sq = float(d @ d)
        if length_sq == 0.0:
            dist = np.hypot(p[:, 0], p[:, 1])
        else:
            t = np.clip(p @ d / length_sq, 0.0, 1.0)
            dist = np.hypot(*(p - t[:, None] * d).T)
        return bool(np.max(dist) <= self.tolerance_m)

    def path(self, robot: int) -> np.ndarray:
        """(K, 2) vertices of robot ``robot``'s path so far, ending at its newest sample."""
        pending = self._pending[robot]
        return np.array(self._vertices[robot] + pending[-1:], dtype=float).reshape(-1, 2)

    @property
    def num_robots(self) -> int:
        """Number of paths."""
        return len(self._vertices)


def path_markers(paths: Sequence[np.ndarray], width_m: float, time_s: float) -> Any:
    """One LINE_STRIP per robot (id = robot index, ns ``paths``) in the robot's colour;
    paths with fewer than two vertices are left out."""
    visualization_msgs = message_module('visualization_msgs')
    markers = []
    for i, path in enumerate(paths):
        if len(path) < 2:
            continue
        marker = _marker('paths', i, visualization_msgs.Marker.LINE_STRIP, time_s)
        marker.scale.x = float(width_m)
        marker.color = _color((*robot_rgb(i), 0.9))
        marker.points = _points(path, _PATH_Z_M)
        markers.append(marker)
    return _array(markers)


# --- mission targets ------------------------------------------------------------------------


def target_markers(
    positions_m: np.ndarray,
    radius_m: float,
    rgba: Sequence[Sequence[float]],
    labels: Sequence[str],
    unit_m: float,
    time_s: float,
    *,
    area_radius_m: float | None = None,
) -> Any:
    """A target per position: a sphere (ns ``targets``), its label (``target_labels``) and,
    with ``area_radius_m``, a flat translucent disc of that radius (``target_areas``: the
    detection radius of a source, the working distance of an RSSI target).

    Args:
        positions_m: (K, 2) target positions [m].
        radius_m: drawn radius of each sphere [m].
        rgba: per target, its colour.
        labels: per target, its text.
        unit_m: the scene's marker unit.
        time_s: stamp [s].
        area_radius_m: radius of the area discs [m], or None for none.
    """
    visualization_msgs = message_module('visualization_msgs')
    marker_class = visualization_msgs.Marker
    markers = []
    for i, ((x, y), colour, text) in enumerate(
        zip(np.asarray(positions_m, dtype=float).reshape(-1, 2), rgba, labels, strict=True)
    ):
        sphere = _marker('targets', i, marker_class.SPHERE, time_s)
        sphere.pose.position.x, sphere.pose.position.y = float(x), float(y)
        sphere.pose.position.z = float(radius_m)
        sphere.scale.x = sphere.scale.y = sphere.scale.z = 2.0 * float(radius_m)
        sphere.color = _color(colour)
        markers.append(sphere)
        if area_radius_m is not None and area_radius_m > 0.0:
            area = _marker('target_areas', i, marker_class.CYLINDER, time_s)
            area.pose.position.x, area.pose.position.y = float(x), float(y)
            area.scale.x = area.scale.y = 2.0 * float(area_radius_m)
            area.scale.z = 0.01
            area.color = _color((*colour[:3], 0.2))
            markers.append(area)
        markers.append(
            _text('target_labels', i, text, (x, y + 2.0 * radius_m), 2.5 * unit_m, time_s)
        )
    return _array(markers)
