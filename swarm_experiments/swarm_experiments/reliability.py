"""Reliability studies: each algorithm under injected faults, OA-Bug under both sensor profiles.

Registered with ``swarm_study`` (entry point ``swarm_experiments.studies``):

* ``faults-oabug``: OA-Bug Gas+Sound on Small sites (10 robots, both departures), one row per
  fault scenario: room coverage, and whether the survivors kept working (the longest time a
  working robot stood still) and the robots with a dead lidar stopped;
* ``faults-bayes``: Bayes-Swarm-P, case 1, on the batch runner: tau and the detection rate;
* ``faults-msc``: MSC + PF, the proposed scheme (15 robots, 10 targets): the capture
  completion time (CCT) and the share of runs that capture every target;
* ``faults-crash``: one robot's node process killed mid-run, and killed and restarted, for
  each algorithm, on real rclpy with one process per node (``--processes``): the mission's
  metric, and whether the crashed robot stopped, moved again after the restart and how long
  the restart took. These runs are in real time, so unlike the other studies they are not
  deterministic (the machine's load is recorded with each run);
* ``sensors-oabug``: every OA-Bug variant on Small sites from both departures, with the
  ``paper`` and the ``tuned`` robot profile, under the ``ideal`` and the ``realistic`` sensor
  profile.

A fault scenario is one string of ``--fault`` items (``'dropout_robots=2'``,
``'comm_loss_probability=0.5,comm_range_m=150'``; ``'none'``): the study's ``fault`` axis.
The fault onset is a fixed parameter (``fault_time_s``: dropouts and sensor faults both start
then). Everything is deterministic from the seed (for OA-Bug, the site index).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from swarm_sim.engine import EngineConfig
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.sensor_profiles import apply_sensor_profile

from swarm_experiments.cli_args import fault_config
from swarm_experiments.study import ReportPage, RunSpec, Smoke, Study, paired_differences
from swarm_experiments.study.checks import (
    check_choice,
    check_number,
    check_whole,
    settings_error,
)
from swarm_experiments.study.errors import UsageError

__all__ = [
    'check_bayes_fault',
    'check_msc_fault',
    'check_oabug_fault',
    'check_oabug_sensors',
    'parse_fault',
    'run_bayes_fault',
    'run_msc_fault',
    'run_oabug_fault',
    'run_oabug_sensors',
    'still_time_s',
    'studies',
]

OABUG_FAULTS = (
    'none',
    'dropout_robots=2',
    'dropout_robots=5',
    'dropout_robots=8',
    'stale_lidar_robots=1',
    'stale_lidar_robots=2',
    'stale_lidar_robots=4',
    'stuck_gas_robots=3',
    'drifting_gas_robots=3;gas_drift_per_s=0.5',
    'drifting_gas_robots=3;gas_drift_per_s=2',
    'drifting_gas_robots=3;gas_drift_per_s=8',
    'imu_drift_robots=3;imu_drift_radps=0.00175',  # 0.1 deg/s
    'imu_drift_robots=3;imu_drift_radps=0.00873',  # 0.5 deg/s
    'imu_drift_robots=3;imu_drift_radps=0.0349',  # 2 deg/s
    'bearing_dropout_probability=0.3',
    'bearing_dropout_probability=0.6',
    'bearing_dropout_probability=0.9',
)
BAYES_FAULTS = (
    'none',
    'dropout_robots=1',
    'dropout_robots=2',
    'dropout_robots=4',
    'comm_loss_probability=0.3',
    'comm_loss_probability=0.6',
    'comm_loss_probability=0.9',
    'comm_loss_probability=1',
    'comm_range_m=1',
    'comm_range_m=0.5',
    'comm_range_m=0.25',
    'stuck_gas_robots=1',
    'stuck_gas_robots=2',
    'drifting_gas_robots=1;gas_drift_per_s=0.002',
    'drifting_gas_robots=1;gas_drift_per_s=0.01',
    'drifting_gas_robots=1;gas_drift_per_s=0.05',
)
MSC_FAULTS = (
    'none',
    'dropout_robots=3',
    'dropout_robots=7',
    'comm_loss_probability=0.5',
    'comm_loss_probability=0.9',
    'comm_range_m=150',
    'comm_range_m=75',
)
# A robot that stood still longer than this while it should work counts as stuck [s].
STUCK_LIMIT_S = 20.0
# Two robots whose centres are this close touch, or nearly (bodies of 0.1 m radius) [m].
CONTACT_M = 0.25


def parse_fault(scenario: str, onset_s: float) -> FaultConfig:
    """The faults of a scenario string (``--fault`` items joined by ``;`` or ``,``, or
    ``'none'``), with dropouts and sensor faults starting at ``onset_s``. The studies' own
    scenarios use ``;``, so that ``--set fault=A,B`` can pick several of them."""
    parts = scenario.replace(';', ',').split(',')
    items = [] if scenario == 'none' else [i.strip() for i in parts if i.strip()]
    items += [f'dropout_time_s={onset_s}', f'sensor_time_s={onset_s}']
    return fault_config(items)


def _check_fault(config: Mapping[str, Any], robots: int) -> FaultConfig:
    """The run's faults once ``fault_time_s`` and the ``fault`` scenario are checked (for a
    swarm of ``robots``)."""
    from swarm_common.errors import SwarmError

    check_number(config, 'fault_time_s', minimum=0.0)
    scenario = config['fault']
    if not isinstance(scenario, str):
        raise UsageError(f"fault={scenario!r}: must be --fault items (or 'none')")
    try:
        faults = parse_fault(scenario, float(config['fault_time_s']))
        FaultPlan(faults, robots, 0)
    except (SwarmError, ValueError) as err:
        raise settings_error(err, f'fault={scenario!r}') from err
    return faults


def _check_oabug(config: Mapping[str, Any]) -> None:
    """The OA-Bug run's settings as the Fig. 4 study (and the spawner) checks them."""
    from swarm_experiments.oabug_study import _fixed_parameters
    from swarm_experiments.oabug_study import check_config as check_oabug

    check_whole(config, 'robots', minimum=1)
    keys = ('site', 'variant', 'robots', 'departure', 'profile')
    check_oabug({**_fixed_parameters(), **{key: config[key] for key in keys}})


