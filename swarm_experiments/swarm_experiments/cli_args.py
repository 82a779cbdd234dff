"""Command-line value types shared by the spawners."""

from __future__ import annotations

import argparse
from collections.abc import Callable

import numpy as np

__all__ = ['points_argument']


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
