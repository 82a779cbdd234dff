"""Fast ROS-free simulator of the MSC + PF mission for benchmarks (spec 0.2).

It runs the very controllers the ROS node runs (:class:`msc_pf.robot.RobotController`) on
the world model of :mod:`swarm_sim.rssi_targets`, with the paper's discrete setting:

* time advances in steps of Delta t = 1 s; each step every robot takes one RSSI sample per
  detectable target, receives the peer messages its neighbours sent in the previous step
  (senders within the communication range, optional random loss), and moves by the
  displacement its controller returns, clipped to the field;
* robots standing still within D_th of a target work on it; the robots working on a target
  when it is captured learn its ID, and the others learn it from their peers;
* the run ends when every target is captured (the capture completion time, CCT) or at
  ``max_time_s``; a scenario without targets searches until ``max_time_s``
  (:func:`search_coverage` times that search).

Positions are holonomic, as in the paper's simulation; the ROS path drives the bridge's
robots through cmd_vel instead, which is what the agreement test checks.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from msc_pf.peers import PeerInfo
from msc_pf.robot import RobotController, StepOutput
from msc_pf.schemes import Scheme
from msc_pf.settings import MscPfConfig
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.rssi_targets import RssiTargetConfig, RssiTargetField, place_robots

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


def _deliver(
    outputs: list[StepOutput],
    positions: np.ndarray,
    comm_range_m: float,
    loss: float,
    rng: np.random.Generator,
    dropped: np.ndarray | None = None,
) -> list[list[PeerInfo]]:
    """Peer messages each robot receives: senders within range, minus random losses
    (``dropped`` robots neither send nor receive)."""
    n = len(outputs)
    diff = positions[:, None, :] - positions[None, :, :]
    in_range = np.hypot(diff[..., 0], diff[..., 1]) <= comm_range_m
    if loss > 0.0:
        in_range &= rng.random((n, n)) >= loss
    np.fill_diagonal(in_range, False)
    if dropped is not None and dropped.any():
        in_range[dropped, :] = False
        in_range[:, dropped] = False
    messages = [out.broadcast for out in outputs]
    return [
        [m for m, heard in zip(messages, row, strict=True) if heard] for row in in_range.tolist()
    ]


def _nearest_hearer_m(
    positions: np.ndarray, target_positions: np.ndarray, samples: np.ndarray
) -> np.ndarray:
    """Per target (columns of ``samples``), the distance of the nearest robot that heard it."""
    diff = positions[:, None, :] - target_positions[None, :, :]
    distance = np.hypot(diff[..., 0], diff[..., 1])
    return np.where(np.isnan(samples), np.inf, distance).min(axis=0)


def run_batch(
    scenario: BatchScenario,
    *,
    record: bool = False,
    on_step: Callable[[float, np.ndarray, list[StepOutput]], bool | None] | None = None,
) -> BatchResult:
    """Simulate ``scenario`` and return its CCT and per-target capture times.

    Args:
        scenario: the run.
        record: keep every robot position and phase (for plots).
        on_step: called after every step with (time, positions, controller outputs); a
            true return ends the run there.
    """
    start_wall = time.perf_counter()
    config = replace(scenario.controller, scheme=Scheme(scenario.scheme))
    world_rng = np.random.default_rng([scenario.seed, 0])
    target_config = RssiTargetConfig(
        n_targets=scenario.n_targets,
        field_size_m=config.field_size_m,
        task_area_m=config.phases.task_area_m,
    )
    if scenario.target_positions_m is None:
        targets = RssiTargetField.random(target_config, world_rng)
    else:
        targets = RssiTargetField(target_config, scenario.target_positions_m)
    center = (config.field_size_m / 2.0, config.field_size_m / 2.0)
    positions = place_robots(scenario.n_robots, center, scenario.start_radius_m, world_rng)
    controllers = [RobotController(i, config, scenario.seed) for i in range(scenario.n_robots)]
    plan = (
        FaultPlan(scenario.faults, scenario.n_robots, scenario.seed)
        if scenario.faults.active
        else None
    )
    comm_range_m, comm_loss = config.swarm.comm_range_m, scenario.comm_loss
    if plan is not None:
        comm_range_m = min(comm_range_m, plan.comm_range_m)
        comm_loss = plan.combined_loss(comm_loss)
    dropped = None
    dt = config.period_s
    inbox: list[list[PeerInfo]] = [[] for _ in controllers]
    notices: list[list[int]] = [[] for _ in controllers]
    paths = [positions.copy()] if record else None
    phases: list[list[int]] | None = [] if record else None

    now = 0.0
    first_heard = np.full(scenario.n_targets, np.nan)
    first_heard_range = np.full(scenario.n_targets, np.nan)
    search_only = scenario.n_targets == 0
    while (search_only or not targets.all_captured) and now < scenario.max_time_s:
        now += dt
        if plan is not None:
            dropped = plan.dropped(now)
        samples = targets.sample_rssi(positions, world_rng)
        if dropped is not None and dropped.any():
            samples[dropped] = np.nan  # a dropped robot hears nothing
        heard_now = ~np.isnan(samples).all(axis=0)
        first_time = heard_now & np.isnan(first_heard)
        if first_time.any():
            first_heard[first_time] = now
            first_heard_range[first_time] = _nearest_hearer_m(
                positions, targets.positions_m[first_time], samples[:, first_time]
            )
        outputs = []
        for i, (controller, row) in enumerate(zip(controllers, samples.tolist(), strict=True)):
            heard = {t: value for t, value in enumerate(row) if value == value}  # not NaN
            outputs.append(
                controller.step(
                    now, positions[i], heard, inbox[i], notices[i], with_estimates=False
                )
            )
        broadcast_positions = positions.copy()
        steps = np.array([out.displacement_m for out in outputs])
        if dropped is not None and dropped.any():
            steps[dropped] = 0.0
        positions = np.clip(positions + steps, 0.0, config.field_size_m)
        speeds = np.hypot(steps[:, 0], steps[:, 1]) / dt
        if dropped is not None and dropped.any():
            speeds[dropped] = np.inf  # a dropped robot works on no target
        notices = [[] for _ in controllers]
        for capture in targets.work(positions, speeds, dt, now):
            for robot in capture.robot_indices:
                notices[robot].append(capture.target_id)
        inbox = _deliver(outputs, broadcast_positions, comm_range_m, comm_loss, world_rng, dropped)
        if paths is not None and phases is not None:
            paths.append(positions.copy())
            phases.append([int(out.status.phase) for out in outputs])
        if on_step is not None and on_step(now, positions, outputs):
            break

    captured = targets.capture_time_s
    cct = float(np.max(captured)) if targets.all_captured and captured.size else math.nan
    return BatchResult(
        cct_s=cct,
        capture_times_s=captured.copy(),
        first_heard_s=first_heard,
        first_heard_range_m=first_heard_range,
        target_positions_m=targets.positions_m.copy(),
        duration_s=now,
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
