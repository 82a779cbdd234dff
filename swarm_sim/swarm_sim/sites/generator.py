"""Seeded generator of OA-Bug search sites, after the structure of the authors' generator.

The authors' generator (in their simulator, SwarmSearchSimulation; this module is an
independent implementation of how it behaves) carves a building out of solid wall:

1. a 4-cell-wide cross of corridors through the middle, spanning the whole site;
2. extra full-length corridors, 2-3 cells wide, placed at random in the remaining bands as
   long as they leave room on both sides for a room of the minimum length and its two wall
   lines (``room_min_length_cells + 2`` cells). Small thus always has one horizontal
   corridor and 3-5 vertical ones; Medium 2-3 and 4-6 (rarely 7), Big 3-4 (rarely 5) and
   6-10, as the authors' generator gives;
3. the solid blocks between corridors are the *spaces*; rooms are carved into them one at a
   time: pick a space, pick a door cell on a wall with exactly one open neighbour (a
   corridor, or an existing room: a nested room), and grow a rectangle away from that
   neighbour, random in depth and lateral extent, keeping one wall line around it;
4. ``victims`` random rooms are marked as holding a victim.

Blocks that corridors surround on all sides become the paper's *isolated islands* (Medium
and Big have them; Small's spaces all touch the outer wall). The site gets one entrance, a
door in the bottom wall at the foot of the central vertical corridor, and the authors'
departure points: "center" in the middle of the corridor cross and "edge" 2.5 cells inside
the entrance, heading into the building.

The generator writes a labelled layout (:class:`~swarm_sim.sites.layout.Layout`), which the
layout importer turns into the :class:`~swarm_sim.sites.model.Site`; a generated site
therefore round-trips through a ``.lay`` file exactly.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Final

import numpy as np

from swarm_sim.sites.errors import GeneratorError
from swarm_sim.sites.layout import (
    CORRIDOR_DOOR,
    FREE,
    MAX_LAYOUT_CHARACTERS,
    MAX_LAYOUT_COLUMNS,
    MAX_LAYOUT_LINES,
    ROOM_DOOR,
    WALL,
    Layout,
    LayoutMode,
    layout_to_site,
)
from swarm_sim.sites.model import CELL_M, MAX_SIDE_M, Site

__all__ = [
    'BIG',
    'MAX_ACTIONS_PER_ROBOT',
    'MEDIUM',
    'PRESETS',
    'SMALL',
    'GeneratorConfig',
    'generate_layout',
    'generate_site',
    'resolve_config',
    'with_size',
]


@dataclass(frozen=True)
class GeneratorConfig:
    """Parameters of a generated site (defaults: the paper's Small configuration).

    Attributes:
        width_cells: grid vertices along x, including the outer walls (Table II "width").
        height_cells: grid vertices along y, including the outer walls.
        rooms: number of rooms to carve; generation fails if they do not fit.
        victims: rooms holding a victim (the authors' runner uses 10 in every
            configuration); they are ordinary rooms for coverage.
        cell_m: grid spacing [m], the paper's 4/15 m.
        central_corridor_cells: width of the central corridor cross [cells].
        extra_corridor_cells: (min, max) width of the extra corridors [cells].
        room_min_length_cells: minimum room length; extra corridors keep this + 2 solid cells
            (a room and its two wall lines) to the edges of the band they split [cells].
        max_attempts: whole-site attempts before giving up when the rooms do not fit.
        name: configuration name, used in site names.
    """

    width_cells: int = 60
    height_cells: int = 30
    rooms: int = 30
    victims: int = 10
    cell_m: float = CELL_M
    central_corridor_cells: int = 4
    extra_corridor_cells: tuple[int, int] = (2, 3)
    room_min_length_cells: int = 5
    max_attempts: int = 20
    name: str = 'custom'

    def __post_init__(self) -> None:
        minimum = self.central_corridor_cells + 6
        if self.width_cells < minimum or self.height_cells < minimum:
            msg = (
                f'a site needs at least {minimum} x {minimum} cells around a '
                f'{self.central_corridor_cells}-cell corridor cross, got '
                f'{self.width_cells} x {self.height_cells}'
            )
            raise GeneratorError(msg)
        if self.rooms < 1 or not 0 <= self.victims <= self.rooms:
            msg = (
                'need rooms >= 1 (a site without rooms has nothing to search) and '
                '0 <= victims <= rooms, got '
                f'rooms={self.rooms}, victims={self.victims}'
            )
            raise GeneratorError(msg)
        low, high = self.extra_corridor_cells
        if not 1 <= low <= high:
            msg = (
                'extra_corridor_cells must be (min, max) with 1 <= min <= max, got '
                f'{self.extra_corridor_cells}'
            )
            raise GeneratorError(msg)
        if (
            self.central_corridor_cells < 2
            or self.room_min_length_cells < 1
            or self.max_attempts < 1
        ):
            raise GeneratorError(
                'central_corridor_cells >= 2, room_min_length_cells >= 1 and max_attempts >= 1 '
                'are required'
            )
        if not (math.isfinite(self.cell_m) and self.cell_m > 0):
            msg = f'cell_m must be positive, got {self.cell_m!r}'
            raise GeneratorError(msg)
        if (
            self.width_cells > MAX_LAYOUT_COLUMNS
            or self.height_cells > MAX_LAYOUT_LINES
            or self.width_cells * self.height_cells > MAX_LAYOUT_CHARACTERS
        ):
            msg = (
                f'a site of {self.width_cells} x {self.height_cells} cells is too large: at most '
                f'{MAX_LAYOUT_COLUMNS} x {MAX_LAYOUT_LINES} cells and {MAX_LAYOUT_CHARACTERS} '
                'in all (the largest layout the importer reads)'
            )
            raise GeneratorError(msg)
        if max(self.width_m, self.height_m) > MAX_SIDE_M:
            msg = (
                f'a site of {self.width_m:g} x {self.height_m:g} m is too large: a side may be at '
                f'most {MAX_SIDE_M:g} m'
            )
            raise GeneratorError(msg)

    @property
    def width_m(self) -> float:
        """Site width [m]: (width_cells - 1) grid steps."""
        return (self.width_cells - 1) * self.cell_m

    @property
    def height_m(self) -> float:
        """Site height [m]."""
        return (self.height_cells - 1) * self.cell_m


SMALL: Final = GeneratorConfig(60, 30, rooms=30, name='small')
MEDIUM: Final = GeneratorConfig(80, 40, rooms=60, name='medium')
BIG: Final = GeneratorConfig(120, 60, rooms=120, name='big')
PRESETS: Final[Mapping[str, GeneratorConfig]] = MappingProxyType(
    {'small': SMALL, 'medium': MEDIUM, 'big': BIG}
)
"""The site configurations of the paper's Table II."""

MAX_ACTIONS_PER_ROBOT: Final[Mapping[str, int]] = MappingProxyType(
    {'small': 1000, 'medium': 2000, 'big': 4000}
)
"""Table II: the authors' per-robot action budget of each configuration."""

_SOLID: Final = 0
_OPEN: Final = 1
_INTERIOR: Final = 2
_DOOR: Final = 3
# Room letters, cycled; 'D' is left out because it marks the departure point in a layout
# (the authors' generator uses it for its fourth room, their layout reader as the departure).
_LABELS: Final = [ord(ch) for ch in 'ABCEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz']


def resolve_config(config: GeneratorConfig | str) -> GeneratorConfig:
    """A config, or the Table II preset called "small", "medium" or "big"."""
    if isinstance(config, GeneratorConfig):
        return config
    try:
        return PRESETS[config.lower()]
    except KeyError:
        msg = f'unknown site configuration {config!r}; choose one of {", ".join(PRESETS)}'
        raise GeneratorError(msg) from None


def generate_layout(config: GeneratorConfig | str, seed: int) -> Layout:
    """The labelled layout of the site for ``config`` and ``seed``.

    Raises:
        GeneratorError: the rooms did not fit in ``config.max_attempts`` attempts.
    """
    config = resolve_config(config)
    rng = np.random.default_rng(seed)
    best = 0
    for _ in range(config.max_attempts):
        carver = _Carver(config, rng)
        if carver.carve_rooms() == config.rooms:
            return Layout(carver.codes(), source=f'{config.name} site, seed {seed}')
        best = max(best, carver.placed)
    msg = (
        f'could place only {best} of {config.rooms} rooms in a {config.width_cells} x '
        f'{config.height_cells} site in {config.max_attempts} attempts; ask for fewer rooms or '
        'a larger site'
    )
    raise GeneratorError(msg)


def generate_site(config: GeneratorConfig | str, seed: int, *, name: str | None = None) -> Site:
    """Generate, convert and validate the site for ``config`` and ``seed``."""
    config = resolve_config(config)
    layout = generate_layout(config, seed)
    result = layout_to_site(
        layout,
        mode=LayoutMode.LABELLED,
        cell_m=config.cell_m,
        name=name if name is not None else f'{config.name}-seed{seed}',
        seed=seed,
    )
    return result.site


def with_size(
    config: GeneratorConfig, *, width_cells: int, height_cells: int, rooms: int
) -> GeneratorConfig:
    """``config`` with another size and room count (victims capped at the room count)."""
    return replace(
        config,
        width_cells=width_cells,
        height_cells=height_cells,
        rooms=rooms,
        victims=min(config.victims, rooms),
        name='custom',
    )


class _Carver:
    """One attempt at carving a site into a solid grid."""

    def __init__(self, config: GeneratorConfig, rng: np.random.Generator) -> None:
        self.config = config
        self.rng = rng
        h, w = config.height_cells, config.width_cells
        self.state = np.full((h, w), _SOLID, dtype=np.int8)
        self.room_of = np.full((h, w), -1, dtype=np.int32)
        self.door_codes: dict[tuple[int, int], int] = {}
        self.blacklist = np.zeros((h, w), dtype=bool)
        self.placed = 0
        c = config.central_corridor_cells
        self.h0 = h // 2 - c // 2
        self.w0 = w // 2 - c // 2
        self.state[self.h0 : self.h0 + c, 1 : w - 1] = _OPEN
        self.state[1 : h - 1, self.w0 : self.w0 + c] = _OPEN
        row_bands = self._extra_corridors([(1, self.h0 - 1), (self.h0 + c, h - 2)], h, axis=0)
        col_bands = self._extra_corridors([(1, self.w0 - 1), (self.w0 + c, w - 2)], w, axis=1)
        self.spaces = [(r0, r1, c0, c1) for r0, r1 in row_bands for c0, c1 in col_bands]

    def _extra_corridors(
        self, bands: list[tuple[int, int]], size: int, axis: int
    ) -> list[tuple[int, int]]:
        """Place the extra corridors across ``axis`` into ``bands`` (inclusive solid ranges)
        and return the bands left between corridors."""
        low = max(1, size // 20)
        high = max(low, size // 10)
        count = int(self.rng.integers(low, high + 1)) - 1
        margin = self.config.room_min_length_cells + 2  # a shortest room and its wall lines
        min_width, max_width = self.config.extra_corridor_cells
        for _ in range(count):
            width = int(self.rng.integers(min_width, max_width + 1))
            fitting = [k for k, (a, b) in enumerate(bands) if b - a + 1 >= 2 * margin + width]
            if not fitting:
                break
            k = fitting[int(self.rng.integers(len(fitting)))]
            a, b = bands[k]
            start = int(self.rng.integers(a + margin, b - margin - width + 2))
            if axis == 0:
                self.state[start : start + width, 1:-1] = _OPEN
            else:
                self.state[1:-1, start : start + width] = _OPEN
            bands[k : k + 1] = [(a, start - 1), (start + width, b)]
        return bands

    def carve_rooms(self) -> int:
        """Carve rooms until the requested number stands or no space has a door candidate;
        return how many were placed."""
        active = list(range(len(self.spaces)))
        while self.placed < self.config.rooms and active:
            pick = int(self.rng.integers(len(active)))
            candidates = self._door_candidates(self.spaces[active[pick]])
            if len(candidates) == 0:
                active.pop(pick)
                continue
            r, c, dr, dc = (int(v) for v in candidates[int(self.rng.integers(len(candidates)))])
            if self._carve(r, c, dr, dc):
                self.placed += 1
            else:
                self.blacklist[r, c] = True
        return self.placed

    def _door_candidates(self, space: tuple[int, int, int, int]) -> np.ndarray:
        """(K, 4) rows of r, c, dr, dc: solid cells of the space with exactly one open
        neighbour (corridor or room interior, no door next to it) and the direction to grow."""
        r0, r1, c0, c1 = space
        state = self.state
        window = state[r0 - 1 : r1 + 2, c0 - 1 : c1 + 2]
        opening = (window == _OPEN) | (window == _INTERIOR)
        doors = window == _DOOR
        up, down = opening[:-2, 1:-1], opening[2:, 1:-1]
        left, right = opening[1:-1, :-2], opening[1:-1, 2:]
        near_door = doors[:-2, 1:-1] | doors[2:, 1:-1] | doors[1:-1, :-2] | doors[1:-1, 2:]
        count = up.astype(np.int8) + down + left + right
        inner = (window[1:-1, 1:-1] == _SOLID) & ~self.blacklist[r0 : r1 + 1, c0 : c1 + 1]
        chosen = inner & (count == 1) & ~near_door
        rows, cols = np.nonzero(chosen)
        # Grow away from the open neighbour.
        dr = down[rows, cols].astype(int) * -1 + up[rows, cols].astype(int)
        dc = right[rows, cols].astype(int) * -1 + left[rows, cols].astype(int)
        return np.column_stack([rows + r0, cols + c0, dr, dc])

    def _carve(self, r: int, c: int, dr: int, dc: int) -> bool:
        """Grow a room from door (r, c) in direction (dr, dc); False if none fits.

        Works in a frame local to the door: u is the depth from the door's wall line (u = 0)
        into the solid, v the lateral offset from the door. The room's interior spans
        u = 1..depth, its wall rectangle u = 0..depth + 1, and every cell of that rectangle
        must be solid before carving, so the room keeps one wall line to everything else.
        """
        h, w = self.state.shape
        pr, pc = abs(dc), abs(dr)  # lateral axis
        depth_limit = (h - 1 - r if dr > 0 else r) if dr else (w - 1 - c if dc > 0 else c)
        lateral_neg = r if pr else c
        lateral_pos = (h - 1 - r) if pr else (w - 1 - c)
        u = np.arange(depth_limit + 1)[:, None]
        v = np.arange(-lateral_neg, lateral_pos + 1)[None, :]
        solid = self.state[r + u * dr + v * pr, c + u * dc + v * pc] == _SOLID
        # Solid cells from the door line inwards, per lateral offset.
        depth_run = np.where(solid.all(axis=0), solid.shape[0], solid.argmin(axis=0))
        v0 = lateral_neg
        if v0 < 1 or v0 + 1 >= solid.shape[1]:
            return False
        max_depth = int(depth_run[v0 - 1 : v0 + 2].min()) - 2  # door row + back wall line
        if max_depth < 1:
            return False
        depth = int(self.rng.integers(1, max_depth + 1))
        deep_enough = depth_run >= depth + 2
        left_free = _run_length(deep_enough[v0 - 1 :: -1])
        right_free = _run_length(deep_enough[v0 + 1 :])
        extend_neg = int(self.rng.integers(0, left_free))  # keep one column for the side wall
        extend_pos = int(self.rng.integers(0, right_free))
        uu = np.arange(1, depth + 1)[:, None]
        vv = np.arange(-extend_neg, extend_pos + 1)[None, :]
        rows, cols = r + uu * dr + vv * pr, c + uu * dc + vv * pc
        self.state[rows, cols] = _INTERIOR
        self.room_of[rows, cols] = self.placed
        behind = self.state[r - dr, c - dc]
        self.door_codes[(r, c)] = CORRIDOR_DOOR if behind == _OPEN else ROOM_DOOR
        self.state[r, c] = _DOOR
        return True

    def codes(self) -> np.ndarray:
        """(H, W) character codes of the labelled layout."""
        codes = np.full(self.state.shape, WALL, dtype=np.int32)
        codes[self.state == _OPEN] = FREE
        labels = np.array([_LABELS[k % len(_LABELS)] for k in range(self.placed)], dtype=np.int32)
        victims = self.rng.choice(self.placed, size=self.config.victims, replace=False)
        labels[np.sort(victims)] = [ord('0') + k % 10 for k in range(len(victims))]
        interior = self.state == _INTERIOR
        codes[interior] = labels[self.room_of[interior]]
        for (r, c), code in self.door_codes.items():
            codes[r, c] = code
        h, w = codes.shape
        centre = (w - 1) / 2
        for col in sorted({math.floor(centre), math.ceil(centre)}):
            codes[h - 1, col] = CORRIDOR_DOOR  # the entrance
        return codes


def _run_length(flags: np.ndarray) -> int:
    """Number of leading True values."""
    if flags.size == 0 or not flags[0]:
        return 0
    return int(flags.size) if flags.all() else int(np.argmin(flags))
