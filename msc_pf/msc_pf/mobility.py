"""Movement laws: avoidance, MSC evaluation and updates, far-field formation, eq. (8).

All functions are pure: positions and vectors are (2,) float arrays in metres in the world
frame; a "movement vector" is what the robot steers along (spec 0.2 turns it into a step).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from msc_pf.search import unit
from msc_pf.settings import AvoidanceConfig, MscConfig

__all__ = [
    'avoidance_vector',
    'count_closer_heading_to',
    'direct_approach_vector',
    'evaluation_value',
    'far_field_leader_vector',
    'follower_slot',
    'msc_follower_vector',
    'msc_gradient_leader_vector',
    'msc_leader_vector',
    'rssi_gradient',
    'step_displacement',
]


def avoidance_vector(
    position_m: np.ndarray,
    neighbour_positions_m: np.ndarray | Sequence[tuple[float, float]],
    config: AvoidanceConfig,
) -> np.ndarray:
    """Collision-avoidance vector S_i (spec 1.3).

    Args:
        position_m: (2,) own position.
        neighbour_positions_m: (M, 2) positions of the other robots heard.
        config: 'linear' form: sum of (x_i - x_j)/d (1 - d/d_s) over d < d_s, so each neighbour
            contributes at most 1; 'inverse_square': sum of (x_i - x_j)/d^3 within range.

    Returns:
        (2,) vector; zero when nobody is close. Coincident robots are skipped.
    """
    px, py = float(position_m[0]), float(position_m[1])
    linear = config.form == 'linear'
    reach = config.safety_radius_m if linear else config.inverse_square_range_m
    sx = sy = 0.0
    # A plain loop: a robot hears at most a few tens of neighbours, and numpy's per-call
    # overhead would dominate.
    for qx, qy in neighbour_positions_m:
        dx, dy = px - float(qx), py - float(qy)
        d = math.hypot(dx, dy)
        if d >= reach or d <= 1e-9:
            continue
        gain = (1.0 - d / config.safety_radius_m) / d if linear else 1.0 / d**3
        sx += gain * dx
        sy += gain * dy
    return np.array([sx, sy])


def count_closer_heading_to(own_rssi_dbm: float, neighbour_rssi_dbm: Sequence[float]) -> int:
    """N_i,k: neighbours heading to the same target that hear it louder (are closer)."""
    return sum(1 for value in neighbour_rssi_dbm if value > own_rssi_dbm)


def evaluation_value(
    rssi_mean_dbm: float, n_closer: int, dispersion_degree: float, dispersion_threshold: int
) -> float:
    """MSC evaluation value E = P + D N 1[N > N_th] (spec 1.6-1)."""
    penalty = dispersion_degree * n_closer if n_closer > dispersion_threshold else 0.0
    return rssi_mean_dbm + penalty


def msc_leader_vector(
    previous_m: np.ndarray,
    position_m: np.ndarray,
    personal_best_m: np.ndarray,
    avoidance: np.ndarray,
    config: MscConfig,
    rng: np.random.Generator,
) -> np.ndarray:
    """Leader update ``w v + c1 r1 (p_best - x) + a S`` (spec 1.6-3).

    When the robot stands on its own best position, it keeps probing along its previous
    vector (or a random direction if it had none).
    """
    pull = personal_best_m - position_m
    v = config.inertia * previous_m + config.cognitive * rng.random() * pull
    if float(np.hypot(pull[0], pull[1])) < 1e-9:
        probe = unit(previous_m)
        if not probe.any():
            theta = rng.uniform(0.0, 2.0 * np.pi)
            probe = np.array([np.cos(theta), np.sin(theta)])
        v = v + probe
    return v + config.avoidance_degree * avoidance


def msc_follower_vector(
    previous_m: np.ndarray,
    position_m: np.ndarray,
    global_best_m: np.ndarray,
    avoidance: np.ndarray,
    config: MscConfig,
    rng: np.random.Generator,
    personal_best_m: np.ndarray | None = None,
) -> np.ndarray:
    """Follower update ``w v + c2 r2 (g_best - x) + a S`` (spec 1.6-4).

    With ``personal_best_m`` (the optional full-PSO variant) the cognitive term is added too.
    """
    v = config.inertia * previous_m + config.social * rng.random() * (global_best_m - position_m)
    if personal_best_m is not None:
        v = v + config.cognitive * rng.random() * (personal_best_m - position_m)
    return v + config.avoidance_degree * avoidance


def rssi_gradient(positions_m: np.ndarray, rssi_dbm: np.ndarray) -> np.ndarray:
    """Least-squares slope [dB/m] of RSSI over position, a plane fit through the samples.

    Args:
        positions_m: (M, 2) sample positions.
        rssi_dbm: (M,) samples.

    Returns:
        (2,) gradient; zero when fewer than 3 samples or they lie (nearly) on a line.
    """
    positions = np.asarray(positions_m, dtype=np.float64).reshape(-1, 2)
    values = np.asarray(rssi_dbm, dtype=np.float64)
    if len(values) < 3:
        return np.zeros(2)
    centred = positions - positions.mean(axis=0)
    scatter = centred.T @ centred
    if np.linalg.eigvalsh(scatter)[0] < 1e-6 * len(values):
        return np.zeros(2)
    return np.linalg.solve(scatter, centred.T @ (values - values.mean()))


def msc_gradient_leader_vector(
    previous_m: np.ndarray,
    gradient: np.ndarray,
    avoidance: np.ndarray,
    config: MscConfig,
    rng: np.random.Generator,
) -> np.ndarray:
    """Leader update ``w v + c1 r1 unit(grad P) + a S``: head where RSSI is likely larger.

    ``gradient`` comes from :func:`rssi_gradient` over the swarm's recent samples. Without a
    usable gradient the leader keeps its previous direction (or a random one).
    """
    direction = unit(gradient)
    if not direction.any():
        direction = unit(previous_m)
        if not direction.any():
            theta = rng.uniform(0.0, 2.0 * np.pi)
            direction = np.array([np.cos(theta), np.sin(theta)])
    v = config.inertia * previous_m + config.cognitive * rng.random() * direction
    return v + config.avoidance_degree * avoidance


def far_field_leader_vector(
    position_m: np.ndarray, best_particle_m: np.ndarray, avoidance: np.ndarray, alpha: float
) -> np.ndarray:
    """(b-1) leader: ``unit(L_j* - x) + alpha S`` toward the largest-weight particle (spec 1.7)."""
    return unit(best_particle_m - position_m) + alpha * avoidance


def follower_slot(
    leader_position_m: np.ndarray, leader_heading: np.ndarray, slot_index: int, spacing_m: float
) -> np.ndarray:
    """Position of follower ``slot_index`` (0, 1, 2...) abreast of the leader (spec 1.7).

    Slots alternate left and right of the leader's heading: +d, -d, +2d, -2d, ...
    """
    heading = unit(leader_heading)
    left = np.array([-heading[1], heading[0]])
    rank = slot_index // 2 + 1
    side = 1.0 if slot_index % 2 == 0 else -1.0
    return leader_position_m + side * rank * spacing_m * left


def direct_approach_vector(
    position_m: np.ndarray, goal_m: np.ndarray, avoidance: np.ndarray, alpha: float
) -> np.ndarray:
    """Eq. (8): ``alpha S + (x_e - x)``, a goal displacement toward the estimate."""
    return alpha * avoidance + (goal_m - position_m)


def step_displacement(vector: np.ndarray, max_step_m: float, is_goal: bool) -> np.ndarray:
    """Displacement for one control period (spec 0.2).

    Along ``vector / |vector|`` by ``min(max_step, |vector|)`` for a goal displacement (eq. 8)
    and by ``max_step`` otherwise; zero when ``|vector| < 1e-6``.
    """
    norm = float(np.hypot(vector[0], vector[1]))
    if norm < 1e-6:
        return np.zeros(2)
    length = min(max_step_m, norm) if is_goal else max_step_m
    return np.asarray(vector, dtype=np.float64) * (length / norm)