def check_oabug_fault(config: Mapping[str, Any]) -> None:
    """Check one ``faults-oabug`` configuration before anything runs.

    Raises:
        UsageError: an OA-Bug setting the spawner rejects, a negative onset, a fault
            scenario that does not parse or asks for more robots than the swarm has.
    """
    _check_oabug(config)
    _check_fault(config, int(config['robots']))


def check_oabug_sensors(config: Mapping[str, Any]) -> None:
    """Check one ``sensors-oabug`` configuration before anything runs.

    Raises:
        UsageError: an OA-Bug setting the spawner rejects, an unknown sensor profile.
    """
    from swarm_sim.sensor_profiles import SENSOR_PROFILES

    check_choice(config, 'sensors', SENSOR_PROFILES)
    _check_oabug(config)


def check_bayes_fault(config: Mapping[str, Any]) -> None:
    """Check one ``faults-bayes`` configuration as the spawner and the batch runner would.

    Raises:
        UsageError: an unknown case, algorithm or profile, a value out of range, a fault
            scenario that does not parse or that the batch runner does not simulate.
    """
    from bayes_swarm.profiles import PROFILES
    from swarm_common.errors import SwarmError
    from swarm_sim.faults import BODY_SENSOR_FAULTS
    from swarm_sim.signal_fields import get_case

    from swarm_experiments.bayes_batch import ALGORITHMS
    from swarm_experiments.spawn_bayes_swarm import MAX_ROBOTS, SpawnSettings, check_settings

    check_choice(config, 'algorithm', ALGORITHMS)
    check_choice(config, 'profile', tuple(PROFILES))
    check_whole(config, 'robots', minimum=0)
    check_number(config, 'noise_std', minimum=0.0)
    check_number(config, 'stop_time_s', minimum=0.0, above=True, allow_none=True)
    try:
        case = get_case(str(config['case']))
        check_settings(
            SpawnSettings(
                algorithm=str(config['algorithm']),
                case=str(config['case']),
                robots=min(int(config['robots']) or case.default_robots, MAX_ROBOTS),
                noise_std=float(config['noise_std']),
                profile=str(config['profile']),
            )
        )
    except SwarmError as err:
        raise settings_error(err) from err
    faults = _check_fault(config, int(config['robots']) or case.default_robots)
    # What bayes_batch.run_mission refuses.
    unsupported = faults.configured(BODY_SENSOR_FAULTS)
    if unsupported:
        raise UsageError(
            f'fault={config["fault"]!r}: {", ".join(unsupported)} not simulated by the batch '
            'runner (no such sensor)'
        )


def check_msc_fault(config: Mapping[str, Any]) -> None:
    """Check one ``faults-msc`` configuration as the spawner checks its settings.

    Raises:
        UsageError: an unknown scheme, a count or time out of range, a fault scenario that
            does not parse or asks for more robots than the swarm has.
    """
    from swarm_common.errors import SwarmError

    from swarm_experiments.spawn_msc_pf import (
        MAX_ROBOTS,
        SCHEMES,
        SpawnSettings,
        check_settings,
    )

    check_choice(config, 'scheme', SCHEMES)
    check_whole(config, 'robots', minimum=1)
    check_whole(config, 'targets', minimum=1)
    check_number(config, 'max_time_s', minimum=0.0, above=True)
    try:
        check_settings(
            SpawnSettings(
                scheme=str(config['scheme']),
                robots=min(int(config['robots']), MAX_ROBOTS),
                targets=int(config['targets']),
                max_time_s=float(config['max_time_s']),
            )
        )
    except SwarmError as err:
        raise settings_error(err) from err
    _check_fault(config, int(config['robots']))


def still_spell(
    times_s: np.ndarray, positions_m: np.ndarray, *, tolerance_m: float = 0.05
) -> tuple[float, float, float]:
    """The longest interval over which a robot's (T, 2) sampled positions stayed within
    ``tolerance_m`` of where the interval began: (duration, start, end) [s]; a robot that
    never stood still gives (0, 0, 0)."""
    longest = (0.0, 0.0, 0.0)
    anchor = 0
    for k in range(1, len(times_s)):
        if np.hypot(*(positions_m[k] - positions_m[anchor])) > tolerance_m:
            anchor = k
        else:
            duration = float(times_s[k] - times_s[anchor])
            if duration > longest[0]:
                longest = (duration, float(times_s[anchor]), float(times_s[k]))
    return longest


def still_time_s(
    times_s: np.ndarray, positions_m: np.ndarray, *, tolerance_m: float = 0.05
) -> float:
    """The longest interval [s] over which a robot's (T, 2) sampled positions stayed within
    ``tolerance_m`` of where the interval began (0 for a robot that never stood still)."""
    return still_spell(times_s, positions_m, tolerance_m=tolerance_m)[0]


