"""Command-line value types and options shared by the spawners."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from swarm_sim.errors import ConfigurationError
from swarm_sim.physics import PHYSICS_BACKENDS, RenderConfig

__all__ = ['add_physics_option', 'add_render_option', 'points_argument', 'render_config']


def points_argument(option: str) -> Callable[[str], np.ndarray]:
    """An argparse ``type`` reading ``'x,y;x,y;...'`` [m] into an (N, 2) float array.

    Args:
        option: the option's name, quoted in the error message (e.g. ``--depots``).
    """

    def parse(text: str) -> np.ndarray:
        msg = f"{option} must look like 'x,y;x,y', got {text!r}"
        try:
            rows = [[float(v) for v in item.split(',')] for item in text.split(';') if item.strip()]
            points = np.array(rows, dtype=float)
        except ValueError as err:
            raise argparse.ArgumentTypeError(msg) from err
        if points.ndim != 2 or points.shape[1] != 2:
            raise argparse.ArgumentTypeError(msg)
        return points

    return parse


def add_physics_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--physics NAME``: the engine's physics and ray-casting backend."""
    parser.add_argument(
        '--physics',
        choices=tuple(PHYSICS_BACKENDS),
        default='numpy',
        help='physics and ray casting: numpy (kinematic discs, exact 2D rays, fast) or '
        'pybullet (rigid bodies with real contacts, rayTestBatch; simulation install only); '
        'see docs/simulation.md',
    )


def add_render_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--render gui`` / ``--render frames DIR`` (pybullet physics only)."""
    parser.add_argument(
        '--render',
        nargs='+',
        default=None,
        metavar=('MODE', 'DIR'),
        help="watch the run (needs --physics pybullet): 'gui' opens pybullet's window "
        "(needs a display), 'frames DIR' writes top-down PNG frames and DIR/run.gif",
    )


def render_config(values: Sequence[str] | None) -> RenderConfig:
    """The :class:`RenderConfig` of a ``--render`` option's values (None: no rendering).

    Raises:
        ConfigurationError: not ``gui`` or ``frames DIR``.
    """
    if not values:
        return RenderConfig()
    mode, *rest = values
    if mode == 'gui' and not rest:
        return RenderConfig(mode='gui')
    if mode == 'frames' and len(rest) == 1:
        return RenderConfig(mode='frames', frames_dir=Path(rest[0]))
    msg = f"--render takes 'gui' or 'frames DIR', got {' '.join(values)!r}"
    raise ConfigurationError(msg)
