"""MSC + PF missions without the runtime: the path of studies and benchmarks.

The ROS path (:func:`swarm_experiments.spawn_msc_pf.run`) runs the sim bridge with the RSSI
extension and the peer relay, and one :class:`msc_pf.node.MscPfNode` per robot on the
built-in runtime. This module drives the same parts directly, and only steps the world:

* the :class:`swarm_sim.engine.SimEngine` of point robots (unicycle bases, odometry at the
  physics rate), the :class:`swarm_sim.rssi_targets.RssiTargetField` (work, captures, one
  RSSI sample per robot and detectable target every second) and the
  :class:`swarm_sim.peer_relay.RelayModel` (range, loss), seeded as the bridge seeds them;
* per robot the node's own loop, :class:`msc_pf.loop.RobotLoop` (sample and hold,
  staleness, timing, steering around :class:`msc_pf.robot.RobotController`).

Per physics step it reproduces what the bridge and the executor do: the engine steps; every
robot receives its odometry pose (through the message's quaternion), its capture notices and,
when due, its RSSI samples (float32 as in ``RssiArray`` when the runtime round-trips CDR);
then the nodes' timers run robot by robot in creation order: the control step, whose
broadcast the relay hands at once to the robots in range (so robot j's step sees the
broadcasts robots i < j sent in this period), then the drive command. Seeded runs therefore
equal the ROS path's: capture times and positions (tested for all three schemes, with
swarms and a lossy relay).

A run ends when every target is captured (the capture completion time, CCT) or at
``max_time_s``; a scenario without targets searches until ``max_time_s``
(:func:`search_coverage` times that search). It records no bags and publishes no state.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from msc_pf.errors import ConfigError
from msc_pf.loop import RobotLoop, Steering
from msc_pf.peers import PeerInfo
from msc_pf.robot import RobotController, StepOutput
from msc_pf.schemes import Scheme
from msc_pf.settings import MscPfConfig
from swarm_common.angles import yaw_from_unit_quaternion, yaw_to_quaternion
from swarm_common.stamps import ns_to_sec_nanosec, seconds_to_ns
from swarm_runtime.builtin._messages import cdr_roundtrip_enabled
from swarm_sim.engine import SimEngine, SiteGeometry
from swarm_sim.faults import BODY_SENSOR_FAULTS, FaultConfig, FaultPlan
from swarm_sim.peer_relay import RelayConfig, RelayModel
from swarm_sim.rssi_targets import RssiTargetConfig, RssiTargetField, place_robots

from swarm_experiments.open_field import point_robot_engine_config

__all__ = ['BatchResult', 'BatchScenario', 'SearchCoverage', 'run_batch', 'search_coverage']


@dataclass(frozen=True)
class BatchScenario:
    """One run.

    Attributes:
        scheme: msc, msc_pf or proposed.
        n_robots: number of robots (spec 0.2 default 15).
        n_targets: number of targets; 0 runs the search alone until ``max_time_s``.
        seed: seeds target placement, robot placement, noise and every controller.
        max_time_s: stop here if not every target is captured [s].
        start_radius_m: robots start uniformly in this disc at the field centre [m].
        comm_loss: probability that one peer message is lost.
        controller: controller configuration (its scheme is replaced by ``scheme``).
        target_positions_m: (n_targets, 2) fixed target positions; None places them randomly.
        steering: the node's steering settings (odom_timeout_s, yaw-rate limit, gain).
        physics_rate_hz: the bridge's physics (and odometry) rate [Hz].
        drive_rate_hz: the node's drive_rate_hz [Hz].
        max_linear_speed_m_s: the simulated base's speed limit [m/s].
        faults: faults injected on purpose (:mod:`swarm_sim.faults`): robot dropouts (a
            dropped robot stands still, hears, works and talks no more) and a shorter or
            lossier peer link.
    """

    scheme: Scheme = Scheme.PROPOSED
    n_robots: int = 15
    n_targets: int = 10
    seed: int = 0
    max_time_s: float = 30000.0
    start_radius_m: float = 30.0
    comm_loss: float = 0.0
    controller: MscPfConfig = field(default_factory=MscPfConfig)
    target_positions_m: np.ndarray | None = None
    steering: Steering = field(default_factory=Steering)
    physics_rate_hz: float = 10.0
    drive_rate_hz: float = 10.0
    max_linear_speed_m_s: float = 1.05
    faults: FaultConfig = field(default_factory=FaultConfig)


@dataclass
class BatchResult:
    """Outcome of one run.

    Attributes:
        cct_s: capture completion time [s]; NaN when not every target was captured.
        capture_times_s: (n_targets,) capture time of each target [s] (NaN if not captured).
        first_heard_s: (n_targets,) first time some robot heard each target, i.e. took a
            sample above the detection threshold [s] (NaN if nobody did). The CCT is the
            last of these plus what the approaches after it took.
        first_heard_range_m: (n_targets,) distance to each target of the nearest robot that
            heard it at that first time [m] (NaN if nobody did): the straight-line length of
            the approach that started there.
        target_positions_m: (n_targets, 2) target positions [m].
        duration_s: simulated time [s].
        wall_time_s: wall-clock time of the run [s].
        paths_m: (steps + 1, n_robots, 2) robot positions when recorded, else None.
        phases: (steps, n_robots) phase of each robot when recorded, else None.
    """

    cct_s: float
    capture_times_s: np.ndarray
    first_heard_s: np.ndarray
    first_heard_range_m: np.ndarray
    target_positions_m: np.ndarray
    duration_s: float
    wall_time_s: float
    paths_m: np.ndarray | None = None
    phases: np.ndarray | None = None


def _message_seconds(time_s: float) -> float:
    """A time as a receiver reads it from a message stamp (rounded to the nanosecond)."""
    sec, nanosec = ns_to_sec_nanosec(seconds_to_ns(time_s))
    return float(sec) + 1e-9 * float(nanosec)


def _as_received(info: PeerInfo) -> PeerInfo:
    """A broadcast as a receiver's node decodes it (``msc_pf.conversions.peer_from_ros``)."""
    movement = info.movement if all(math.isfinite(v) for v in info.movement) else (0.0, 0.0)
    return replace(info, stamp_s=_message_seconds(info.stamp_s), movement=movement)