def stuck_causes(
    times_s: np.ndarray, positions_m: np.ndarray, working: np.ndarray, stopped_from_s: float
) -> dict[str, int]:
    """The working robots (``working``: (N,) bool) that stood still longer than
    :data:`STUCK_LIMIT_S`, by what touched them meanwhile (``positions_m``: (T, N, 2)):
    ``stuck_by_stopped``: a robot that no longer worked (one of ``~working``, from
    ``stopped_from_s`` on); ``stuck_by_peer``: only working robots; ``stuck_alone``: no robot
    within :data:`CONTACT_M` (walls only)."""
    causes = {'stuck_by_stopped': 0, 'stuck_by_peer': 0, 'stuck_alone': 0}
    for i in np.flatnonzero(working):
        duration, start, end = still_spell(times_s, positions_m[:, i])
        if duration <= STUCK_LIMIT_S:
            continue
        during = (times_s >= start) & (times_s <= end)
        gaps = np.hypot(*np.moveaxis(positions_m[during] - positions_m[during, i][:, None], -1, 0))
        touching = gaps <= CONTACT_M  # (T', N)
        touching[:, i] = False
        stopped = touching[times_s[during] >= stopped_from_s][:, ~working]
        if stopped.any():
            causes['stuck_by_stopped'] += 1
        elif touching.any():
            causes['stuck_by_peer'] += 1
        else:
            causes['stuck_alone'] += 1
    return causes


def _oabug(
    spec: RunSpec, engine: EngineConfig, variant: str, departure: str, profile: str = 'tuned'
) -> Any:
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings

    cfg = spec.config
    settings = SpawnSettings(
        site=cfg['site'],
        site_seed=spec.seed,
        seed=spec.seed,
        variant=variant,
        robots=int(cfg['robots']),
        departure=departure,
        engine=engine,
        profile=profile,
    )
    return run_spawn_batch(settings).mission


def run_oabug_fault(spec: RunSpec) -> dict[str, Any]:
    """One OA-Bug run of the ``faults-oabug`` study."""
    cfg = spec.config
    onset = float(cfg['fault_time_s'])
    faults = parse_fault(cfg['fault'], onset)
    engine = EngineConfig(faults=faults)
    mission = _oabug(spec, engine, cfg['variant'], cfg['departure'], cfg['profile'])
    n = len(mission.robot_names)
    plan = FaultPlan(faults, n, spec.seed)
    # The robots expected to keep driving: all but the dropped and the lidar-less ones.
    idle = plan.mask('dropout') | plan.mask('stale_lidar')
    times = mission.trajectory_times_s
    positions = mission.trajectories[:, :, :2]
    still = [still_time_s(times, positions[:, i]) for i in range(n) if not idle[i]]
    # A lidar-less robot must stop within the stale timeout (0.5 s) plus a control period.
    late = times >= onset + 2.0
    stopped_moves = [
        float(np.hypot(*np.diff(positions[late, i], axis=0).T).sum())
        for i in np.flatnonzero(plan.mask('stale_lidar'))
    ]
    return {
        'coverage': 100.0 * mission.coverage,
        'complete': bool(mission.rooms_covered == mission.rooms_total),
        'sim_time_s': float(mission.sim_time_s),
        'survivors': int(n - plan.mask('dropout').sum()),
        'max_still_s': max(still, default=0.0),
        'stuck_survivors': int(sum(s > STUCK_LIMIT_S for s in still)),
        **stuck_causes(times, positions, ~idle, onset),
        'faulty_moved_m': max(stopped_moves, default=0.0),
    }


def run_oabug_sensors(spec: RunSpec) -> dict[str, Any]:
    """One OA-Bug run of the ``sensors-oabug`` study: the robot ``profile`` (paper, tuned)
    under the sensor profile ``sensors`` (ideal, realistic)."""
    cfg = spec.config
    engine = apply_sensor_profile(EngineConfig(), cfg['sensors'])
    mission = _oabug(spec, engine, cfg['variant'], cfg['departure'], cfg['profile'])
    return {
        'coverage': 100.0 * mission.coverage,
        'complete': bool(mission.rooms_covered == mission.rooms_total),
        'sim_time_s': float(mission.sim_time_s),
    }


def decisions_after_s(waypoints_m: np.ndarray, speed_mps: float, time_s: float) -> int:
    """How many of a Bayes-Swarm robot's legs started at or after ``time_s``: the robot flies
    its (k, 2) path (start, waypoints, end) at ``speed_mps`` without stopping, and every
    waypoint but the end was a decision."""
    legs = np.hypot(*np.diff(waypoints_m, axis=0).T)
    starts_s = np.concatenate(([0.0], np.cumsum(legs)))[:-1] / speed_mps
    return int(np.count_nonzero(starts_s >= time_s - 1e-9))


def run_bayes_fault(spec: RunSpec) -> dict[str, Any]:
    """One Bayes-Swarm run of the ``faults-bayes`` study."""
    from swarm_sim.signal_fields import get_case

    from swarm_experiments.bayes_batch import run_mission
    from swarm_experiments.spawn_bayes_swarm import batch_mission_spec

    cfg = spec.config
    case = get_case(cfg['case'])
    onset = float(cfg['fault_time_s'])
    mission = batch_mission_spec(
        case, noise_std=float(cfg['noise_std']), profile=str(cfg['profile'])
    )
    stop = cfg.get('stop_time_s')
    mission = dataclasses.replace(
        mission,
        faults=parse_fault(cfg['fault'], onset),
        stop_time_s=None if stop is None else float(stop),
    )
    robots = int(cfg['robots']) or case.default_robots
    result = run_mission(mission, cfg['algorithm'], robots, spec.seed)
    plan = FaultPlan(mission.faults, robots, spec.seed)
    survivors = np.flatnonzero(~plan.mask('dropout'))
    speed = mission.planner.velocity_mps
    # The survivors go on deciding (on new samples) after the fault: the fewest decisions
    # one of them took after the onset, among the runs that lasted a while after it.
    after = [decisions_after_s(result.trajectories[i], speed, onset) for i in survivors]
    # Where the swarm believed the source was at the end: the median of the survivors' last
    # GP-mean maxima; how far from the source, and from the nearest robot whose signal
    # sensor failed (where a misleading sensor pulls the belief).
    beliefs = [
        d.expected_source_m
        for i in survivors
        for d in result.decisions[i][-1:]
        if d.expected_source_m is not None
    ]
    belief = np.median(beliefs, axis=0) if beliefs else np.full(2, np.nan)
    faulty = np.flatnonzero(plan.mask('stuck_gas') | plan.mask('drifting_gas'))
    ends = np.array([result.trajectories[i][-1] for i in faulty]).reshape(-1, 2)
    return {
        'found': bool(result.found),
        'tau': float(result.tau) if result.found else math.nan,
        'end_time_s': float(result.end_time_s),
        'survivor_decisions_after_fault': (
            min(after) if after and result.end_time_s >= onset + 10.0 else math.nan
        ),
        'belief_error_m': float(np.hypot(*(belief - mission.source_m))),
        'belief_to_faulty_sensor_m': (
            float(np.hypot(*(ends - belief).T).min()) if len(ends) else math.nan
        ),
    }


