"""In-process records of what robots exchange and decide (ROS-free).

:class:`PeerUpdate` carries exactly the content of ``swarm_interfaces/BayesSwarmPeer``
(Algorithm 3, Table 9); the node converts between the two in ``conversions.py`` and the
batch simulator passes these records directly, so both paths feed the planner the same data.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

__all__ = ['Decision', 'DecisionKind', 'PeerUpdate']


def _empty_points() -> np.ndarray:
    return np.zeros((0, 2))


@dataclass(frozen=True)
class PeerUpdate:
    """One robot's broadcast after a waypoint decision.

    Attributes:
        sender: robot name (e.g. 'r3').
        decision_index: the sender's decision counter k (0 for the first decision).
        position_m: (2,) sender position when it decided [m].
        waypoint_m: (2,) sender's planned next waypoint [m].
        sample_points_m: (k, 2) locations of the sender's new observations [m].
        sample_values: (k,) their signal values.
        weaker_sources_m: (w, 2) locations the sender believes are weaker sources [m].
    """

    sender: str
    decision_index: int
    position_m: np.ndarray
    waypoint_m: np.ndarray
    sample_points_m: np.ndarray = field(default_factory=_empty_points)
    sample_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    weaker_sources_m: np.ndarray = field(default_factory=_empty_points)


class DecisionKind(Enum):
    """How a waypoint was chosen (Algorithm 1 branches)."""

    FIRST = 'first'
    ACQUISITION = 'acquisition'
    EXPLORE = 'explore'
    APPROACH = 'approach'
    RANDOM_JUMP = 'random_jump'
    FALLBACK = 'fallback'


@dataclass(frozen=True)
class Decision:
    """Outcome of one TAKEDECISION call.

    Attributes:
        waypoint_m: (2,) next waypoint [m].
        decision_index: k of this decision (0 for the first).
        kind: the branch of Algorithm 1 that produced it.
        alpha: exploitation weight used (NaN for the first decision).
        expected_source_m: (2,) argmax of the GP mean, or None for the first decision.
        n_samples: observations the GP was conditioned on (after downsampling).
        compute_time_s: wall-clock time of the decision [s].
        cpu_time_s: CPU time of this process during the decision [s] (robust to contention).
        detail: a short reason for fallbacks, empty otherwise.
    """

    waypoint_m: np.ndarray
    decision_index: int
    kind: DecisionKind
    alpha: float = float('nan')
    expected_source_m: np.ndarray | None = None
    n_samples: int = 0
    compute_time_s: float = 0.0
    detail: str = ''
    cpu_time_s: float = 0.0