def _nearest_hearer_m(
    positions: np.ndarray, target_positions: np.ndarray, samples: np.ndarray
) -> np.ndarray:
    """Per target (columns of ``samples``), the distance of the nearest robot that heard it."""
    diff = positions[:, None, :] - target_positions[None, :, :]
    distance = np.hypot(diff[..., 0], diff[..., 1])
    return np.where(np.isnan(samples), np.inf, distance).min(axis=0)


def scenario_start(
    n_targets: int,
    seed: int,
    *,
    field_size_m: float,
    start_radius_m: float,
    n_robots: int,
    target_positions_m: np.ndarray | None = None,
    task_area_m: float = 5.0,
) -> tuple[RssiTargetField, np.ndarray]:
    """Targets and (n_robots, 3) start poses of a seeded run, as the spawner draws them."""
    rng = np.random.default_rng([seed, 0])
    config = RssiTargetConfig(
        n_targets=n_targets, field_size_m=field_size_m, task_area_m=task_area_m
    )
    if target_positions_m is None:
        targets = RssiTargetField.random(config, rng)
    else:
        targets = RssiTargetField(config, target_positions_m)
    centre = (field_size_m / 2.0, field_size_m / 2.0)
    xy = place_robots(n_robots, centre, start_radius_m, rng)
    yaw = rng.uniform(-math.pi, math.pi, n_robots)
    return targets, np.column_stack([xy, yaw])