def run_msc_fault(spec: RunSpec) -> dict[str, Any]:
    """One MSC + PF run of the ``faults-msc`` study."""
    from swarm_experiments.msc_pf_batch import BatchScenario, run_batch

    cfg = spec.config
    onset = float(cfg['fault_time_s'])
    scenario = BatchScenario(
        scheme=cfg['scheme'],
        n_robots=int(cfg['robots']),
        n_targets=int(cfg['targets']),
        seed=spec.seed,
        max_time_s=float(cfg['max_time_s']),
        faults=parse_fault(cfg['fault'], onset),
    )
    result = run_batch(scenario, record=True)
    captured = np.isfinite(result.capture_times_s)
    row = {
        'cct_s': float(result.cct_s),
        'all_captured': bool(captured.all()),
        'captured': int(captured.sum()),
        'duration_s': float(result.duration_s),
        'survivor_min_moved_m': math.nan,
        'survivor_max_still_s': math.nan,
    }
    # The survivors keep searching after the fault: the least one of them drove after the
    # onset, and the longest time one of them stood (within 1 m of a spot) after it.
    paths = result.paths_m
    assert paths is not None
    times = np.arange(len(paths), dtype=float) * (result.duration_s / max(len(paths) - 1, 1))
    after = times >= onset
    if np.count_nonzero(after) > 1:
        plan = FaultPlan(scenario.faults, scenario.n_robots, spec.seed)
        survivors = np.flatnonzero(~plan.mask('dropout'))
        late = paths[after]
        row['survivor_min_moved_m'] = min(
            float(np.hypot(*np.diff(late[:, i], axis=0).T).sum()) for i in survivors
        )
        row['survivor_max_still_s'] = max(
            still_time_s(times[after], late[:, i], tolerance_m=1.0) for i in survivors
        )
    return row


@dataclasses.dataclass(frozen=True)
class CrashMission:
    """The mission of one algorithm in the ``faults-crash`` study.

    Attributes:
        spawner: the spawner's console script.
        argv: its options (the seed options are added per run).
        seed_options: the options that take the run's seed.
        time_scale: the bridge's real-time factor.
        crash_s: when robot ``CRASH_ROBOT``'s node is killed [s sim].
        restart_after_s: how much later it is started again [s sim].
    """

    spawner: str
    argv: tuple[str, ...]
    seed_options: tuple[str, ...]
    time_scale: float
    crash_s: float
    restart_after_s: float


#: The crashed robot (r1: never the bridge's first robot, never the last).
CRASH_ROBOT = 1
#: Per algorithm, a small swarm and a short mission: real-time runs on a shared machine.
CRASH_MISSIONS = {
    'oabug': CrashMission(
        'spawn',
        ('--robots', '4', '--actions', '300', '--profile', 'paper'),
        ('--seed', '--site-seed'),
        2.0,
        30.0,
        10.0,
    ),
    'bayes_swarm': CrashMission(
        'spawn_bayes_swarm', ('--robots', '3'), ('--seed',), 1.0, 10.0, 5.0
    ),
    'msc_pf': CrashMission(
        'spawn_msc_pf',
        (
            '--robots',
            '4',
            '--targets',
            '2',
            '--target-positions',
            '1000,1060;1060,1000',
            '--t-max',
            '250',
        ),
        ('--seed',),
        2.0,
        40.0,
        20.0,
    ),
}
CRASH_SCENARIOS = ('none', 'crash', 'restart')
# A robot counts as moving again once it is this far from where it stood [m].
_MOVED_M = 0.05


def crash_item(mission: CrashMission, scenario: str) -> list[str]:
    """The ``--fault`` options of a scenario: none, a crash, or a crash and a restart."""
    if scenario == 'none':
        return []
    item = f'crash:r{CRASH_ROBOT}@{mission.crash_s:g}'
    if scenario == 'restart':
        item += f'+{mission.restart_after_s:g}'
    return ['--fault', item]


def path_length_m(
    times_s: np.ndarray, positions_m: np.ndarray, start_s: float, end_s: float
) -> float:
    """Length [m] of the (T, 2) sampled path between ``start_s`` and ``end_s``."""
    inside = (times_s >= start_s - 1e-9) & (times_s <= end_s + 1e-9)
    if np.count_nonzero(inside) < 2:
        return 0.0
    return float(np.hypot(*np.diff(positions_m[inside], axis=0).T).sum())


