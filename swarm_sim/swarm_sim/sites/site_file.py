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
from swarm_common.outputs import write_text_atomic

from swarm_sim.sites.errors import SiteError, SiteFileError, SiteValidationError
from swarm_sim.sites.model import DeparturePoint, Door, Room, Site, check_site_size
from swarm_sim.sites.validation import validate_site

__all__ = [
    'FORMAT',
    'MAX_FILE_BYTES',
    'MAX_NESTING',
    'dump_site',
    'load_site',
    'parse_site',
    'save_site',
    'site_to_dict',
]

FORMAT: Final = 'swarm_site/1'
"""Format tag every site file starts with; bumped when a change is incompatible."""

MAX_FILE_BYTES: Final = 16 * 1024 * 1024
"""Largest site file the loader reads [bytes] (a Big site's file is about 33 kB)."""

MAX_NESTING: Final = 32
"""Deepest nesting of YAML collections the loader accepts (a site file needs 5 levels)."""

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
        point_entry = {'x_m': _round(point.x_m), 'y_m': _round(point.y_m)}
        if point.heading_rad is not None:
            point_entry['heading_rad'] = _round(point.heading_rad)
        points[name] = point_entry
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
    """Write the site to a YAML file (under a temporary name first, then renamed)."""
    write_text_atomic(path, dump_site(site))


def load_site(path: str | Path) -> Site:
    """Read, check and validate a site file.

    Raises:
        SiteFileError: a file that cannot be read or is not UTF-8 text, unreadable YAML, a
            missing/unknown/mistyped key, or an invalid site; the message names the file,
            line and key path.
    """
    path = Path(path)
    try:
        with path.open('rb') as file:
            data = file.read(MAX_FILE_BYTES + 1)
    except OSError as err:
        raise SiteFileError(str(path), err.strerror or str(err)) from None
    if len(data) > MAX_FILE_BYTES:
        msg = (
            f'the file is larger than the {MAX_FILE_BYTES // (1024 * 1024)} MiB a site file may be'
        )
        raise SiteFileError(str(path), msg)
    try:
        text = data.decode('utf-8')
    except UnicodeDecodeError as err:
        line = data.count(b'\n', 0, err.start) + 1
        column = err.start - (data.rfind(b'\n', 0, err.start) + 1) + 1
        msg = f'the file is not UTF-8 text (byte 0x{data[err.start]:02x} at column {column})'
        raise SiteFileError(str(path), msg, line=line) from None
    return parse_site(text, source=str(path))


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
    """YAML data and the 1-based line of every key path.

    The node tree is checked before it is turned into data: no key twice in a mapping, no
    alias that contains itself, no nesting deeper than :data:`MAX_NESTING` (a site file
    needs 5 levels).
    """
    loader_class = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
    loader = loader_class(text)
    lines: dict[KeyPath, int] = {}
    try:
        node = loader.get_single_node()
        if node is None:
            raise SiteFileError(source, 'the file is empty')
        _NodeChecker(source, lines).walk(node, (), 0)
        data = loader.construct_document(node)
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        line = None if mark is None else mark.line + 1
        problem = getattr(err, 'problem', None) or str(err)
        raise SiteFileError(source, f'not valid YAML: {problem}', line=line) from None
    except RecursionError:
        msg = f'not valid YAML for a site file: nested more than {MAX_NESTING} levels deep'
        raise SiteFileError(source, msg) from None
    finally:
        loader.dispose()
    return data, lines


class _NodeChecker:
    """Walks a YAML node tree once, recording the line of every key path and rejecting
    duplicate keys, self-containing aliases and deep nesting."""

    def __init__(self, source: str, lines: dict[KeyPath, int]) -> None:
        self.source = source
        self.lines = lines
        self.open: set[int] = set()  # nodes being walked: the ancestors of the current one
        self.done: set[int] = set()  # nodes walked already (aliases are walked once)

    def walk(self, item: yaml.Node, path: KeyPath, depth: int) -> None:
        line = item.start_mark.line + 1
        self.lines.setdefault(path, line)
        if id(item) in self.open:
            msg = 'an alias refers to the collection that contains it (a recursive alias)'
            raise SiteFileError(self.source, msg, key_path=path, line=self._line(path, line))
        if id(item) in self.done or not isinstance(item, yaml.CollectionNode):
            return
        if depth >= MAX_NESTING:
            msg = f'nested more than {MAX_NESTING} levels deep; a site file needs 5'
            raise SiteFileError(self.source, msg, key_path=path[:3], line=line)
        self.open.add(id(item))
        if isinstance(item, yaml.MappingNode):
            seen: dict[tuple[str, str], int] = {}
            for key_node, value_node in item.value:
                key_line = key_node.start_mark.line + 1
                child = (*path, str(key_node.value))
                if isinstance(key_node, yaml.ScalarNode):
                    key = (key_node.tag, key_node.value)
                    if key in seen:
                        msg = f'duplicate key {key_node.value!r} (first at line {seen[key]})'
                        raise SiteFileError(self.source, msg, key_path=child, line=key_line)
                    seen[key] = key_line
                self.lines[child] = key_line
                self.walk(value_node, child, depth + 1)
        else:
            for index, value_node in enumerate(item.value):
                self.walk(value_node, (*path, index), depth + 1)
        self.open.discard(id(item))
        self.done.add(id(item))

    def _line(self, path: KeyPath, default: int) -> int:
        line = self.lines.get(path[:-1]) if path else None
        return default if line is None else line


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
        grid = top.get('grid_m')
        grid = None if grid is None else self.number(grid, ('grid_m',), positive=True)
        try:  # before anything of the site's size is built
            check_site_size(width, height, grid)
        except SiteValidationError as err:
            raise self.error(err.key_path, err.message) from err
        points = self.mapping(
            top['departure_points'], ('departure_points',), tuple(top['departure_points'] or ())
        )
        if not points:
            raise self.error(('departure_points',), 'at least one departure point is required')
        departures = {str(name): self.departure(str(name), value) for name, value in points.items()}
        seed = top.get('seed')
        entrance = top.get('entrance')
        parts: dict[str, Any] = {
            'name': self.text(top['name'], ('name',)),
            'walls': self.each(top['walls'], ('walls',), self.wall),
            'rooms': tuple(self.each(top.get('rooms') or [], ('rooms',), self.room)),
            'doors': tuple(self.each(top.get('doors') or [], ('doors',), self.inner_door)),
            'entrance': None if entrance is None else self.door(entrance, ('entrance',)),
            'grid_m': grid,
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
        # Room's __post_init__ turns the lists into read-only float arrays.
        return Room(room_id, rects, label=label, has_victim=victim, polygon=polygon)  # type: ignore[arg-type]

    def inner_door(self, value: Any, path: KeyPath) -> Door:
        door = self.door(value, path)
        if not door.room_ids:
            where = (*path, 'rooms') if isinstance(value, dict) and 'rooms' in value else path
            msg = (
                'a door joins rooms: give the id of the room behind it (one id: room to '
                'corridor) or of both rooms (two ids)'
            )
            raise self.error(where, msg)
        return door

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
