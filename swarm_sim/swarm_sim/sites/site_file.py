"""YAML site files, format ``swarm_site/1`` (documented in docs/site_format.md).

A site file holds everything a :class:`Site` holds, in metres, in the site's world frame
(origin at the lower-left corner, x right, y up). The loader checks every key and value and
then runs :func:`validate_site`; every error names the file, the line and the key path, e.g.
``lab.yaml:41: rooms[3].rects[0]: expected 4 numbers x0, y0, x1, y1, got 3``.

Writing rounds coordinates to a micrometre so files stay readable; loading a written file
gives the same site to that precision.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, Final

import yaml

from swarm_sim.sites.errors import SiteError, SiteFileError, SiteValidationError
from swarm_sim.sites.model import DeparturePoint, Door, Room, Site
from swarm_sim.sites.validation import validate_site

__all__ = ['FORMAT', 'dump_site', 'load_site', 'parse_site', 'save_site', 'site_to_dict']

FORMAT: Final = 'swarm_site/1'
"""Format tag every site file starts with; bumped when a change is incompatible."""

_DECIMALS: Final = 6
_TOP_KEYS: Final = (
    'format',
    'name',
    'seed',
    'grid_m',
    'bounds',
    'departure_points',
    'entrance',
    'walls',
    'rooms',
    'doors',
)
_REQUIRED_TOP_KEYS: Final = ('format', 'name', 'bounds', 'departure_points', 'walls')

KeyPath = tuple[str | int, ...]


def _round(value: float) -> float:
    rounded = round(float(value), _DECIMALS)
    return 0.0 if rounded == 0 else rounded  # no "-0.0" in files


def _numbers(values: Any) -> list[float]:
    return [_round(v) for v in values]


def site_to_dict(site: Site) -> dict[str, Any]:
    """The YAML structure of a site (plain dicts, lists, numbers and strings)."""
    data: dict[str, Any] = {'format': FORMAT, 'name': site.name}
    if site.seed is not None:
        data['seed'] = site.seed
    if site.grid_m is not None:
        data['grid_m'] = site.grid_m  # exact: room lookups use it as their resolution
    data['bounds'] = {'width_m': _round(site.width_m), 'height_m': _round(site.height_m)}
    points: dict[str, Any] = {}
    for name, point in site.departure_points.items():
        entry = {'x_m': _round(point.x_m), 'y_m': _round(point.y_m)}
        if point.heading_rad is not None:
            entry['heading_rad'] = _round(point.heading_rad)
        points[name] = entry
    data['departure_points'] = points
    if site.entrance is not None:
        data['entrance'] = _door_to_dict(site.entrance)
    data['walls'] = [_numbers(wall) for wall in site.walls]
    rooms = []
    for room in site.rooms:
        entry: dict[str, Any] = {'id': room.room_id}
        if room.label:
            entry['label'] = room.label
        if room.has_victim:
            entry['victim'] = True
        if len(room.rects):
            entry['rects'] = [_numbers(rect) for rect in room.rects]
        if room.polygon is not None:
            entry['polygon'] = [_numbers(vertex) for vertex in room.polygon]
        rooms.append(entry)
    data['rooms'] = rooms
    data['doors'] = [_door_to_dict(door) for door in site.doors]
    return data


def _door_to_dict(door: Door) -> dict[str, Any]:
    return {'segment': _numbers(door.segment), 'rooms': list(door.room_ids)}


def dump_site(site: Site) -> str:
    """The site as ``swarm_site/1`` YAML text."""
    header = f'# Search site, format {FORMAT} (see docs/site_format.md). Units: metres, radians.\n'
    body = yaml.safe_dump(
        site_to_dict(site), sort_keys=False, default_flow_style=None, width=100, allow_unicode=False
    )
    return header + body


def save_site(site: Site, path: str | Path) -> None:
    """Write the site to a YAML file."""
    Path(path).write_text(dump_site(site), encoding='utf-8')


def load_site(path: str | Path) -> Site:
    """Read, check and validate a site file.

    Raises:
        SiteFileError: unreadable YAML, a missing/unknown/mistyped key, or an invalid site;
            the message names the file, line and key path.
    """
    path = Path(path)
    return parse_site(path.read_text(encoding='utf-8'), source=str(path))


def parse_site(text: str, source: str = '<site>') -> Site:
    """Parse ``swarm_site/1`` text (see :func:`load_site`)."""
    data, lines = _compose(text, source)
    reader = _Reader(source, lines)
    site = reader.site(data)
    try:
        warnings = validate_site(site)
    except SiteValidationError as err:
        raise reader.error(err.key_path, err.message) from err
    if not warnings:
        return site
    texts = tuple(str(reader.error(w.key_path, w.message)) for w in warnings)
    return dataclasses.replace(site, warnings=texts)


def _compose(text: str, source: str) -> tuple[Any, dict[KeyPath, int]]:
    """YAML data and the 1-based line of every key path."""
    loader_class = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
    loader = loader_class(text)
    try:
        node = loader.get_single_node()
        if node is None:
            raise SiteFileError(source, 'the file is empty')
        data = loader.construct_document(node)
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        line = None if mark is None else mark.line + 1
        problem = getattr(err, 'problem', None) or str(err)
        raise SiteFileError(source, f'not valid YAML: {problem}', line=line) from None
    finally:
        loader.dispose()
    lines: dict[KeyPath, int] = {}

    def walk(item: yaml.Node, path: KeyPath) -> None:
        lines.setdefault(path, item.start_mark.line + 1)
        if isinstance(item, yaml.MappingNode):
            for key_node, value_node in item.value:
                child = (*path, str(key_node.value))
                lines[child] = key_node.start_mark.line + 1
                walk(value_node, child)
        elif isinstance(item, yaml.SequenceNode):
            for index, value_node in enumerate(item.value):
                walk(value_node, (*path, index))

    walk(node, ())
    return data, lines


class _Reader:
    """Typed access to the parsed YAML; every complaint names its key path and line."""

    def __init__(self, source: str, lines: dict[KeyPath, int]) -> None:
        self.source = source
        self.lines = lines
        self.room_paths: dict[int, KeyPath] = {}

    def error(self, path: KeyPath, message: str) -> SiteFileError:
        line = None
        for depth in range(len(path), -1, -1):
            line = self.lines.get(path[:depth])
            if line is not None:
                break
        return SiteFileError(self.source, message, key_path=path, line=line)

    def mapping(
        self, value: Any, path: KeyPath, known: tuple[str, ...], required: tuple[str, ...] = ()
    ) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.error(path, f'expected a mapping, got {_kind(value)}')
        for key in value:
            if key not in known:
                raise self.error((*path, str(key)), f'unknown key (known: {", ".join(known)})')
        for key in required:
            if key not in value:
                raise self.error(path, f'missing required key {key!r}')
        return value

    def sequence(self, value: Any, path: KeyPath) -> list[Any]:
        if not isinstance(value, list):
            raise self.error(path, f'expected a list, got {_kind(value)}')
        return value

    def number(self, value: Any, path: KeyPath, *, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(path, f'expected a number, got {_kind(value)}')
        number = float(value)
        if not math.isfinite(number):
            raise self.error(path, f'expected a finite number, got {value!r}')
        if positive and number <= 0:
            raise self.error(path, f'expected a positive number, got {value!r}')
        return number

    def integer(self, value: Any, path: KeyPath) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(path, f'expected an integer, got {_kind(value)}')
        return value

    def text(self, value: Any, path: KeyPath) -> str:
        if not isinstance(value, str) or not value:
            raise self.error(path, f'expected a non-empty string, got {_kind(value)}')
        return value

    def numbers(self, value: Any, path: KeyPath, count: int, meaning: str) -> list[float]:
        items = self.sequence(value, path)
        if len(items) != count:
            raise self.error(path, f'expected {count} numbers {meaning}, got {len(items)}')
        return [self.number(v, (*path, i)) for i, v in enumerate(items)]

    def each(self, value: Any, path: KeyPath, read: Callable[[Any, KeyPath], Any]) -> list[Any]:
        return [read(item, (*path, i)) for i, item in enumerate(self.sequence(value, path))]

    def site(self, data: Any) -> Site:
        top = self.mapping(data, (), _TOP_KEYS, _REQUIRED_TOP_KEYS)
        if top['format'] != FORMAT:
            msg = f'unsupported format {top["format"]!r}; this version reads {FORMAT!r}'
            raise self.error(('format',), msg)
        bounds = self.mapping(
            top['bounds'], ('bounds',), ('width_m', 'height_m'), ('width_m', 'height_m')
        )
        width = self.number(bounds['width_m'], ('bounds', 'width_m'), positive=True)
        height = self.number(bounds['height_m'], ('bounds', 'height_m'), positive=True)
        points = self.mapping(
            top['departure_points'], ('departure_points',), tuple(top['departure_points'] or ())
        )
        if not points:
            raise self.error(('departure_points',), 'at least one departure point is required')
        departures = {str(name): self.departure(str(name), value) for name, value in points.items()}
        seed = top.get('seed')
        grid = top.get('grid_m')
        entrance = top.get('entrance')
        parts = {
            'name': self.text(top['name'], ('name',)),
            'walls': self.each(top['walls'], ('walls',), self.wall),
            'rooms': tuple(self.each(top.get('rooms') or [], ('rooms',), self.room)),
            'doors': tuple(self.each(top.get('doors') or [], ('doors',), self.door)),
            'entrance': None if entrance is None else self.door(entrance, ('entrance',)),
            'grid_m': None if grid is None else self.number(grid, ('grid_m',), positive=True),
            'seed': None if seed is None else self.integer(seed, ('seed',)),
        }
        try:
            return Site(width_m=width, height_m=height, departure_points=departures, **parts)
        except SiteValidationError as err:
            raise self.error(err.key_path, err.message) from err
        except SiteError as err:
            raise self.error((), str(err)) from err

    def wall(self, value: Any, path: KeyPath) -> list[float]:
        return self.numbers(value, path, 4, 'x0, y0, x1, y1')

    def departure(self, name: str, value: Any) -> DeparturePoint:
        path: KeyPath = ('departure_points', name)
        entry = self.mapping(value, path, ('x_m', 'y_m', 'heading_rad'), ('x_m', 'y_m'))
        heading = entry.get('heading_rad')
        return DeparturePoint(
            name,
            self.number(entry['x_m'], (*path, 'x_m')),
            self.number(entry['y_m'], (*path, 'y_m')),
            None if heading is None else self.number(heading, (*path, 'heading_rad')),
        )

    def room(self, value: Any, path: KeyPath) -> Room:
        entry = self.mapping(value, path, ('id', 'label', 'victim', 'rects', 'polygon'), ('id',))
        room_id = self.integer(entry['id'], (*path, 'id'))
        if room_id < 0:
            raise self.error((*path, 'id'), f'room ids must be non-negative, got {room_id}')
        if room_id in self.room_paths:
            first = self.room_paths[room_id]
            msg = f'room id {room_id} is used twice (first at line {self.lines.get(first)})'
            raise self.error((*path, 'id'), msg)
        self.room_paths[room_id] = path
        rects = []
        for index, rect in enumerate(self.sequence(entry.get('rects') or [], (*path, 'rects'))):
            rect_path = (*path, 'rects', index)
            x0, y0, x1, y1 = self.numbers(rect, rect_path, 4, 'x0, y0, x1, y1')
            if not (x0 < x1 and y0 < y1):
                raise self.error(rect_path, 'a rectangle needs x0 < x1 and y0 < y1')
            rects.append((x0, y0, x1, y1))
        polygon = None
        if entry.get('polygon') is not None:
            vertices = self.sequence(entry['polygon'], (*path, 'polygon'))
            polygon = [
                self.numbers(v, (*path, 'polygon', i), 2, 'x, y') for i, v in enumerate(vertices)
            ]
            if len(polygon) < 3:
                raise self.error((*path, 'polygon'), 'a polygon needs at least 3 vertices')
        if not rects and polygon is None:
            raise self.error(path, "a room needs 'rects' or a 'polygon'")
        victim = entry.get('victim', False)
        if not isinstance(victim, bool):
            raise self.error((*path, 'victim'), f'expected true or false, got {_kind(victim)}')
        label = entry.get('label', '')
        if not isinstance(label, str):
            label = str(label)
        return Room(room_id, rects, label=label, has_victim=victim, polygon=polygon)

    def door(self, value: Any, path: KeyPath) -> Door:
        entry = self.mapping(value, path, ('segment', 'rooms'), ('segment',))
        segment = self.numbers(entry['segment'], (*path, 'segment'), 4, 'x0, y0, x1, y1')
        rooms = self.sequence(entry.get('rooms') or [], (*path, 'rooms'))
        if len(rooms) > 2:
            raise self.error((*path, 'rooms'), f'a door joins at most 2 rooms, got {len(rooms)}')
        ids = tuple(self.integer(r, (*path, 'rooms', i)) for i, r in enumerate(rooms))
        return Door((segment[0], segment[1], segment[2], segment[3]), ids)


def _kind(value: Any) -> str:
    if value is None:
        return 'nothing'
    return (
        f'{type(value).__name__} {value!r}'
        if not isinstance(value, dict | list)
        else type(value).__name__
    )