def first_move_s(times_s: np.ndarray, positions_m: np.ndarray, after_s: float) -> float:
    """The first sample time from ``after_s`` on at which the robot is more than 5 cm from
    where it stood at ``after_s`` (NaN: it never moved again)."""
    inside = np.flatnonzero(times_s >= after_s - 1e-9)
    if inside.size == 0:
        return math.nan
    start = positions_m[inside[0]]
    away = np.hypot(*(positions_m[inside] - start).T) > _MOVED_M
    return float(times_s[inside[np.argmax(away)]]) if away.any() else math.nan


def crash_metrics(
    mission: CrashMission, scenario: str, outcome: Mapping[str, Any]
) -> dict[str, Any]:
    """The ``faults-crash`` row of one run from its bridge outcome (``outcome.json``)."""
    times = np.asarray(outcome['trajectory_times_s'], dtype=float)
    n = len(outcome['robot_names'])
    paths = np.asarray(outcome['trajectories'], dtype=float).reshape(len(times), n, 3)[..., :2]
    end_s = float(outcome['sim_time_s'])
    row: dict[str, Any] = {'sim_time_s': end_s, 'stop_reason': str(outcome['stop_reason'])}
    extension = (outcome.get('extensions') or [{}])[0]
    if extension.get('kind') == 'signal':
        row['found'] = bool(extension['found'])
        row['tau'] = math.nan if extension['tau'] is None else float(extension['tau'])
    elif extension.get('kind') == 'rssi':
        captured = [t for t in extension['capture_times_s'] if t is not None]
        row['captured'] = len(captured)
        row['all_captured'] = bool(extension['all_captured'])
        row['cct_s'] = max(captured) if row['all_captured'] else math.nan
    else:
        entries = outcome['room_entries']
        row['coverage'] = 100.0 * len({int(e[0]) for e in entries}) / int(outcome['rooms_total'])
    crashed = paths[:, CRASH_ROBOT]
    others = [i for i in range(n) if i != CRASH_ROBOT]
    nan = math.nan
    row.update(down_moved_m=nan, restart_delay_s=nan, restart_moved_m=nan, others_moved_m=nan)
    if scenario == 'none' or end_s < mission.crash_s:
        return row
    # Down from the kill plus the bridge's cmd_vel timeout, up at the restart (or the end).
    restart_s = mission.crash_s + mission.restart_after_s if scenario == 'restart' else end_s
    down_end_s = min(restart_s, end_s)
    row['down_moved_m'] = path_length_m(times, crashed, mission.crash_s + 1.0, down_end_s)
    row['others_moved_m'] = min(
        path_length_m(times, paths[:, i], mission.crash_s, down_end_s) for i in others
    )
    if scenario == 'restart' and restart_s < end_s:
        moving_s = first_move_s(times, crashed, restart_s)
        row['restart_delay_s'] = moving_s - restart_s
        row['restart_moved_m'] = path_length_m(times, crashed, restart_s, end_s)
    return row


def run_crash(spec: RunSpec) -> dict[str, Any]:
    """One ``faults-crash`` run: the spawner with ``--processes`` in a DDS domain of its own
    (kept on this machine), the crash fault of the scenario, metrics from its outcome."""
    import json
    import os
    import resource
    import signal
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    from swarm_runtime.dds_isolation import reserve_test_domain

    cfg = spec.config
    mission = CRASH_MISSIONS[cfg['algorithm']]
    seed = [str(v) for option in mission.seed_options for v in (option, spec.seed)]
    reservation = reserve_test_domain(int(cfg['domain_id']))
    env = dict(
        os.environ,
        ROS_DOMAIN_ID=str(reservation.domain_id),
        ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
    )
    children_cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()[0]
    wall_start = time.perf_counter()
    try:
        with tempfile.TemporaryDirectory(prefix='faults-crash-') as directory:
            run_dir = Path(directory)
            argv = [
                str(Path(sys.executable).parent / mission.spawner),
                *mission.argv,
                *seed,
                '--processes',
                '--run-dir',
                str(run_dir),
                '--time-scale',
                f'{mission.time_scale:g}',
                '--no-plots',
                '--quiet',
                *crash_item(mission, cfg['scenario']),
            ]
            done = subprocess.run(argv, capture_output=True, text=True, env=env, check=False)
            if done.returncode in (130, -signal.SIGINT):  # Ctrl-C reached the spawner too
                raise KeyboardInterrupt
            if done.returncode not in (0, 1):
                lines = done.stderr.strip().splitlines()
                msg = f'{mission.spawner} exited {done.returncode}: {lines[-1] if lines else ""}'
                raise RuntimeError(msg)
            outcome = json.loads((run_dir / 'outcome.json').read_text())
            if outcome['stop_reason'] == 'interrupted':  # a node failed: not a crash fault
                lines = done.stderr.strip().splitlines()
                raise RuntimeError(lines[-1] if lines else f'{mission.spawner} was interrupted')
    finally:
        reservation.release()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = crash_metrics(mission, cfg['scenario'], outcome)
    row['processes_cpu_s'] = (after.ru_utime + after.ru_stime) - (
        children_cpu.ru_utime + children_cpu.ru_stime
    )
    row['wall_s'] = time.perf_counter() - wall_start
    row['load'] = 0.5 * (load + os.getloadavg()[0])
    return row


def check_crash(config: Mapping[str, Any]) -> None:
    """The ``faults-crash`` runs need real rclpy (``--processes``)."""
    import importlib.util

    from swarm_experiments.study.errors import UsageError

    if importlib.util.find_spec('rclpy') is None:
        raise UsageError('faults-crash runs the nodes with --processes: it needs real rclpy')
    if config['algorithm'] not in CRASH_MISSIONS or config['scenario'] not in CRASH_SCENARIOS:
        raise UsageError(f'faults-crash: unknown algorithm or scenario in {dict(config)}')