def run_batch(
    scenario: BatchScenario,
    *,
    record: bool = False,
    on_step: Callable[[float, np.ndarray, list[StepOutput]], bool | None] | None = None,
    float32_fields: bool | None = None,
) -> BatchResult:
    """Simulate ``scenario`` and return its CCT and per-target capture times.

    Args:
        scenario: the run.
        record: keep every robot position and phase, once per control period (for plots).
        on_step: called after every control period with (time, positions, controller
            outputs); a true return ends the run there.
        float32_fields: round the RSSI samples to float32 as ``RssiArray`` serialization
            does; None follows the built-in runtime's CDR round-trip setting, so the run
            equals the ROS path's in the same process.
    """
    unsupported = scenario.faults.configured(
        (*BODY_SENSOR_FAULTS, 'stuck_gas_robots', 'drifting_gas_robots', 'gas_drift_per_s')
    )
    if unsupported:
        msg = f'faults {", ".join(unsupported)} are not simulated by this runner (no such sensor)'
        raise ConfigError(msg)
    start_wall = time.perf_counter()
    config = replace(scenario.controller, scheme=Scheme(scenario.scheme))
    if float32_fields is None:
        float32_fields = cdr_roundtrip_enabled()
    targets, poses = scenario_start(
        scenario.n_targets,
        scenario.seed,
        field_size_m=config.field_size_m,
        start_radius_m=scenario.start_radius_m,
        n_robots=scenario.n_robots,
        target_positions_m=scenario.target_positions_m,
        task_area_m=config.phases.task_area_m,
    )
    engine = SimEngine(
        SiteGeometry(
            walls=np.zeros((0, 2, 2)),
            room_rects=(np.array([[0.0, 0.0, config.field_size_m, config.field_size_m]]),),
            name='msc_pf field',
        ),
        poses,
        point_robot_engine_config(
            physics_rate_hz=scenario.physics_rate_hz,
            seed=scenario.seed,
            max_linear_speed_mps=scenario.max_linear_speed_m_s,
        ),
    )
    noise_rng = np.random.default_rng([scenario.seed, 1])
    plan = (
        FaultPlan(scenario.faults, scenario.n_robots, scenario.seed)
        if scenario.faults.active
        else None
    )
    relay = RelayModel.for_mission(
        RelayConfig(
            msg_type='swarm_interfaces/msg/MscPeer',
            comm_range_m=config.swarm.comm_range_m,
            loss_probability=scenario.comm_loss,
        ),
        scenario.seed,
        plan,
    )
    steering = scenario.steering
    loops = [
        RobotLoop(RobotController(i, config, scenario.seed), steering)
        for i in range(scenario.n_robots)
    ]
    n = len(loops)
    robot_indices = list(range(n))
    control_every = max(1, round(config.period_s * scenario.physics_rate_hz))
    drive_every = max(1, round(scenario.physics_rate_hz / scenario.drive_rate_hz))
    sample_every = max(1, round(scenario.physics_rate_hz))  # the extension samples at 1 Hz
    paths = [poses[:, :2].copy()] if record else None
    phases: list[list[int]] | None = [] if record else None
    first_heard = np.full(scenario.n_targets, np.nan)
    first_heard_range = np.full(scenario.n_targets, np.nan)
    last: list[StepOutput | None] = [None] * n
    now = 0.0
    all_captured = False  # only a capture can change it (a search-only run never ends so)
    while not all_captured and now + 1e-9 < scenario.max_time_s:
        # The bridge's tick: physics, odometry, work and captures, RSSI samples.
        out = engine.step()
        step = engine.step_index
        now_ns = seconds_to_ns(out.time_s)
        now = now_ns * 1e-9  # the nodes' clock: the /clock stamp
        # Faults: a dropped robot's node is dead (no pose, samples, ticks or messages), its
        # base stands still and it works on no target.
        dropped = plan.dropped(out.time_s) if plan is not None else None
        if dropped is not None and not dropped.any():
            dropped = None
        if out.odometry is not None:
            for i, (loop, pose) in enumerate(zip(loops, out.odometry[0].tolist(), strict=True)):
                if dropped is not None and dropped[i]:
                    continue
                _, _, qz, qw = yaw_to_quaternion(pose[2])
                loop.receive_pose(
                    (pose[0], pose[1], yaw_from_unit_quaternion(0.0, 0.0, qz, qw)), now
                )
        positions = out.poses[:, :2]
        speeds = np.abs(engine.world.velocities[:, 0])
        if dropped is not None:
            speeds[dropped] = np.inf  # a dropped robot works on no target
        captures = targets.work(positions, speeds, engine.config.physics_period_s, out.time_s)
        for capture in captures:
            for robot in capture.robot_indices:
                loops[robot].receive_captured([capture.target_id])
        if captures:
            all_captured = targets.all_captured
        if step % sample_every == 0:
            samples = targets.sample_rssi(positions, noise_rng)
            if float32_fields:
                samples = samples.astype(np.float32).astype(np.float64)
            if dropped is not None:
                samples[dropped] = np.nan  # a dropped robot hears nothing
            stamp = _message_seconds(out.time_s)
            for i, (loop, row) in enumerate(zip(loops, samples.tolist(), strict=True)):
                if dropped is not None and dropped[i]:
                    continue
                loop.receive_rssi(stamp, {t: v for t, v in enumerate(row) if v == v})
            heard_now = ~np.isnan(samples).all(axis=0)
            first_time = heard_now & np.isnan(first_heard)
            if first_time.any():
                first_heard[first_time] = now
                first_heard_range[first_time] = _nearest_hearer_m(
                    positions, targets.positions_m[first_time], samples[:, first_time]
                )
        # The nodes' timers, in creation order: robot by robot its control step (whose
        # broadcast the relay hands on at once), then its drive command.
        control_due = step % control_every == 0
        drive_due = control_due or step % drive_every == 0
        if not drive_due:
            continue
        commands: list[tuple[float, float]] = []
        for i, loop in enumerate(loops):
            if dropped is not None and dropped[i]:
                commands.append((0.0, 0.0))
                continue
            if control_due:
                result = loop.control(now, with_estimates=False)
                if result.output is not None:
                    last[i] = result.output
                    message = _as_received(result.output.broadcast)
                    for receiver in relay.receivers(i, engine.world.poses).tolist():
                        if dropped is None or not dropped[receiver]:
                            loops[receiver].receive_peer(message)
            commands.append(loop.command(now))
        # Commands act at the next physics step, so recording them after the loop is the same.
        engine.set_velocity_commands(robot_indices, commands)
        if control_due:
            outputs = [o for o in last if o is not None]
            if paths is not None and phases is not None:
                paths.append(engine.world.poses[:, :2].copy())
                phases.append([int(o.status.phase) if o else 0 for o in last])
            if on_step is not None and on_step(now, engine.world.poses[:, :2], outputs):
                break

    captured = targets.capture_time_s
    cct = float(np.max(captured)) if targets.all_captured and captured.size else math.nan
    return BatchResult(
        cct_s=cct,
        capture_times_s=captured.copy(),
        first_heard_s=first_heard,
        first_heard_range_m=first_heard_range,
        target_positions_m=targets.positions_m.copy(),
        duration_s=engine.step_index / scenario.physics_rate_hz,
        wall_time_s=time.perf_counter() - start_wall,
        paths_m=np.array(paths) if paths is not None else None,
        phases=np.array(phases) if phases is not None else None,
    )


