"""OA-Bug run report from a recorded bag alone: summary, Fig.-6 PNG, coverage over time.

Reads the simulator's ground truth from a rosbag2 directory (``/sim/site`` for walls and
rooms, ``/sim/poses`` for the paths, ``/sim/coverage`` for the first entries, ``/clock`` if
recorded for the end time) and rebuilds
what the spawner printed and drew, without rerunning the simulation::

    python -m swarm_analysis.oabug_report path/to/bag --out-dir figures/
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from swarm_common.stamps import stamp_to_seconds

from swarm_analysis.coverage import CoverageSummary, RoomFirstVisit
from swarm_analysis.plots import plot_coverage_curves, plot_site_paths

__all__ = ['RecordedRun', 'ReportError', 'load_run', 'main', 'write_report']

SITE_TOPIC = '/sim/site'
POSES_TOPIC = '/sim/poses'
COVERAGE_TOPIC = '/sim/coverage'
CLOCK_TOPIC = '/clock'


class ReportError(Exception):
    """The bag lacks what the report needs."""


@dataclass(frozen=True)
class RecordedRun:
    """The ground truth of one run as read from its bag.

    Attributes:
        site_name: name of the site.
        walls: (M, 4) walls x0, y0, x1, y1 [m], the entrance closed.
        room_rects: per room, (Ki, 4) rectangles x0, y0, x1, y1 [m].
        robot_names: robot names in /sim/poses order.
        times_s: (T,) stamps of the recorded poses [s].
        poses: (T, N, 3) true poses.
        coverage: the coverage summary.
    """

    site_name: str
    walls: np.ndarray
    room_rects: tuple[np.ndarray, ...]
    robot_names: tuple[str, ...]
    times_s: np.ndarray
    poses: np.ndarray
    coverage: CoverageSummary


def _site_geometry(msg: Any) -> tuple[str, np.ndarray, tuple[np.ndarray, ...]]:
    walls = np.asarray(msg.walls, dtype=float).reshape(-1, 4)
    entrance = [np.array([e.x0, e.y0, e.x1, e.y1], dtype=float) for e in msg.entrance]
    if entrance:
        walls = np.vstack([walls, *entrance])
    rooms = tuple(np.asarray(room.rects, dtype=float).reshape(-1, 4) for room in msg.rooms)
    return str(msg.name), walls, rooms


def load_run(bag: str | Path, *, allow_truncated: bool = False) -> RecordedRun:
    """Read a run's ground truth from the bag directory ``bag``.

    ``allow_truncated`` reads a damaged bag as far as it can be read.

    Raises:
        ReportError: a topic the report needs is missing from the bag.
    """
    from swarm_runtime.bag import read_messages

    site_msg = None
    coverage_msg = None
    times: list[float] = []
    poses: list[np.ndarray] = []
    names: tuple[str, ...] = ()
    end_s = 0.0
    for item in read_messages(
        bag, [SITE_TOPIC, POSES_TOPIC, COVERAGE_TOPIC, CLOCK_TOPIC], allow_truncated=allow_truncated
    ):
        msg = item.message
        if item.topic == SITE_TOPIC and site_msg is None:
            site_msg = msg
        elif item.topic == POSES_TOPIC:
            t = stamp_to_seconds(msg.header.stamp)
            current = tuple(p.robot for p in msg.poses)
            if names and current != names:
                raise ReportError(f'the robots in {POSES_TOPIC} changed at t = {t:.2f} s')
            names = current
            times.append(t)
            poses.append(np.array([[p.x, p.y, p.yaw] for p in msg.poses], dtype=float))
            end_s = max(end_s, t)
        elif item.topic == COVERAGE_TOPIC:
            coverage_msg = msg
            end_s = max(end_s, stamp_to_seconds(msg.header.stamp))
        elif item.topic == CLOCK_TOPIC:
            end_s = max(end_s, stamp_to_seconds(msg.clock))
    missing = [
        topic
        for topic, found in (
            (SITE_TOPIC, site_msg),
            (COVERAGE_TOPIC, coverage_msg),
            (POSES_TOPIC, poses or None),
        )
        if found is None
    ]
    if missing:
        raise ReportError(f'bag {bag} has no {", ".join(missing)} messages')
    assert site_msg is not None
    assert coverage_msg is not None
    site_name, walls, rooms = _site_geometry(site_msg)
    visits = [
        RoomFirstVisit(int(v.room_index), str(v.robot), stamp_to_seconds(v.stamp))
        for v in coverage_msg.visits
    ]
    summary = CoverageSummary.build(int(coverage_msg.rooms_total), visits, end_s, names)
    return RecordedRun(
        site_name=site_name,
        walls=walls,
        room_rects=rooms,
        robot_names=names,
        times_s=np.array(times),
        poses=np.stack(poses),
        coverage=summary,
    )


def write_report(run: RecordedRun, out_dir: Path, stem: str) -> tuple[Path, Path]:
    """Write the Fig.-6 PNG and the coverage-over-time PNG of ``run``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    cov = run.coverage
    title = (
        f'{stem}: {100.0 * cov.coverage:.1f} % ({cov.rooms_covered}/{cov.rooms_total} rooms) '
        f'in {cov.end_time_s:.0f} s'
    )
    paths = plot_site_paths(
        out_dir / f'{stem}_paths.png',
        walls=run.walls,
        room_rects=run.room_rects,
        robot_names=run.robot_names,
        trajectories=run.poses[:, :, :2],
        first_visitor=cov.first_visitor_by_room(),
        title=title,
    )
    curve = plot_coverage_curves(out_dir / f'{stem}_coverage.png', {stem: cov.curve()})
    return paths, curve


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: print the run's summary and write its figures; returns the exit code."""
    parser = argparse.ArgumentParser(
        prog='oabug_report',
        description='Coverage summary and figures of an OA-Bug run, from its bag alone.',
    )
    parser.add_argument('bag', type=Path, help='rosbag2 directory recorded by the spawner')
    parser.add_argument('--out-dir', type=Path, default=None, help='PNG directory (default: bag)')
    args = parser.parse_args(argv)
    from swarm_runtime.bag import BagError

    try:
        run = load_run(args.bag)
    except (ReportError, BagError) as err:
        sys.stderr.write(f'oabug_report: {err}\n')
        return 1
    out_dir = args.out_dir if args.out_dir is not None else args.bag
    figures = write_report(run, out_dir, f'{args.bag.name}')
    sys.stdout.write(run.coverage.format_report(f'Coverage of {run.site_name}') + '\n')
    for path in figures:
        sys.stdout.write(f'wrote {path}\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