def _planned(
    page: ReportPage,
    order: Sequence[str],
    by: Sequence[str] = ('config.fault',),
    per: str | None = None,
) -> pd.DataFrame:
    """The rows a table averages: of the fault scenarios the study declares now (``order``;
    rows of older scenarios stay stored but are left out; every row when empty), on the
    seeds that every configuration (``by``) has run, within each value of ``per``. So every
    row of a table averages the same seeds (sites), and a call that ran some scenarios on
    more seeds than the others adds nothing to those alone."""
    rows = page.rows
    if rows.empty:
        return rows
    if order and 'config.fault' in rows.columns:
        rows = rows[rows['config.fault'].isin(order)]
    groups = [group for _, group in rows.groupby(per)] if per in rows.columns else [rows]
    kept = []
    for group in groups:
        seeds = group.groupby(list(by))['seed'].agg(frozenset)
        common = frozenset.intersection(*seeds) if len(seeds) else frozenset()
        kept.append(group[group['seed'].isin(common)])
    return pd.concat(kept).reset_index(drop=True) if kept else rows.iloc[:0]


def _summary(
    rows: pd.DataFrame, by: Sequence[str], metrics: Mapping[str, str], order: Sequence[str]
) -> pd.DataFrame:
    """Mean +- std (and count) of each metric per configuration, faults in study order."""
    out = []
    for key, group in rows.groupby(list(by), sort=False):
        key = key if isinstance(key, tuple) else (key,)
        row = {b.removeprefix('config.'): k for b, k in zip(by, key, strict=True)}
        row['runs'] = len(group)
        for column, label in metrics.items():
            values = pd.to_numeric(group[column], errors='coerce').astype(float)
            finite = values.dropna()
            if not len(finite):
                row[label] = 'n/a'
            elif label.startswith('runs ') and label.endswith('%'):  # a share of runs
                row[label] = f'{finite.mean():.0f}'
            elif label.startswith('runs with'):  # a count over the runs
                row[label] = f'{int((finite > 0).sum())}'
            else:
                spread = finite.std(ddof=1) if len(finite) > 1 else 0.0
                row[label] = f'{finite.mean():.3g} ± {spread:.2g}'
            if label.endswith('(complete runs)'):
                row[label] += f' ({len(finite)})'

        out.append(row)
    frame = pd.DataFrame(out)
    if 'fault' in frame.columns:
        rank = {f: i for i, f in enumerate(order)}
        frame = frame.sort_values('fault', key=lambda s: s.map(rank), kind='stable')
    return frame.reset_index(drop=True)


def _mean_sd(values: pd.Series) -> str:
    finite = pd.to_numeric(values, errors='coerce').astype(float).dropna()
    if not len(finite):
        return 'n/a'
    spread = finite.std(ddof=1) if len(finite) > 1 else 0.0
    return f'{finite.mean():.3g} ± {spread:.2g}'


def _paired_change(rows: pd.DataFrame, column: str, by: Sequence[str]) -> pd.Series:
    """Per row, ``column`` minus its value in the fault-free run of the same seed and
    configuration (``by``); NaN where that run is missing."""
    base = rows[rows['config.fault'] == 'none'].set_index([*by, 'seed'])[column]
    keys = pd.MultiIndex.from_frame(rows[[*by, 'seed']])
    reference = base.reindex(keys).to_numpy(dtype=float)
    return pd.Series(rows[column].to_numpy(dtype=float) - reference, index=rows.index)


def _report_oabug_faults(page: ReportPage) -> None:
    rows = _planned(page, OABUG_FAULTS, ('config.departure', 'config.fault'), 'config.profile')
    if rows.empty:
        return
    if 'config.profile' not in rows.columns:
        rows = rows.assign(**{'config.profile': 'tuned'})
    rows = rows.assign(
        **{
            'metric.complete_pct': 100.0 * rows['metric.complete'].astype(float),
            'change': _paired_change(
                rows, 'metric.coverage', ['config.profile', 'config.departure']
            ),
        }
    )
    rank = {f: i for i, f in enumerate(OABUG_FAULTS)}
    profiles = sorted(pd.unique(rows['config.profile']), key=lambda p: (p != 'paper', p))
    for profile in profiles:
        table = []
        of_profile = rows[rows['config.profile'] == profile]
        for fault, group in sorted(of_profile.groupby('config.fault'), key=lambda g: rank[g[0]]):
            line: dict[str, Any] = {'fault': fault, 'sites': group['seed'].nunique()}
            for departure in ('center', 'edge'):
                runs = group[group['config.departure'] == departure]
                if runs.empty:
                    continue
                line[f'{departure}: coverage %'] = _mean_sd(runs['metric.coverage'])
                line[f'{departure}: change (paired) %'] = (
                    '' if fault == 'none' else _mean_sd(runs['change'])
                )
                line[f'{departure}: all rooms %'] = f'{runs["metric.complete_pct"].mean():.0f}'
                line[f'{departure}: stuck survivors'] = int(runs['metric.stuck_survivors'].sum())
            moved = pd.to_numeric(group['metric.faulty_moved_m']).max()
            line['lidar-less robot moved m (max)'] = f'{moved:.2g}' if 'stale' in fault else ''
            table.append(line)
        frame = pd.DataFrame(table)
        for column in frame.columns:
            if column.endswith('stuck survivors'):  # a count, blank where not run
                frame[column] = ['' if pd.isna(v) else str(int(v)) for v in frame[column]]
        page.add_table(
            frame,
            title=f'Reliability: OA-Bug Gas+Sound, profile {profile}, Small, 10 robots',
            export=f'faults-{profile}',
        )
    causes = [
        c for c in ('stuck_by_stopped', 'stuck_by_peer', 'stuck_alone') if f'metric.{c}' in rows
    ]
    if causes:
        # Only the scenarios and sites that every profile and departure ran, so that the
        # rows compare the same runs.
        keys = ['config.fault', 'seed']
        runs = rows.groupby(['config.profile', 'config.departure'])[keys]
        shared = frozenset.intersection(
            *(frozenset(map(tuple, group.to_numpy())) for _, group in runs)
        )
        common = rows[[tuple(key) in shared for key in rows[keys].to_numpy()]]
        table = []
        for (profile, departure), group in common.groupby(['config.profile', 'config.departure']):
            line = {'profile': profile, 'departure': departure, 'runs': len(group)}
            line['stuck survivors'] = int(group['metric.stuck_survivors'].sum())
            for cause, label in zip(
                causes,
                ('beside a stopped robot', 'beside working peers only', 'no robot within 0.25 m'),
                strict=True,
            ):
                line[label] = int(group[f'metric.{cause}'].sum())
            table.append(line)
        frame = pd.DataFrame(table)
        frame = frame.sort_values('profile', key=lambda s: s != 'paper', kind='stable')
        page.add_table(
            frame.reset_index(drop=True),
            title=(
                'OA-Bug survivors that stood still longer than 20 s, by what touched them '
                '(the scenarios and sites every row ran)'
            ),
            export='stuck',
        )


