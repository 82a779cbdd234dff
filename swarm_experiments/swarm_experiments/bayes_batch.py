"""Batch runner of Bayes-Swarm missions and their baselines, without the runtime.

It steps the same planner objects the ROS node uses in the paper's motion model
(:class:`swarm_sim.point_robots.PointRobotField`): robots fly straight legs at V, sample the
field at every tick of the observation clock (t = k / f_Hz, all robots), decide on arrival at
their waypoint (so decisions are asynchronous) and broadcast a
:class:`~bayes_swarm.messages.PeerUpdate`, delivered at once to every robot within
``comm_range_m`` unless dropped with probability ``loss_probability``. Detection is
continuous: a mission succeeds at the first instant any robot comes within eps of the source
along its straight leg. Glowworm runs after the first dispersal leg as a synchronous
iteration at its own decision rate.

Decisions take no simulated time; their wall-clock duration is recorded per robot.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from bayes_swarm.baselines.exhaustive import sweep_paths
from bayes_swarm.baselines.glowworm import GlowwormSwarm
from bayes_swarm.baselines.levy import LevyWalk
from bayes_swarm.errors import ConfigError
from bayes_swarm.messages import Decision, DecisionKind, PeerUpdate
from bayes_swarm.planner import BayesSwarmPlanner, first_waypoint
from bayes_swarm.settings import (
    Arena,
    BayesSwarmConfig,
    ExhaustiveConfig,
    GlowwormConfig,
    LevyConfig,
)
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.point_robots import FieldFunction, PointRobotField

__all__ = [
    'ALGORITHMS',
    'MissionResult',
    'MissionSpec',
    'depot_fan',
    'robot_start_and_fan',
    'run_mission',
]

Algorithm = Literal['bayes_swarm_p', 'bayes_swarm_o', 'glowworm', 'levy', 'exhaustive']
ALGORITHMS: tuple[str, ...] = ('bayes_swarm_p', 'bayes_swarm_o', 'glowworm', 'levy', 'exhaustive')
_TIME_EPS = 1e-9


@dataclass(frozen=True)
class MissionSpec:
    """World and mission settings (the part of a case the robots do not know).

    Attributes:
        field: (q, 2) points [m] -> (q,) signal values.
        source_m: (2,) true source [m].
        depots_m: (d, 2) start points; robot i starts at depot i mod d.
        depot_direction_offsets_deg: per depot, the heading the first-decision fan starts at.
        planner: Bayes-Swarm settings shared by all robots (robot_index/n_robots are set here).
        noise_std: std of additive Gaussian measurement noise.
        relative_noise: std of measurement noise as a fraction of |f| (Table 7's |A| / k).
        comm_range_m: peer-message range [m]; None is unlimited.
        loss_probability: probability that one peer message to one receiver is lost.
        faults: faults injected on purpose (:mod:`swarm_sim.faults`): robot dropouts, a
            shorter or lossier peer link, stuck or drifting signal sensors.
    """

    field: FieldFunction
    source_m: np.ndarray
    depots_m: np.ndarray
    planner: BayesSwarmConfig
    depot_direction_offsets_deg: tuple[float, ...] = (0.0,)
    noise_std: float = 0.0
    relative_noise: float = 0.0
    comm_range_m: float | None = None
    loss_probability: float = 0.0
    glowworm: GlowwormConfig = field(default_factory=GlowwormConfig)
    levy: LevyConfig = field(default_factory=LevyConfig)
    exhaustive: ExhaustiveConfig = field(default_factory=ExhaustiveConfig)
    faults: FaultConfig = field(default_factory=FaultConfig)

    def __post_init__(self) -> None:
        if self.noise_std < 0.0 or self.relative_noise < 0.0:
            msg = 'noise_std and relative_noise must be >= 0'
            raise ConfigError(msg)
        if self.comm_range_m is not None and self.comm_range_m < 0.0:
            msg = f'comm_range_m must be >= 0 or None, got {self.comm_range_m}'
            raise ConfigError(msg)
        if not 0.0 <= self.loss_probability <= 1.0:
            msg = f'loss_probability must be in [0, 1], got {self.loss_probability}'
            raise ConfigError(msg)

    @property
    def arena(self) -> Arena:
        return self.planner.arena


@dataclass
class MissionResult:
    """Outcome of one run.

    Attributes:
        found: a robot came within eps of the source before T_max.
        found_time_s: time of detection [s] (NaN if not found).
        finder: index of the robot that found it (-1 if none).
        tau: relative completion time, Eq. 12 (NaN if not found).
        decisions: per robot, its decisions in order.
        trajectories: per robot, (k, 2) positions at the start, waypoints and the end [m].
        planners: the Bayes-Swarm planners (empty for baselines), for plots.
        end_time_s: simulated time when the run stopped [s].
    """

    found: bool
    found_time_s: float
    finder: int
    tau: float
    decisions: list[list[Decision]]
    trajectories: list[np.ndarray]
    planners: list[BayesSwarmPlanner] = field(default_factory=list)
    end_time_s: float = 0.0

    def decision_times_s(self, robot: int | None = None) -> np.ndarray:
        """Wall-clock decision times of ``robot`` (default: the finder, else all robots)."""
        if robot is None:
            robot = self.finder
        lists = self.decisions if robot < 0 else [self.decisions[robot]]
        return np.array([d.compute_time_s for ds in lists for d in ds])


def depot_fan(
    depots_m: np.ndarray, offsets_deg: tuple[float, ...], n_robots: int, robot: int
) -> tuple[np.ndarray, int, int, float]:
    """Depot (2,), first-decision fan index (1-based), fan size and heading offset of a robot:
    robot i starts at depot i mod d, and the robots of one depot share its fan."""
    n_depots = depots_m.shape[0]
    depot = robot % n_depots
    fan_size = len(range(depot, n_robots, n_depots))
    fan_index = robot // n_depots + 1
    return depots_m[depot], fan_index, fan_size, offsets_deg[depot % len(offsets_deg)]


def robot_start_and_fan(
    spec: MissionSpec, n_robots: int, robot: int
) -> tuple[np.ndarray, int, int, float]:
    """Start (2,), first-decision fan index (1-based), fan size and heading offset of a robot."""
    depot, fan_index, fan_size, offset = depot_fan(
        spec.depots_m, spec.depot_direction_offsets_deg, n_robots, robot
    )
    return depot.astype(float), fan_index, fan_size, offset


def _world(spec: MissionSpec, n_robots: int, rng: np.random.Generator) -> PointRobotField:
    starts = np.array([robot_start_and_fan(spec, n_robots, i)[0] for i in range(n_robots)])
    return PointRobotField(
        starts,
        spec.field,
        spec.source_m,
        spec.planner.detection_radius_m,
        rng,
        noise_std=spec.noise_std,
        relative_noise=spec.relative_noise,
    )


def _tau(spec: MissionSpec, world: PointRobotField) -> float:
    """Relative completion time (Eq. 12) of the finder, NaN if none."""
    if world.finder < 0:
        return math.nan
    ideal = float(np.hypot(*(spec.source_m - world.starts[world.finder])))
    ideal /= spec.planner.velocity_mps
    return (world.found_time_s - ideal) / ideal


def run_mission(
    spec: MissionSpec, algorithm: str, n_robots: int, seed: int, *, keep_planners: bool = False
) -> MissionResult:
    """Simulate one mission of ``n_robots`` running ``algorithm`` (one of ALGORITHMS)."""
    if algorithm not in ALGORITHMS:
        msg = f'unknown algorithm {algorithm!r}; choose one of {", ".join(ALGORITHMS)}'
        raise ConfigError(msg)
    if n_robots < 1:
        msg = f'n_robots must be >= 1, got {n_robots}'
        raise ConfigError(msg)
    plan = FaultPlan(spec.faults, n_robots, seed) if spec.faults.active else None
    seeds = np.random.SeedSequence(seed).spawn(n_robots + 1)
    world_rng = np.random.default_rng(seeds[0])
    world = _world(spec, n_robots, world_rng)
    if algorithm == 'glowworm':
        if plan is not None:
            msg = 'faults are not simulated for glowworm (a synchronous swarm iteration)'
            raise ConfigError(msg)
        return _run_glowworm(spec, world, n_robots, seeds)
    agents = _make_agents(spec, algorithm, n_robots, seeds, world)
    return _run_events(spec, world, agents, keep_planners, plan)


# --------------------------------------------------------------------------- agents
class _Agent(ABC):
    """What the event loop needs from a robot's decision maker."""

    planner: BayesSwarmPlanner | None = None

    def observe(self, point: np.ndarray, value: float) -> None:
        return None

    @abstractmethod
    def decide(self, position: np.ndarray, time_s: float) -> Decision:
        """Next waypoint on arrival at ``position``."""

    def broadcast(self, position: np.ndarray) -> PeerUpdate | None:
        return None

    def receive(self, update: PeerUpdate) -> None:
        return None


class _BayesAgent(_Agent):
    def __init__(self, planner: BayesSwarmPlanner) -> None:
        self.planner = planner

    def observe(self, point: np.ndarray, value: float) -> None:
        self.planner.add_observations(point.reshape(1, 2), np.array([value]))

    def decide(self, position: np.ndarray, time_s: float) -> Decision:
        return self.planner.decide(position, time_s)

    def broadcast(self, position: np.ndarray) -> PeerUpdate | None:
        return self.planner.broadcast(position)

    def receive(self, update: PeerUpdate) -> None:
        self.planner.receive(update)


class _LevyAgent(_Agent):
    def __init__(self, walk: LevyWalk) -> None:
        self._walk = walk
        self._k = 0
        self._last_signal: float | None = None

    def observe(self, point: np.ndarray, value: float) -> None:
        self._last_signal = value

    def decide(self, position: np.ndarray, time_s: float) -> Decision:
        waypoint = self._walk.next_waypoint(position, self._last_signal)
        self._k += 1
        return Decision(waypoint, self._k - 1, DecisionKind.RANDOM_JUMP)


class _SweepAgent(_Agent):
    def __init__(self, waypoints: np.ndarray) -> None:
        self._waypoints = waypoints
        self._k = 0

    def decide(self, position: np.ndarray, time_s: float) -> Decision:
        index = min(self._k, self._waypoints.shape[0] - 1)
        self._k += 1
        return Decision(self._waypoints[index].copy(), self._k - 1, DecisionKind.ACQUISITION)


def _make_agents(
    spec: MissionSpec,
    algorithm: str,
    n_robots: int,
    seeds: list[np.random.SeedSequence],
    world: PointRobotField,
) -> list[_Agent]:
    if algorithm == 'levy':
        return [
            _LevyAgent(LevyWalk(spec.levy, spec.arena, seed=seeds[i + 1])) for i in range(n_robots)
        ]
    if algorithm == 'exhaustive':
        spacing = spec.exhaustive.spacing_m(spec.planner.detection_radius_m)
        paths = sweep_paths(spec.arena, world.starts, spacing, spec.exhaustive.partition)
        return [_SweepAgent(p) for p in paths]
    agents: list[_Agent] = []
    for i in range(n_robots):
        _, fan_index, fan_size, offset = robot_start_and_fan(spec, n_robots, i)
        cfg = replace(
            spec.planner,
            robot_index=i,
            n_robots=n_robots,
            penalty_enabled=algorithm == 'bayes_swarm_p' and spec.planner.penalty_enabled,
        )
        planner = BayesSwarmPlanner(
            cfg,
            f'r{i}',
            seed=seeds[i + 1],
            fan_index=fan_index,
            fan_size=fan_size,
            direction_offset_deg=offset,
        )
        agents.append(_BayesAgent(planner))
    return agents


# ----------------------------------------------------------------------- event loop
def _deliver(
    spec: MissionSpec,
    world: PointRobotField,
    agents: list[_Agent],
    sender: int,
    update: PeerUpdate,
    links: tuple[float | None, float, np.ndarray | None] | None = None,
) -> None:
    """Deliver ``sender``'s update; ``links``: range [m] (None: unlimited), loss and the
    dropped robots that receive nothing, when faults change them."""
    comm_range_m, loss, dropped = links or (spec.comm_range_m, spec.loss_probability, None)
    for j, agent in enumerate(agents):
        if j == sender or (dropped is not None and dropped[j]):
            continue
        if comm_range_m is not None:
            gap = world.positions[j] - world.positions[sender]
            if np.hypot(*gap) > comm_range_m:
                continue
        if loss > 0.0 and world.rng.uniform() < loss:
            continue
        agent.receive(update)


def _run_events(
    spec: MissionSpec,
    world: PointRobotField,
    agents: list[_Agent],
    keep_planners: bool,
    plan: FaultPlan | None = None,
) -> MissionResult:
    cfg = spec.planner
    n = len(agents)
    period = 1.0 / cfg.observation_rate_hz
    speed = cfg.velocity_mps
    t_max = cfg.max_mission_time_s
    decisions: list[list[Decision]] = [[] for _ in range(n)]
    waypoints = world.positions.copy()
    tick = 0
    t = 0.0
    # Faults: the dropout instant is an event; dropped robots stop, sample, decide and talk
    # no more; faulty sensors read what the plan says.
    dropout_s = math.inf if plan is None else plan.config.dropout_time_s
    dropped = np.zeros(n, dtype=bool)
    held: dict[int, float] = {}

    def links() -> tuple[float | None, float, np.ndarray | None] | None:
        if plan is None:
            return None
        comm_range_m = plan.combined_range_m(spec.comm_range_m)
        return comm_range_m, plan.combined_loss(spec.loss_probability), dropped

    def sample_all() -> None:
        values = world.sample(world.positions)
        for i, (agent, p, v) in enumerate(zip(agents, world.positions, values, strict=True)):
            if plan is None:
                agent.observe(p, float(v))
            elif not dropped[i]:
                agent.observe(p, plan.signal(i, float(v), t, held))

    def drop_out() -> None:
        nonlocal dropped
        assert plan is not None
        dropped = plan.dropped(t).copy()
        waypoints[dropped] = world.positions[dropped]

    def decide(i: int) -> None:
        decision = agents[i].decide(world.positions[i].copy(), t)
        decisions[i].append(decision)
        waypoints[i] = decision.waypoint_m
        world.trajectories[i].append(world.positions[i].copy())
        update = agents[i].broadcast(world.positions[i].copy())
        if update is not None:
            _deliver(spec, world, agents, i, update, links())

    if dropout_s <= 0.0:
        drop_out()
    sample_all()
    if world.move(waypoints, 0.0, 0.0, speed):
        pass
    else:
        for i in range(n):
            if not dropped[i]:
                decide(i)
    while world.finder < 0 and t < t_max - _TIME_EPS:
        remaining = np.hypot(*(waypoints - world.positions).T)
        arrivals = t + remaining / speed
        next_tick = (tick + 1) * period
        moving = remaining > 1e-12
        t_next = min(next_tick, float(np.min(arrivals[moving])) if np.any(moving) else math.inf)
        t_next = min(t_next, t_max)
        if t < dropout_s - _TIME_EPS:
            t_next = min(t_next, dropout_s)
        if world.move(waypoints, t, t_next, speed):
            t = world.found_time_s
            break
        t = t_next
        if plan is not None and abs(t - dropout_s) <= _TIME_EPS:
            drop_out()
        if abs(t - next_tick) <= _TIME_EPS:
            tick += 1
            sample_all()
        arrived = np.flatnonzero(np.hypot(*(waypoints - world.positions).T) <= 1e-9)
        for i in arrived:
            if not dropped[i]:
                decide(int(i))
    for i in range(n):
        world.trajectories[i].append(world.positions[i].copy())
    planners = [a.planner for a in agents if a.planner is not None] if keep_planners else []
    return MissionResult(
        found=world.finder >= 0,
        found_time_s=world.found_time_s,
        finder=world.finder,
        tau=_tau(spec, world),
        decisions=decisions,
        trajectories=[np.array(tr) for tr in world.trajectories],
        planners=planners,
        end_time_s=t,
    )


def _run_glowworm(
    spec: MissionSpec, world: PointRobotField, n_robots: int, seeds: list[np.random.SeedSequence]
) -> MissionResult:
    cfg = spec.planner
    speed = cfg.velocity_mps
    decisions: list[list[Decision]] = [[] for _ in range(n_robots)]
    targets = np.empty((n_robots, 2))
    for i in range(n_robots):
        start, fan_index, fan_size, offset = robot_start_and_fan(spec, n_robots, i)
        targets[i] = cfg.arena.clip(
            first_waypoint(
                start,
                fan_index=fan_index,
                fan_size=fan_size,
                direction_range_deg=cfg.initial_direction_range_deg,
                direction_offset_deg=offset,
                leg_m=cfg.max_leg_m,
            )
        )
        decisions[i].append(Decision(targets[i].copy(), 0, DecisionKind.FIRST))
    t_disperse = float(np.max(np.hypot(*(targets - world.starts).T))) / speed
    t = min(t_disperse, cfg.max_mission_time_s)
    if not world.move(targets, 0.0, t, speed):
        for i in range(n_robots):
            world.trajectories[i].append(world.positions[i].copy())
        swarm = GlowwormSwarm(spec.glowworm, cfg.arena, world.positions, speed, seed=seeds[1])
        period = swarm.period_s
        k = 0
        while t < cfg.max_mission_time_s - _TIME_EPS:
            new_positions = swarm.step(world.sample(world.positions))
            k += 1
            t_next = t_disperse + k * period
            if world.move(new_positions.copy(), t, t_next, speed):
                t = world.found_time_s
                break
            world.positions = new_positions.copy()
            t = t_next
    for i in range(n_robots):
        world.trajectories[i].append(world.positions[i].copy())
    return MissionResult(
        found=world.finder >= 0,
        found_time_s=world.found_time_s,
        finder=world.finder,
        tau=_tau(spec, world),
        decisions=decisions,
        trajectories=[np.array(tr) for tr in world.trajectories],
        end_time_s=t,
    )
