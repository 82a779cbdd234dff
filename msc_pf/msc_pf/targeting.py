"""Capture and re-targeting with the R * N_r rule (paper Sec. III-c, Fig. 3; spec 1.8).

After its target is captured, a robot of the proposed scheme chooses among the targets whose
location estimates have converged. A candidate's value is its RSSI when the robot hears it,
or else the RSSI the path-loss model predicts at the distance to the estimate (so both kinds
share one dBm scale). N_r counts the neighbours closer to the candidate than the robot; the
value is degraded by R * N_r when the candidate is heard and N_r > N_thr, or when it is not
heard and N_r >= 1. The largest value wins; ties go to the lower target ID.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from msc_pf.settings import PhaseConfig, RadioConfig

__all__ = ['Candidate', 'candidate_value', 'count_closer_to', 'select_retarget']


@dataclass(frozen=True)
class Candidate:
    """A target with a converged estimate, as seen by one robot.

    Attributes:
        target_id: emitter ID.
        estimate_m: (2,) converged location estimate [m].
        rssi_dbm: the robot's smoothed RSSI of the target when it currently hears it, else None.
    """

    target_id: int
    estimate_m: np.ndarray
    rssi_dbm: float | None = None


def count_closer_to(
    position_m: np.ndarray, goal_m: np.ndarray, neighbour_positions_m: np.ndarray
) -> int:
    """N_r: neighbours strictly closer to ``goal_m`` than ``position_m`` is."""
    if len(neighbour_positions_m) == 0:
        return 0
    own = float(np.hypot(*(goal_m - position_m)))
    others = np.hypot(*(np.asarray(neighbour_positions_m) - goal_m[None, :]).T)
    return int(np.count_nonzero(others < own))


def candidate_value(
    candidate: Candidate,
    position_m: np.ndarray,
    n_closer: int,
    radio: RadioConfig,
    config: PhaseConfig,
) -> float:
    """Evaluation value of one candidate including the R * N_r degradation."""
    if candidate.rssi_dbm is not None:
        value = candidate.rssi_dbm
        degrade = n_closer > config.retarget_threshold
    else:
        value = radio.mean_rssi_dbm(float(np.hypot(*(candidate.estimate_m - position_m))))
        degrade = n_closer >= 1
    return value + (config.retarget_penalty * n_closer if degrade else 0.0)


def select_retarget(
    candidates: Sequence[Candidate],
    position_m: np.ndarray,
    neighbour_positions_m: np.ndarray,
    radio: RadioConfig,
    config: PhaseConfig,
    max_closer: int = 0,
) -> int | None:
    """ID of the candidate with the largest value (lower ID on ties); None without candidates.

    With ``max_closer`` > 0, candidates that at least that many neighbours are closer to
    are left to them (beyond the paper: ``phases.max_pursuers``).
    """
    best_id: int | None = None
    best_value = -np.inf
    for candidate in sorted(candidates, key=lambda c: c.target_id):
        n_r = count_closer_to(position_m, candidate.estimate_m, neighbour_positions_m)
        if 0 < max_closer <= n_r:
            continue
        value = candidate_value(candidate, position_m, n_r, radio, config)
        if value > best_value:
            best_id, best_value = candidate.target_id, value
    return best_id