def _extreme(rows: pd.DataFrame, column: str, how: str, fmt: str = '.3g') -> dict[Any, str]:
    """Per fault, the smallest (``how='min'``) or largest value of ``column`` over the runs."""
    out: dict[Any, str] = {}
    for fault, group in rows.groupby('config.fault'):
        values = pd.to_numeric(group[column], errors='coerce').astype(float).dropna()
        out[fault] = format(getattr(values, how)(), fmt) if len(values) else 'n/a'
    return out


def _report_bayes_faults(page: ReportPage) -> None:
    rows = _planned(page, BAYES_FAULTS)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.found_pct': 100.0 * rows['metric.found'].astype(float)})
    table = _summary(
        rows,
        ['config.fault'],
        {'metric.tau': 'tau (complete runs)', 'metric.found_pct': 'runs finding the source %'},
        BAYES_FAULTS,
    )
    medians = rows.groupby('config.fault')['metric.tau'].median()
    table.insert(3, 'median tau', [f'{medians.get(f, math.nan):.3g}' for f in table['fault']])
    if 'metric.belief_error_m' in rows:
        failed = rows[~rows['metric.found'].astype(bool)]
        for column, label in (
            ('metric.belief_error_m', 'failed runs: belief to source m'),
            ('metric.belief_to_faulty_sensor_m', 'failed runs: belief to faulty sensor m'),
        ):
            values = failed.groupby('config.fault')[column].median()
            table[label] = [
                f'{values[f]:.2g}' if f in values and np.isfinite(values[f]) else ''
                for f in table['fault']
            ]
    if 'metric.survivor_decisions_after_fault' in rows:
        fewest = _extreme(rows, 'metric.survivor_decisions_after_fault', 'min', '.0f')
        table['fewest decisions of a survivor after the fault'] = [
            '' if f == 'none' else fewest[f] for f in table['fault']
        ]
    profile = str(rows['param.profile'].iloc[0]) if 'param.profile' in rows else 'grid'
    page.add_table(
        table, title=f'Reliability: Bayes-Swarm-P, profile {profile}, case 1', export='faults'
    )


def _report_msc_faults(page: ReportPage) -> None:
    rows = _planned(page, MSC_FAULTS)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.all_pct': 100.0 * rows['metric.all_captured'].astype(float)})
    table = _summary(
        rows,
        ['config.fault'],
        {
            'metric.cct_s': 'CCT s (complete runs)',
            'metric.all_pct': 'runs capturing all %',
            'metric.captured': 'targets captured',
        },
        MSC_FAULTS,
    )
    if 'metric.survivor_min_moved_m' in rows:
        least = _extreme(rows, 'metric.survivor_min_moved_m', 'min', '.0f')
        still = _extreme(rows, 'metric.survivor_max_still_s', 'max', '.0f')
        table['least a survivor drove after the fault m'] = [least[f] for f in table['fault']]
        table['longest a survivor stood after the fault s'] = [still[f] for f in table['fault']]
    robots = int(rows['param.robots'].iloc[0])
    targets = int(rows['param.targets'].iloc[0])
    page.add_table(
        table,
        title=f'Reliability: MSC + PF (proposed), {robots} robots, {targets} targets',
        export='faults',
    )


_CRASH_TABLES = {
    'oabug': (
        'OA-Bug Gas+Sound (paper profile), Small, 4 robots, 100 s',
        {
            'metric.coverage': 'coverage %',
        },
    ),
    'bayes_swarm': (
        'Bayes-Swarm-P (paper profile), case 1, 3 robots',
        {
            'metric.tau': 'tau (complete runs)',
            'metric.found_pct': 'runs finding the source %',
        },
    ),
    'msc_pf': (
        'MSC + PF (proposed), 4 robots, 2 targets, 250 s',
        {
            'metric.cct_s': 'CCT s (complete runs)',
            'metric.all_pct': 'runs capturing all %',
        },
    ),
}
_CRASH_COLUMNS = {
    'metric.down_moved_m': 'r1 moved while down m',
    'metric.restart_delay_s': 'restart to moving s',
    'metric.restart_moved_m': 'r1 moved after restart m',
    'metric.others_moved_m': 'least others moved while r1 down m',
    'metric.wall_s': 'wall s',
    'metric.load': 'load',
}


