"""Batch runner of Bayes-Swarm missions and their baselines, without the runtime.

Only the world lives here. The robots are the ROS node's own per-robot loop,
:class:`bayes_swarm.controller.RobotController` (sample and hold, staleness, decision timing,
the planner), with the settings a spawned node gets. The world is the paper's motion model
(:class:`swarm_sim.point_robots.PointRobotField`): robots fly straight legs at V, every robot
gets its pose and a sample at every tick of the observation clock (t = k / f_Hz), a robot that
reaches its waypoint gets a control tick, which decides (so decisions are asynchronous), and
its :class:`~bayes_swarm.messages.PeerUpdate` is delivered at once to every robot within
``comm_range_m`` unless dropped with probability ``loss_probability`` (the sim bridge's
:class:`~swarm_sim.peer_relay.RelayModel`, seeded as the bridge seeds it). Detection is
continuous: a mission succeeds at the first instant any robot comes within eps of the source
along its straight leg. Glowworm robots take a sample and iterate at every tick of their
decision clock (the observation clock runs at that rate for them, as the spawner sets it),
in lockstep as GSO is defined: every robot broadcasts its new luciferin, then every robot
picks its leader from this iteration's broadcasts (the two halves of the node's iteration).

Decisions take no simulated time; their wall-clock duration is recorded per robot.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Literal, Protocol

import numpy as np
from bayes_swarm.controller import ControlOutput, GlowwormBroadcast, RobotController, robot_seed
from bayes_swarm.errors import ConfigError
from bayes_swarm.messages import Decision, PeerUpdate
from bayes_swarm.node_settings import NodeSettings
from bayes_swarm.planner import BayesSwarmPlanner
from bayes_swarm.settings import (
    Arena,
    BayesSwarmConfig,
    ExhaustiveConfig,
    GlowwormConfig,
    LevyConfig,
)
from swarm_sim.faults import BODY_SENSOR_FAULTS, FaultConfig, FaultPlan
from swarm_sim.peer_relay import RelayConfig, RelayModel
from swarm_sim.point_robots import FieldFunction, PointRobotField

__all__ = [
    'ALGORITHMS',
    'ControllerLink',
    'MissionResult',
    'MissionSpec',
    'RobotLink',
    'depot_fan',
    'robot_settings',
    'robot_start_and_fan',
    'ros_time_s',
    'run_events',
    'run_mission',
    'with_glowworm_clock',
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
        stop_time_s: when the world stops the run [s] (None: the planners' T_max, which is
            also what their alpha schedule uses).
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
    stop_time_s: float | None = None
    glowworm: GlowwormConfig = field(default_factory=GlowwormConfig)
    levy: LevyConfig = field(default_factory=LevyConfig)
    exhaustive: ExhaustiveConfig = field(default_factory=ExhaustiveConfig)
    faults: FaultConfig = field(default_factory=FaultConfig)

    def __post_init__(self) -> None:
        if self.noise_std < 0.0 or self.relative_noise < 0.0:
            msg = 'noise_std and relative_noise must be >= 0'
            raise ConfigError(msg)
        if self.comm_range_m is not None and not self.comm_range_m > 0.0:
            msg = f'comm_range_m must be > 0 or None, got {self.comm_range_m}'
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
        trajectories: per robot, (k, 2) positions at the start, waypoints and the end [m]
            (Glowworm: the start, the first waypoint, the end of the dispersal leg and the end).
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
    """Simulate one mission of ``n_robots`` running ``algorithm`` (one of ALGORITHMS).

    Every robot is a :class:`~bayes_swarm.controller.RobotController` with the settings a
    spawned node gets (:func:`robot_settings`).
    """
    if algorithm not in ALGORITHMS:
        msg = f'unknown algorithm {algorithm!r}; choose one of {", ".join(ALGORITHMS)}'
        raise ConfigError(msg)
    if n_robots < 1:
        msg = f'n_robots must be >= 1, got {n_robots}'
        raise ConfigError(msg)
    unsupported = spec.faults.configured(BODY_SENSOR_FAULTS)
    if unsupported:
        msg = f'faults {", ".join(unsupported)} are not simulated by this runner (no such sensor)'
        raise ConfigError(msg)
    glowworm = algorithm == 'glowworm'
    if glowworm:
        spec = with_glowworm_clock(spec)
    controllers = [
        RobotController(robot_settings(spec, algorithm, n_robots, i, seed), f'r{i}')
        for i in range(n_robots)
    ]
    links = [ControllerLink(c) for c in controllers]
    result = run_events(spec, n_robots, seed, links, glowworm=glowworm)
    if keep_planners:
        result.planners = [c.planner for c in controllers if c.planner is not None]
    return result


def with_glowworm_clock(spec: MissionSpec) -> MissionSpec:
    """``spec`` with the observation clock at the Glowworm decision rate: Glowworm robots
    sample, and iterate, at that rate (the spawner's rule too)."""
    rate_hz = spec.glowworm.decision_rate_hz
    return replace(spec, planner=replace(spec.planner, observation_rate_hz=rate_hz))


# --------------------------------------------------------------------------- robots
class RobotLink(Protocol):
    """How the world loop talks to one robot: the calls of a RobotController.

    The batch runner links :class:`~bayes_swarm.controller.RobotController` objects directly
    (:class:`ControllerLink`); a test links ROS nodes through their messages instead, to show
    that both paths take the same decisions.
    """

    def pose(self, position_m: np.ndarray, yaw_rad: float, time_s: float) -> None:
        """The robot's pose at ``time_s``."""

    def signal(self, value: float, time_s: float) -> None:
        """One field sample at the latest pose."""

    def peer(self, update: PeerUpdate, time_s: float) -> None:
        """A peer's broadcast."""

    def control(self, time_s: float) -> ControlOutput:
        """One control tick."""

    def glowworm_broadcast(self, time_s: float) -> GlowwormBroadcast | None:
        """The first half of a Glowworm iteration: the robot's broadcast (None: it does not
        iterate, e.g. still dispersing)."""

    def glowworm_move(self, time_s: float) -> np.ndarray | None:
        """The second half: the robot's new waypoint (2,) [m] (None without a broadcast)."""

    def glowworm_peer(self, sender: str, broadcast: GlowwormBroadcast, time_s: float) -> None:
        """A peer's Glowworm broadcast."""


class ControllerLink:
    """A RobotController driven directly."""

    def __init__(self, controller: RobotController) -> None:
        self.controller = controller

    def pose(self, position_m: np.ndarray, yaw_rad: float, time_s: float) -> None:
        self.controller.on_pose((float(position_m[0]), float(position_m[1]), yaw_rad), time_s)

    def signal(self, value: float, time_s: float) -> None:
        self.controller.on_signal(value)

    def peer(self, update: PeerUpdate, time_s: float) -> None:
        self.controller.on_peer(update)

    def control(self, time_s: float) -> ControlOutput:
        return self.controller.control(time_s)

    def glowworm_broadcast(self, time_s: float) -> GlowwormBroadcast | None:
        return self.controller.glowworm_broadcast()

    def glowworm_move(self, time_s: float) -> np.ndarray | None:
        return self.controller.glowworm_move()

    def glowworm_peer(self, sender: str, broadcast: GlowwormBroadcast, time_s: float) -> None:
        self.controller.on_glowworm_peer(
            sender, broadcast.index, broadcast.position_m, broadcast.luciferin
        )


def robot_settings(
    spec: MissionSpec, algorithm: str, n_robots: int, robot: int, seed: int
) -> NodeSettings:
    """The node settings of robot ``robot`` (0-based) in a mission seeded ``seed``.

    The same values the spawner gives its nodes: the spec's planner with this robot's index,
    the swarm size, its depot's fan and :func:`~bayes_swarm.controller.robot_seed`.
    """
    _, fan_index, fan_size, offset = robot_start_and_fan(spec, n_robots, robot)
    planner = replace(spec.planner, robot_index=robot, n_robots=n_robots)
    return NodeSettings(
        algorithm=algorithm,
        seed=robot_seed(seed, robot),
        planner=planner,
        initial_direction_offset_deg=offset,
        fan_index=fan_index,
        fan_size=fan_size,
        levy=spec.levy,
        glowworm=spec.glowworm,
        exhaustive=spec.exhaustive,
    )


def ros_time_s(time_s: float) -> float:
    """``time_s`` rounded to whole nanoseconds, as a ROS clock carries it."""
    return round(time_s * 1e9) * 1e-9


# ----------------------------------------------------------------------- event loop
def _deliver(
    relay: RelayModel,
    world: PointRobotField,
    robots: Sequence[RobotLink],
    sender: int,
    update: PeerUpdate | GlowwormBroadcast,
    time_s: float,
    dropped: np.ndarray,
) -> None:
    """Deliver ``sender``'s update to the receivers ``relay`` picks (range and loss, the
    bridge's relay model), except the ``dropped`` robots, which receive nothing. Robot i is
    named ``r{i}`` (:func:`run_mission`'s names)."""
    name = f'r{sender}'
    for j in relay.receivers(sender, world.positions).tolist():
        if dropped[j]:
            continue
        if isinstance(update, PeerUpdate):
            robots[j].peer(update, time_s)
        else:
            robots[j].glowworm_peer(name, update, time_s)


def run_events(
    spec: MissionSpec,
    n_robots: int,
    seed: int,
    robots: Sequence[RobotLink],
    *,
    glowworm: bool = False,
) -> MissionResult:
    """World stepping of one mission with the given robots (see :func:`run_mission`).

    Events: the observation clock (every robot gets its pose and a sample), and arrivals
    (the arrived robot gets its pose and a control tick, which decides; its broadcast is
    delivered at once). With ``glowworm``, every observation tick is also a Glowworm
    iteration of the swarm after the samples, in lockstep: every robot broadcasts (delivered
    at once), then every robot that broadcast moves. Times passed to the robots are rounded
    to nanoseconds.
    """
    seeds = np.random.SeedSequence(seed).spawn(n_robots + 1)
    world = _world(spec, n_robots, np.random.default_rng(seeds[0]))
    cfg = spec.planner
    n = len(robots)
    period = 1.0 / cfg.observation_rate_hz
    speed = cfg.velocity_mps
    t_max = cfg.max_mission_time_s if spec.stop_time_s is None else spec.stop_time_s
    decisions: list[list[Decision]] = [[] for _ in range(n)]
    waypoints = world.positions.copy()
    yaws = np.zeros(n)
    tick = 0
    t = 0.0
    plan = FaultPlan(spec.faults, n_robots, seed) if spec.faults.active else None
    # The peer link as the sim bridge relays it: the same model on the same random stream,
    # so a batch run and a spawned one drop the same deliveries.
    relay = RelayModel.for_mission(
        RelayConfig(
            comm_range_m=math.inf if spec.comm_range_m is None else spec.comm_range_m,
            loss_probability=spec.loss_probability,
        ),
        seed,
        plan,
    )
    # Faults: the dropout instant is an event; dropped robots stop, sample, decide and talk
    # no more; faulty sensors read what the plan says.
    dropout_s = math.inf if plan is None else plan.config.dropout_time_s
    dropped = np.zeros(n, dtype=bool)
    held: dict[int, float] = {}

    def sample_all() -> None:
        values = world.sample(world.positions)
        stamp = ros_time_s(t)
        for i, robot in enumerate(robots):
            if dropped[i]:
                continue
            value = float(values[i])
            if plan is not None:
                value = plan.signal(i, value, t, held)
            robot.pose(world.positions[i].copy(), float(yaws[i]), stamp)
            robot.signal(value, stamp)

    def drop_out() -> None:
        nonlocal dropped
        assert plan is not None
        dropped = plan.dropped(t).copy()
        waypoints[dropped] = world.positions[dropped]

    def iterate_glowworm() -> None:
        # Lockstep, as GSO is defined: every robot broadcasts its new luciferin, then every
        # robot picks its leader from the broadcasts of this iteration.
        stamp = ros_time_s(t)
        moving: list[int] = []
        for i, robot in enumerate(robots):
            if dropped[i]:
                continue
            broadcast = robot.glowworm_broadcast(stamp)
            if broadcast is None:
                continue
            moving.append(i)
            if broadcast.index == 1:  # the end of the dispersal leg
                world.trajectories[i].append(world.positions[i].copy())
            _deliver(relay, world, robots, i, broadcast, stamp, dropped)
        for i in moving:
            waypoint = robots[i].glowworm_move(stamp)
            if waypoint is None:
                continue
            position = world.positions[i]
            waypoints[i] = waypoint
            dx, dy = float(waypoint[0] - position[0]), float(waypoint[1] - position[1])
            if dx != 0.0 or dy != 0.0:
                yaws[i] = math.atan2(dy, dx)

    def tick_robot(i: int) -> None:
        stamp = ros_time_s(t)
        robots[i].pose(world.positions[i].copy(), float(yaws[i]), stamp)
        out = robots[i].control(stamp)
        if out.decision is None:
            return
        decisions[i].append(out.decision)
        waypoints[i] = out.decision.waypoint_m
        leg = waypoints[i] - world.positions[i]
        if np.hypot(*leg) > 0.0:
            yaws[i] = math.atan2(leg[1], leg[0])
        world.trajectories[i].append(world.positions[i].copy())
        if out.broadcast is not None:
            _deliver(relay, world, robots, i, out.broadcast, stamp, dropped)

    if dropout_s <= 0.0:
        drop_out()
    sample_all()
    if not world.move(waypoints, 0.0, 0.0, speed):
        for i in range(n):
            if not dropped[i]:
                tick_robot(i)
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
            if glowworm:
                iterate_glowworm()
        arrived = np.flatnonzero(np.hypot(*(waypoints - world.positions).T) <= 1e-9)
        for i in arrived:
            if not dropped[i]:
                tick_robot(int(i))
    for i in range(n):
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
