"""Relative completion time tau (Bayes-Swarm-P paper, Eq. 12), live or from a recorded bag.

tau = (t_achieved - t_idealized) / t_idealized, where t_idealized is the straight-line
travel time at the nominal speed V from the start of the robot that found the source to the
source. From a bag, the mission constants (source, eps, V, robots) come from the simulator's
``/sim/source_search`` status (with the start positions), and the detection is recomputed
from the true poses on ``/sim/poses``: the first instant a robot, moving straight between
two pose samples, comes within eps of the source.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from swarm_common.segments import first_entry_fraction

__all__ = [
    'TauError',
    'TauResult',
    'first_detection',
    'relative_completion_time',
    'tau_from_bag',
    'tau_from_tracks',
]

STATUS_TOPIC = '/sim/source_search'
POSES_TOPIC = '/sim/poses'


class TauError(ValueError):
    """A bag lacks what tau needs (no status message, unknown robots, ...)."""


def relative_completion_time(
    found_time_s: float, start_m: Iterable[float], source_m: Iterable[float], velocity_mps: float
) -> float:
    """Eq. 12 for a robot that started at ``start_m`` [m] and found the source at t [s]."""
    distance = float(np.hypot(*(np.asarray(source_m, float) - np.asarray(start_m, float))))
    if velocity_mps <= 0.0 or distance <= 0.0:
        msg = 'tau needs a positive speed and a start away from the source'
        raise TauError(msg)
    ideal = distance / velocity_mps
    return (found_time_s - ideal) / ideal


@dataclass(frozen=True)
class TauResult:
    """Outcome of a mission.

    Attributes:
        found: a robot came within eps of the source.
        found_time_s: time of detection [s] (NaN if not found).
        finder: name of the robot that found it ('' if none).
        tau: relative completion time (NaN if not found).
        reported_tau: tau the simulator itself reported in the bag (NaN if absent).
    """

    found: bool
    found_time_s: float
    finder: str
    tau: float
    reported_tau: float = math.nan


def first_detection(
    times_s: np.ndarray, positions_m: np.ndarray, source_m: np.ndarray, radius_m: float
) -> tuple[float, int] | None:
    """First (time [s], robot index) within ``radius_m`` of the source, else None.

    Args:
        times_s: (k,) increasing sample times.
        positions_m: (k, n, 2) positions of n robots at those times; robots move straight
            between samples.
    """
    pos = np.asarray(positions_m, dtype=float)
    src = np.asarray(source_m, dtype=float)
    for k in range(pos.shape[0]):
        if k == 0:
            inside = np.flatnonzero(np.hypot(*(pos[0] - src).T) <= radius_m)
            if inside.size:
                return float(times_s[0]), int(inside[0])
            continue
        best: tuple[float, int] | None = None
        for i in range(pos.shape[1]):
            s = first_entry_fraction(pos[k - 1, i], pos[k, i], src, radius_m)
            if s is not None:
                t = float(times_s[k - 1] + s * (times_s[k] - times_s[k - 1]))
                if best is None or t < best[0]:
                    best = (t, i)
        if best is not None:
            return best
    return None


def tau_from_tracks(
    times_s: np.ndarray,
    positions_m: np.ndarray,
    robots: list[str],
    source_m: np.ndarray,
    radius_m: float,
    velocity_mps: float,
    starts_m: np.ndarray | None = None,
) -> TauResult:
    """tau from (k,) times and (k, n, 2) true positions of ``robots``.

    ``starts_m`` (n, 2) are the start positions; None takes the first sample of each track.
    """
    hit = first_detection(times_s, positions_m, source_m, radius_m)
    if hit is None:
        return TauResult(False, math.nan, '', math.nan)
    time_s, index = hit
    starts = np.asarray(positions_m)[0] if starts_m is None else np.asarray(starts_m)
    start = starts[index]
    tau = relative_completion_time(time_s, start, source_m, velocity_mps)
    return TauResult(True, time_s, robots[index], tau)


def tau_from_bag(
    path: str | Path,
    status_topic: str = STATUS_TOPIC,
    poses_topic: str = POSES_TOPIC,
    *,
    allow_truncated: bool = False,
) -> TauResult:
    """tau of a recorded simulated mission (rosbag2 directory or .mcap file).

    ``allow_truncated`` reads a damaged bag as far as it can be read.

    Raises:
        TauError: if the bag has no status message or no poses of the status's robots.
    """
    from swarm_runtime.bag import read_messages

    status = None
    reported = math.nan
    times: list[float] = []
    rows: list[dict[str, tuple[float, float]]] = []
    for item in read_messages(path, [status_topic, poses_topic], allow_truncated=allow_truncated):
        msg = item.message
        if item.topic == status_topic:
            status = msg
            if msg.found:
                reported = float(msg.tau)
        else:
            stamp = float(msg.header.stamp.sec) + 1e-9 * float(msg.header.stamp.nanosec)
            times.append(stamp)
            rows.append({p.robot: (float(p.x), float(p.y)) for p in msg.poses})
    if status is None:
        msg_text = f'{path}: no {status_topic} message; was the mission simulated with it?'
        raise TauError(msg_text)
    robots = list(status.robots)
    complete = [k for k, row in enumerate(rows) if all(r in row for r in robots)]
    if not complete:
        msg_text = f'{path}: no {poses_topic} message with all robots {robots}'
        raise TauError(msg_text)
    positions = np.array([[rows[k][r] for r in robots] for k in complete])
    starts = None
    if len(status.start_x) == len(robots) == len(status.start_y):
        starts = np.column_stack([np.asarray(status.start_x), np.asarray(status.start_y)])
    result = tau_from_tracks(
        np.array([times[k] for k in complete]),
        positions,
        robots,
        np.array([status.source_x, status.source_y]),
        float(status.detection_radius_m),
        float(status.velocity_mps),
        starts,
    )
    return TauResult(result.found, result.found_time_s, result.finder, result.tau, reported)