def _report_crash(page: ReportPage) -> None:
    rows = _planned(page, (), ('config.algorithm', 'config.scenario'))
    if rows.empty:
        return
    for column, share in (
        ('metric.found', 'metric.found_pct'),
        ('metric.all_captured', 'metric.all_pct'),
    ):
        if column in rows.columns:
            rows = rows.assign(**{share: 100.0 * pd.to_numeric(rows[column]).astype(float)})
    for algorithm, (title, metrics) in _CRASH_TABLES.items():
        of = rows[rows['config.algorithm'] == algorithm]
        if of.empty:
            continue
        table = _summary(of, ['config.scenario'], {**metrics, **_CRASH_COLUMNS}, ())
        rank = {s: i for i, s in enumerate(CRASH_SCENARIOS)}
        table = table.sort_values('scenario', key=lambda s: s.map(rank), kind='stable')
        page.add_table(
            table.reset_index(drop=True), title=f'Node crash: {title}', export=f'crash-{algorithm}'
        )


def _report_sensors(page: ReportPage) -> None:
    keys = ('config.profile', 'config.variant', 'config.departure', 'config.sensors')
    rows = _planned(page, (), keys)
    if rows.empty:
        return
    rows = rows.assign(**{'metric.complete_pct': 100.0 * rows['metric.complete'].astype(float)})
    rank = {'paper': 0, 'tuned': 1}  # the as-published robot leads
    rows = rows.sort_values('config.profile', key=lambda p: p.map(rank), kind='stable')
    table = _summary(
        rows,
        list(keys),
        {'metric.coverage': 'coverage %', 'metric.complete_pct': 'runs covering all rooms %'},
        (),
    )
    page.add_table(
        table,
        title='OA-Bug variants under both sensor profiles, Small, 10 robots (robot profile '
        'paper first)',
        export='sensors',
    )
    if set(rows['config.sensors']) >= {'ideal', 'realistic'}:
        paired = paired_differences(
            rows,
            'metric.coverage',
            by='config.sensors',
            baseline='ideal',
            group_by=['config.profile', 'config.variant', 'config.departure'],
        )
        paired = paired.sort_values('config.profile', key=lambda p: p.map(rank), kind='stable')
        page.add_table(
            paired.reset_index(drop=True),
            title='Coverage, realistic minus ideal sensors, paired by site (wins: realistic '
            'covers more)',
            export='sensors-paired',
        )


def studies() -> list[Study]:
    """The reliability and sensor-profile studies."""
    return [
        Study(
            name='faults-oabug',
            run=run_oabug_fault,
            axes={
                'profile': ('paper', 'tuned'),
                'departure': ('center', 'edge'),
                'fault': OABUG_FAULTS,
            },
            params={'site': 'small', 'robots': 10, 'variant': 'gas_sound', 'fault_time_s': 60.0},
            runs=3,
            seed_label='site',
            description='OA-Bug Gas+Sound coverage under injected faults (onset at 60 s).',
            smoke=Smoke(
                runs=1,
                axes={
                    'profile': ('paper',),
                    'departure': ('center',),
                    'fault': ('none', 'dropout_robots=5'),
                },
            ),
            report=_report_oabug_faults,
            check=check_oabug_fault,
        ),
        Study(
            name='faults-bayes',
            run=run_bayes_fault,
            axes={'fault': BAYES_FAULTS},
            params={
                'case': 'case1',
                'algorithm': 'bayes_swarm_p',
                'robots': 0,
                'noise_std': 0.0,
                'profile': 'paper',
                'fault_time_s': 10.0,
                'stop_time_s': None,
            },
            runs=3,
            description='Bayes-Swarm-P tau under injected faults (onset at 10 s).',
            smoke=Smoke(runs=1, axes={'fault': ('none', 'dropout_robots=2')}),
            report=_report_bayes_faults,
            check=check_bayes_fault,
        ),
        Study(
            name='faults-msc',
            run=run_msc_fault,
            axes={'fault': MSC_FAULTS},
            params={
                'scheme': 'proposed',
                'robots': 15,
                'targets': 10,
                'max_time_s': 30000.0,
                'fault_time_s': 500.0,
            },
            runs=2,
            description='MSC + PF capture completion time under injected faults (onset 500 s).',
            smoke=Smoke(
                runs=1,
                axes={'fault': ('none', 'dropout_robots=7')},
                params={'targets': 3, 'max_time_s': 3000.0},
            ),
            report=_report_msc_faults,
            check=check_msc_fault,
        ),
        Study(
            name='faults-crash',
            run=run_crash,
            axes={'algorithm': tuple(CRASH_MISSIONS), 'scenario': CRASH_SCENARIOS},
            params={'domain_id': 90},
            runs=3,
            description=(
                'A robot node killed (and restarted) mid-run, one process per node on real '
                'rclpy, in real time.'
            ),
            smoke=Smoke(runs=1, axes={'algorithm': ('oabug',), 'scenario': ('restart',)}),
            report=_report_crash,
            check=check_crash,
        ),
        Study(
            name='sensors-oabug',
            run=run_oabug_sensors,
            axes={
                'profile': ('paper', 'tuned'),
                'variant': ('random', 'minimum', 'sound', 'gas', 'gas_sound'),
                'departure': ('center', 'edge'),
                'sensors': ('ideal', 'realistic'),
            },
            params={'site': 'small', 'robots': 10},
            runs=100,  # the OA-Bug paper's Fig. 4 site count
            seed_label='site',
            description='Every OA-Bug variant, both robot profiles (paper first), under the ideal '
            'and the realistic sensor profile.',
            smoke=Smoke(
                runs=1,
                axes={'profile': ('paper',), 'variant': ('gas_sound',), 'departure': ('center',)},
            ),
            report=_report_sensors,
            check=check_oabug_sensors,
        ),
    ]
