"""Figures of an OA-Bug run: the paper's Fig. 6 view and coverage over time (matplotlib).

Fig. 6 of the paper shows the site, each robot's path in its own colour, and every room
filled with the colour of the robot that entered it first. The functions take plain arrays
so the spawner (live run) and the bag report (replay) draw the very same figure. Figures
are built on :class:`matplotlib.figure.Figure` directly (no pyplot state, no backend switch),
so they render headless.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from swarm_common.outputs import atomic_output

__all__ = ['plot_coverage_curves', 'plot_site_paths', 'robot_colours']


def robot_colours(count: int) -> list[tuple[float, float, float, float]]:
    """One distinct colour per robot (tab10, then tab20 beyond ten robots)."""
    cmap = matplotlib.colormaps['tab10' if count <= 10 else 'tab20']
    return [cmap(i % cmap.N) for i in range(count)]


def plot_site_paths(
    path: Path,
    *,
    walls: np.ndarray,
    room_rects: Sequence[np.ndarray],
    robot_names: Sequence[str],
    trajectories: np.ndarray,
    first_visitor: Mapping[int, str],
    title: str = '',
) -> Path:
    """Write the Fig.-6 style PNG and return its path.

    Args:
        path: output PNG file.
        walls: (M, 4) wall segments x0, y0, x1, y1 [m].
        room_rects: per room, (Ki, 4) rectangles x0, y0, x1, y1 [m].
        robot_names: robot names in trajectory order.
        trajectories: (T, N, 2+) positions of every robot over time [m].
        first_visitor: room index -> name of the first robot in it.
        title: figure title.
    """
    colours = dict(zip(robot_names, robot_colours(len(robot_names)), strict=True))
    walls = np.asarray(walls, dtype=float).reshape(-1, 4)
    extent = walls.reshape(-1, 2)
    width = float(np.ptp(extent[:, 0])) if len(extent) else 1.0
    height = float(np.ptp(extent[:, 1])) if len(extent) else 1.0
    fig_w = 12.0
    fig = Figure(figsize=(fig_w, max(3.0, fig_w * height / max(width, 1e-6)) + 1.0))
    ax = fig.subplots()
    for index, rects in enumerate(room_rects):
        visitor = first_visitor.get(index)
        for x0, y0, x1, y1 in np.asarray(rects, dtype=float).reshape(-1, 4):
            if visitor is None:
                patch = Rectangle(
                    (x0, y0),
                    x1 - x0,
                    y1 - y0,
                    facecolor='0.9',
                    hatch='//',
                    edgecolor='0.7',
                    linewidth=0.0,
                )
            else:
                patch = Rectangle(
                    (x0, y0),
                    x1 - x0,
                    y1 - y0,
                    facecolor=colours.get(visitor, 'k'),
                    alpha=0.3,
                    linewidth=0.0,
                )
            ax.add_patch(patch)
    for x0, y0, x1, y1 in walls:
        ax.plot([x0, x1], [y0, y1], color='k', linewidth=1.5, solid_capstyle='butt')
    traj = np.asarray(trajectories, dtype=float)
    for i, name in enumerate(robot_names):
        if traj.ndim == 3 and traj.shape[0]:
            ax.plot(traj[:, i, 0], traj[:, i, 1], color=colours[name], linewidth=1.0, label=name)
            ax.plot(traj[0, i, 0], traj[0, i, 1], 'o', color=colours[name], markersize=4)
    ax.set_aspect('equal')
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    if title:
        ax.set_title(title)
    ax.legend(loc='upper left', bbox_to_anchor=(1.0, 1.0), fontsize='small', frameon=False)
    fig.tight_layout()
    path = Path(path)
    with atomic_output(path) as partial:  # no half-written PNG under the final name
        fig.savefig(partial, dpi=120)
    return path


def plot_coverage_curves(
    path: Path,
    curves: Mapping[str, tuple[np.ndarray, np.ndarray]],
    *,
    title: str = 'Room coverage over time',
    xlabel: str = 'sim time [s]',
) -> Path:
    """Write a PNG of one or more coverage step curves (label -> (times, fraction))."""
    fig = Figure(figsize=(7.0, 4.0))
    ax = fig.subplots()
    for label, (times, fraction) in curves.items():
        ax.step(np.asarray(times), 100.0 * np.asarray(fraction), where='post', label=label)
    ax.set_ylim(0.0, 102.0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel('rooms covered [%]')
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if len(curves) > 1:
        ax.legend()
    fig.tight_layout()
    path = Path(path)
    with atomic_output(path) as partial:  # no half-written PNG under the final name
        fig.savefig(partial, dpi=120)
    return path
