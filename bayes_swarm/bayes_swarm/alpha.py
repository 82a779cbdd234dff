"""Adaptive exploitation weight alpha (paper Sec. 2.2 and Algorithm 2).

Algorithm 2 compares squared distances with 2 * l_robot:

* a known weaker source within reach of the expected source x_star -> alpha = 0.1 (with
  ``weaker_source_radius_m`` set: within that distance instead, not in the paper);
* otherwise, no peer heading to x_star -> alpha = 0.8;
* otherwise the time schedule alpha = 1 / (1 + exp(-10 (t / T_max - 1/3))).

``time_scale`` multiplies T_max in the schedule (1 in the paper; the authors' code uses 0.1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

__all__ = ['AlphaBranch', 'AlphaDecision', 'exploitation_weight', 'scheduled_alpha']

WEAKER_SOURCE_ALPHA = 0.1
NO_PEER_ALPHA = 0.8


class AlphaBranch(Enum):
    """Which line of Algorithm 2 set alpha."""

    WEAKER_SOURCE = 'weaker_source'
    NO_PEER_NEAR = 'no_peer_near'
    SCHEDULE = 'schedule'
    EXPLORE = 'explore'
    FIXED = 'fixed'


@dataclass(frozen=True)
class AlphaDecision:
    """alpha in [0, 1] and the branch that produced it."""

    value: float
    branch: AlphaBranch


def scheduled_alpha(time_s: float, max_mission_time_s: float, time_scale: float = 1.0) -> float:
    """Sigmoid schedule 1 / (1 + exp(-10 (t / (time_scale T_max) - 1/3)))."""
    ratio = time_s / (time_scale * max_mission_time_s)
    return 1.0 / (1.0 + math.exp(-10.0 * (ratio - 1.0 / 3.0)))


def _min_squared_distance(points_m: np.ndarray, target_m: np.ndarray) -> float:
    pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
    if pts.shape[0] == 0:
        return math.inf
    diff = pts - np.asarray(target_m, dtype=float)
    return float(np.min(np.einsum('ij,ij->i', diff, diff)))


def exploitation_weight(
    expected_source_m: np.ndarray,
    peer_waypoints_m: np.ndarray,
    weaker_sources_m: np.ndarray,
    *,
    robot_size_m: float,
    time_s: float,
    max_mission_time_s: float,
    time_scale: float = 1.0,
    weaker_source_radius_m: float | None = None,
) -> AlphaDecision:
    """Algorithm 2: alpha for the expected source (2,), peers' waypoints (p, 2), weaker (w, 2).

    ``weaker_source_radius_m`` replaces the weaker-source test's squared distance
    < 2 l_robot (the paper's) by distance < the radius.
    """
    threshold = 2.0 * robot_size_m
    weak_threshold = threshold if weaker_source_radius_m is None else weaker_source_radius_m**2
    if _min_squared_distance(weaker_sources_m, expected_source_m) < weak_threshold:
        return AlphaDecision(WEAKER_SOURCE_ALPHA, AlphaBranch.WEAKER_SOURCE)
    if _min_squared_distance(peer_waypoints_m, expected_source_m) >= threshold:
        return AlphaDecision(NO_PEER_ALPHA, AlphaBranch.NO_PEER_NEAR)
    return AlphaDecision(
        scheduled_alpha(time_s, max_mission_time_s, time_scale), AlphaBranch.SCHEDULE
    )