@dataclass(frozen=True)
class SearchCoverage:
    """How fast the eq. (1) search alone brings the field within earshot of a robot.

    Attributes:
        fractions: the coverage fractions asked for, ascending.
        times_s: first check time [s] at which each fraction of the field was within the
            detection range of some robot's path; NaN if not reached by the end.
        duration_s: simulated time [s].
    """

    fractions: tuple[float, ...]
    times_s: tuple[float, ...]
    duration_s: float


def search_coverage(
    n_robots: int,
    seed: int,
    *,
    max_time_s: float,
    controller: MscPfConfig | None = None,
    fractions: tuple[float, ...] = (0.5, 0.9, 0.99, 1.0),
    check_period_s: float = 10.0,
    cell_size_m: float = 20.0,
) -> SearchCoverage:
    """Run the search with no targets and time how fast it covers the field.

    A cell of ``cell_size_m`` counts as covered once its centre has been within the radio
    model's detection range (about 292 m) of some robot, checked every ``check_period_s``.
    It is a :func:`run_batch` run without targets (the same seed gives the same starts);
    without targets every scheme only searches, so the scheme does not matter. The run
    stops when the last fraction is reached or at ``max_time_s``.
    """
    ascending = all(a < b for a, b in itertools.pairwise(fractions))
    if not fractions or not ascending or not all(0.0 < f <= 1.0 for f in fractions):
        msg = f'fractions must ascend within (0, 1], got {fractions!r}'
        raise ValueError(msg)
    config = controller if controller is not None else MscPfConfig()
    centres = (np.arange(math.ceil(config.field_size_m / cell_size_m)) + 0.5) * cell_size_m
    cell_x, cell_y = np.meshgrid(centres, centres)
    covered = np.zeros(cell_x.shape, dtype=bool)
    reach_sq = config.radio.detection_range_m**2
    times = [math.nan] * len(fractions)
    steps_per_check = max(1, round(check_period_s / config.period_s))
    steps = itertools.count(1)

    def track(now_s: float, positions: np.ndarray, _outputs: list[StepOutput]) -> bool:
        if next(steps) % steps_per_check:
            return False
        for x, y in positions:
            np.logical_or(covered, (cell_x - x) ** 2 + (cell_y - y) ** 2 < reach_sq, out=covered)
        share = float(covered.mean())
        for i, fraction in enumerate(fractions):
            if math.isnan(times[i]) and share >= fraction:
                times[i] = now_s
        return not math.isnan(times[-1])

    scenario = BatchScenario(
        n_robots=n_robots, n_targets=0, seed=seed, max_time_s=max_time_s, controller=config
    )
    result = run_batch(scenario, on_step=track)
    return SearchCoverage(tuple(fractions), tuple(times), result.duration_s)
