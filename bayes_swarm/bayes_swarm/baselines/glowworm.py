"""Glowworm swarm optimisation for source search (paper Table 11).

One synchronous iteration, for every agent i:

1. luciferin  l_i <- (1 - rho) l_i + gamma J(x_i);
2. neighbours N_i = {j != i : |x_j - x_i| <= r_d_i and l_i < l_j};
3. leader j drawn with probability (l_j - l_i) / sum_k (l_k - l_i) (or the brightest
   neighbour in the deterministic variant); no neighbour -> no move;
4. move a step s toward the leader (a move leaving the arena is rejected);
5. r_d_i <- min(r_s, max(0, r_d_i + beta (n_t - |N_i|))).

Luciferins are all updated first, leaders are chosen from that snapshot, then everyone moves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bayes_swarm.settings import Arena, GlowwormConfig

__all__ = ['GlowwormAgent', 'GlowwormState', 'GlowwormSwarm', 'glowworm_step', 'select_leaders']


@dataclass(frozen=True)
class GlowwormState:
    """Swarm state: (m, 2) positions [m], (m,) luciferins, (m,) decision ranges [m]."""

    positions_m: np.ndarray
    luciferin: np.ndarray
    decision_range_m: np.ndarray


def select_leaders(
    positions_m: np.ndarray,
    luciferin: np.ndarray,
    decision_range_m: np.ndarray,
    rng: np.random.Generator,
    *,
    deterministic: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Leader index (m,) of every agent (-1: none) and its neighbour count (m,)."""
    diff = positions_m[None, :, :] - positions_m[:, None, :]
    dist = np.hypot(diff[..., 0], diff[..., 1])
    gain = luciferin[None, :] - luciferin[:, None]
    neighbours = (dist <= decision_range_m[:, None]) & (gain > 0.0)
    np.fill_diagonal(neighbours, False)
    counts = neighbours.sum(axis=1)
    leaders = np.full(positions_m.shape[0], -1)
    weights = np.where(neighbours, gain, 0.0)
    totals = weights.sum(axis=1)
    for i in np.flatnonzero(totals > 0.0):
        if deterministic:
            leaders[i] = int(np.argmax(np.where(neighbours[i], luciferin, -np.inf)))
        else:
            leaders[i] = int(rng.choice(weights.shape[1], p=weights[i] / totals[i]))
    return leaders, counts


def glowworm_step(
    state: GlowwormState,
    signal: np.ndarray,
    config: GlowwormConfig,
    arena: Arena,
    step_m: float,
    rng: np.random.Generator,
) -> GlowwormState:
    """One synchronous GSO iteration given the (m,) signal J measured at the positions."""
    luciferin = (1.0 - config.luciferin_decay) * state.luciferin + (
        config.luciferin_enhancement * np.asarray(signal, dtype=float)
    )
    leaders, counts = select_leaders(
        state.positions_m,
        luciferin,
        state.decision_range_m,
        rng,
        deterministic=config.deterministic,
    )
    positions = state.positions_m.copy()
    movers = np.flatnonzero(leaders >= 0)
    if movers.size:
        toward = state.positions_m[leaders[movers]] - state.positions_m[movers]
        norm = np.hypot(toward[:, 0], toward[:, 1])
        ok = norm > 0.0
        target = state.positions_m[movers[ok]] + step_m * toward[ok] / norm[ok, None]
        inside = arena.contains(target)
        positions[movers[ok][inside]] = target[inside]
    ranges = np.minimum(
        config.sensor_range_m,
        np.maximum(
            0.0, state.decision_range_m + config.range_gain * (config.desired_neighbours - counts)
        ),
    )
    return GlowwormState(positions, luciferin, ranges)


class GlowwormSwarm:
    """Synchronous GSO over a whole swarm (used by the batch simulator)."""

    def __init__(
        self,
        config: GlowwormConfig,
        arena: Arena,
        positions_m: np.ndarray,
        velocity_mps: float,
        seed: int | None = None,
    ) -> None:
        pos = np.asarray(positions_m, dtype=float).reshape(-1, 2)
        m = pos.shape[0]
        self._cfg = config
        self._arena = arena
        self._rng = np.random.default_rng(seed)
        self.step_m = min(config.step_m, velocity_mps / config.decision_rate_hz)
        self.state = GlowwormState(
            pos,
            np.full(m, config.initial_luciferin),
            np.full(m, config.sensor_range_m),
        )

    @property
    def period_s(self) -> float:
        """Time between two GSO iterations [s]."""
        return 1.0 / self._cfg.decision_rate_hz

    def step(self, signal: np.ndarray) -> np.ndarray:
        """Advance one iteration with the (m,) measured signal; returns the new positions."""
        self.state = glowworm_step(
            self.state, signal, self._cfg, self._arena, self.step_m, self._rng
        )
        return self.state.positions_m


class GlowwormAgent:
    """GSO decisions of one robot from its own signal and its neighbours' broadcasts.

    The same update as :func:`glowworm_step`, seen from one agent: peers' luciferins are the
    latest they broadcast, so decisions are asynchronous.
    """

    def __init__(
        self, config: GlowwormConfig, arena: Arena, velocity_mps: float, seed: int | None = None
    ) -> None:
        self._cfg = config
        self._arena = arena
        self._rng = np.random.default_rng(seed)
        self.step_m = min(config.step_m, velocity_mps / config.decision_rate_hz)
        self.luciferin = config.initial_luciferin
        self.decision_range_m = config.sensor_range_m

    def update_luciferin(self, signal: float) -> float:
        """Step 1 with the latest measured signal; returns the new luciferin."""
        cfg = self._cfg
        self.luciferin = (1.0 - cfg.luciferin_decay) * self.luciferin + (
            cfg.luciferin_enhancement * signal
        )
        return self.luciferin

    def next_waypoint(
        self, position_m: np.ndarray, peer_positions_m: np.ndarray, peer_luciferin: np.ndarray
    ) -> np.ndarray:
        """Steps 2-5 for this agent; returns the (2,) next position [m]."""
        own = np.asarray(position_m, dtype=float).reshape(1, 2)
        positions = np.vstack([own, np.asarray(peer_positions_m, dtype=float).reshape(-1, 2)])
        luciferin = np.concatenate([[self.luciferin], np.asarray(peer_luciferin, dtype=float)])
        ranges = np.full(positions.shape[0], self.decision_range_m)
        leaders, counts = select_leaders(
            positions, luciferin, ranges, self._rng, deterministic=self._cfg.deterministic
        )
        cfg = self._cfg
        self.decision_range_m = min(
            cfg.sensor_range_m,
            max(
                0.0,
                self.decision_range_m + cfg.range_gain * (cfg.desired_neighbours - counts[0]),
            ),
        )
        if leaders[0] < 0:
            return own[0].copy()
        toward = positions[leaders[0]] - own[0]
        norm = float(np.hypot(*toward))
        if norm <= 0.0:
            return own[0].copy()
        target = own[0] + self.step_m * toward / norm
        return target if self._arena.contains(target) else own[0].copy()
