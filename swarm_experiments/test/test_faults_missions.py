"""Injected faults in whole missions: the same spec on both paths, survivors keep working."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from msc_pf.schemes import Scheme
from swarm_experiments.bayes_batch import run_mission as run_bayes
from swarm_experiments.cli_args import fault_config
from swarm_experiments.mission import run_mission
from swarm_experiments.msc_pf_batch import BatchScenario, run_batch
from swarm_experiments.node_overrides import OverrideError
from swarm_experiments.oabug_batch import BatchRobot, BatchSwarm, _deliver, run_oabug_batch
from swarm_experiments.reliability import decisions_after_s, parse_fault, still_time_s
from swarm_experiments.spawn import SpawnSettings, build_mission
from swarm_experiments.spawn import main as spawn_main
from swarm_experiments.spawn_msc_pf import main as msc_main
from swarm_sim.engine import EngineConfig, SimEngine
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.sensor_profiles import apply_sensor_profile
from swarm_sim.site_geometry import geometry_from_site

NO_NODE = pytest.mark.runtime_independent(reason='batch runs, no node')

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'


@pytest.mark.builtin_only(
    reason='bit-exact agreement needs the deterministic executor order of the built-in runtime'
)
def test_the_same_faults_give_the_same_mission_on_the_batch_and_ros_paths():
    faults = FaultConfig(
        dropout_robots=1,
        dropout_time_s=8.0,
        stale_lidar_robots=1,
        stuck_gas_robots=1,
        sensor_time_s=5.0,
        bearing_dropout_probability=0.3,
    )
    engine = apply_sensor_profile(EngineConfig(faults=faults), 'realistic')
    config = SpawnSettings(
        site=str(FIVE_ROOMS),
        robots=4,
        variant='gas_sound',
        departure='edge',
        actions=150,
        engine=engine,
    )
    spec, _ = build_mission(config)
    ros = run_mission(spec)
    batch = run_oabug_batch(spec)
    np.testing.assert_array_equal(batch.trajectories, ros.trajectories)
    assert batch.room_entries == ros.room_entries
    plan = FaultPlan(faults, 4, config.seed)
    (dropped,) = plan.robots['dropout']
    late = ros.trajectory_times_s >= 8.5
    assert np.ptp(ros.trajectories[late, dropped, :2], axis=0).max() == 0.0


def _robots_and_engine(settings):
    spec, _ = build_mission(settings)
    engine = SimEngine(
        geometry_from_site(spec.site),
        np.asarray(spec.initial_poses, dtype=float),
        dataclasses.replace(spec.engine_config, sensors=spec.engine_config.sensors - {'odometry'}),
        bearing_cycles=True,
    )
    robots = [BatchRobot(r.parameters, engine.config.lidar) for r in spec.robots]
    return engine, BatchSwarm(robots, tuple(f'R{i}' for i in range(len(robots))))


class PushWatch:
    """Per robot, the longest time it drove forward without moving 2 cm (pushing)."""

    def __init__(self, engine):
        self.anchor = engine.world.poses[:, :2].copy()
        self.since = np.full(engine.num_robots, np.nan)
        self.longest_s = np.zeros(engine.num_robots)

    def update(self, engine, poses):
        now = engine.time_s
        forward = engine.active_commands()[:, 0] > 0.01
        moved = np.hypot(*(poses[:, :2] - self.anchor).T) > 0.02
        self.anchor[moved] = poses[moved, :2]
        restart = moved | ~forward
        self.since[restart] = np.nan
        self.since[~restart & np.isnan(self.since)] = now
        self.longest_s = np.fmax(self.longest_s, now - self.since)


@NO_NODE
@pytest.mark.slow
def test_survivors_never_push_into_a_wall_and_lidarless_robots_stop_with_the_pump_off():
    onset = 20.0
    faults = FaultConfig(
        dropout_robots=2,
        dropout_time_s=onset,
        stale_lidar_robots=2,
        stuck_gas_robots=1,
        drifting_gas_robots=1,
        imu_drift_robots=1,
        sensor_time_s=onset,
        bearing_dropout_probability=0.5,
    )
    settings = SpawnSettings(
        site='small', robots=10, variant='gas_sound', seed=4, engine=EngineConfig(faults=faults)
    )
    engine, swarm = _robots_and_engine(settings)
    plan = engine.fault_plan
    stale = plan.mask('stale_lidar')
    working = ~(plan.mask('dropout') | stale)
    pushing = PushWatch(engine)
    pumped_before = np.zeros(10, dtype=bool)
    while engine.time_s < 150.0:
        out = engine.step()
        _deliver(engine, out, swarm)
        pushing.update(engine, out.poses)
        now = engine.time_s
        if now < onset:
            pumped_before |= engine.pumps_running()
        elif now > onset + 1.0:
            # Stale scan: zero command and the pump off, within the stale timeout.
            assert not engine.pumps_running()[stale].any()
            assert not engine.active_commands()[stale].any()
    assert pumped_before.any()  # the pumps did run: "off" above is a change
    # No robot drove forward against an obstacle for more than 5 s.
    assert pushing.longest_s[working].max() < 5.0
    assert engine.distance_travelled_m[working].min() > 10.0


@NO_NODE
@pytest.mark.slow
def test_robots_touching_side_by_side_do_not_push_for_ever():
    # Site 5 from the edge: at 14 s two robots touch, each beside the other's front outside
    # the 30 deg hit cone. Without the contact rule both drive on into the other, blocked,
    # for 36 s; with it each takes the touch for a robot hit and turns, whether it counts
    # the whole contact sector or only the body's path. (The scenario arises with inner
    # corners turned on the spot, the earlier default.)
    def longest_push(contact_m, in_path=True):
        settings = SpawnSettings(
            site='small',
            site_seed=5,
            seed=5,
            robots=10,
            variant='gas_sound',
            departure='edge',
            profile='tuned',
            robot_parameters={
                'robot_contact_distance_m': contact_m,
                'robot_contact_in_path': in_path,
                'inner_corner_arc_radius_m': 0.0,
            },
        )
        engine, swarm = _robots_and_engine(settings)
        pushing = PushWatch(engine)
        while engine.time_s < 45.0:
            out = engine.step()
            _deliver(engine, out, swarm)
            pushing.update(engine, out.poses)
        return pushing.longest_s.max()

    assert longest_push(0.16) < 5.0
    assert longest_push(0.16, in_path=False) < 5.0
    assert longest_push(0.0) > 20.0  # the rule off: the old dead lock


@NO_NODE
def test_a_bayes_swarm_without_some_robots_still_finds_the_source(case1_spec):
    full = run_bayes(case1_spec, 'bayes_swarm_p', 5, seed=3)
    faults = FaultConfig(dropout_robots=2, dropout_time_s=5.0)
    spec = dataclasses.replace(case1_spec, faults=faults)
    fewer = run_bayes(spec, 'bayes_swarm_p', 5, seed=3)
    plan = FaultPlan(faults, 5, 3)
    assert full.found
    assert fewer.found
    assert fewer.finder not in plan.robots['dropout']
    for robot in plan.robots['dropout']:
        assert all(d.compute_time_s >= 0 for d in fewer.decisions[robot])
        path = fewer.trajectories[robot]
        # After the dropout the robot is where it was at 5 s: at most V * 5 s from its start.
        assert np.hypot(*(path[-1] - path[0])) <= case1_spec.planner.velocity_mps * 5.0 + 1e-9
    # The survivors went on deciding (on the samples they took since) after the dropout.
    speed = case1_spec.planner.velocity_mps
    for robot in sorted(set(range(5)) - set(plan.robots['dropout'])):
        assert decisions_after_s(fewer.trajectories[robot], speed, 5.0) >= 2
    everyone = dataclasses.replace(case1_spec, faults=FaultConfig(dropout_robots=5))
    assert not run_bayes(everyone, 'bayes_swarm_p', 5, seed=3).found
    deaf = dataclasses.replace(case1_spec, faults=FaultConfig(comm_loss_probability=1.0))
    alone = run_bayes(deaf, 'bayes_swarm_p', 5, seed=3)
    assert alone.found_time_s != full.found_time_s


@NO_NODE
@pytest.mark.slow
def test_dropped_msc_robots_stand_still_and_capture_nothing():
    targets = np.array([[1150.0, 1080.0], [820.0, 900.0]])
    faults = FaultConfig(dropout_robots=2, dropout_time_s=50.0)
    scenario = BatchScenario(
        scheme=Scheme.PROPOSED,
        n_robots=6,
        n_targets=2,
        seed=7,
        max_time_s=3000.0,
        target_positions_m=targets,
        faults=faults,
    )
    result = run_batch(scenario, record=True)
    dropped = FaultPlan(faults, 6, 7).robots['dropout']
    paths = result.paths_m
    assert np.ptp(paths[51:, dropped], axis=0).max() == 0.0
    assert np.ptp(paths[:50, dropped], axis=0).max() > 10.0
    assert np.isfinite(result.cct_s)
    # The survivors went on driving after the dropout, to the last capture.
    survivors = sorted(set(range(6)) - set(dropped))
    steps = np.diff(paths[51:, survivors], axis=0)
    driven = np.hypot(steps[..., 0], steps[..., 1]).sum(axis=0)
    assert driven.min() > 50.0


@NO_NODE
def test_msc_link_faults_act_in_the_relay_and_dropped_robots_go_silent():
    base = BatchScenario(scheme=Scheme.PROPOSED, n_robots=4, n_targets=2, seed=5, max_time_s=150.0)
    deaf = run_batch(
        dataclasses.replace(base, faults=FaultConfig(comm_loss_probability=1.0)), record=True
    )
    lossy = run_batch(dataclasses.replace(base, comm_loss=1.0), record=True)
    talking = run_batch(base, record=True)
    # The fault's loss combines with the scenario's in the relay: all lost either way.
    assert np.array_equal(deaf.paths_m, lossy.paths_m)
    assert not np.array_equal(deaf.paths_m, talking.paths_m)
    # Robots dropped at 0 s never move, and nobody hears from them.
    faults = FaultConfig(dropout_robots=3, dropout_time_s=0.0)
    alone = run_batch(dataclasses.replace(base, faults=faults), record=True)
    dropped = FaultPlan(faults, 4, 5).robots['dropout']
    assert np.ptp(alone.paths_m[:, dropped], axis=0).max() == 0.0
    survivor = [i for i in range(4) if i not in dropped]
    solo = run_batch(dataclasses.replace(base, comm_loss=1.0), record=True)
    assert np.ptp(alone.paths_m[:, survivor], axis=0).max() > 1.0
    assert np.array_equal(alone.paths_m[:, survivor], solo.paths_m[:, survivor])


@NO_NODE
def test_faults_of_sensors_the_point_robot_runners_lack_are_refused(case1_spec):
    from bayes_swarm.errors import ConfigError as BayesConfigError
    from msc_pf.errors import ConfigError as MscConfigError

    lidar = dataclasses.replace(case1_spec, faults=FaultConfig(stale_lidar_robots=1))
    with pytest.raises(BayesConfigError, match='stale_lidar_robots are not simulated'):
        run_bayes(lidar, 'bayes_swarm_p', 3, seed=1)
    gas = BatchScenario(n_robots=3, n_targets=1, faults=FaultConfig(stuck_gas_robots=1))
    with pytest.raises(MscConfigError, match='stuck_gas_robots are not simulated'):
        run_batch(gas)


@NO_NODE
def test_still_time_measures_the_longest_stop():
    times = np.arange(6.0)
    positions = np.array([[0, 0], [1, 0], [1, 0], [1, 0.01], [2, 0], [3, 0]], dtype=float)
    assert still_time_s(times, positions) == 2.0
    driving = np.column_stack([0.1 * times, np.zeros(6)])
    assert still_time_s(times, driving) == 0.0


@NO_NODE
def test_fault_scenarios_and_options_parse_and_bad_ones_fail_in_one_line(capsys):
    config = parse_fault('dropout_robots=2,comm_loss_probability=0.5', 30.0)
    assert (config.dropout_robots, config.dropout_time_s) == (2, 30.0)
    assert config.comm_loss_probability == 0.5
    assert parse_fault('none', 0.0) == FaultConfig()
    with pytest.raises(OverrideError, match='dropout_robot'):
        fault_config(['dropout_robot=2'])
    with pytest.raises(OverrideError, match='comm_loss_probability'):
        fault_config(['comm_loss_probability=2'])
    assert spawn_main(['--fault', 'stale_lidars=1', '--no-plots']) == 2
    assert msc_main(['--fault', 'comm_range_m=-3', '--no-plots']) == 2
    assert spawn_main(['--sensors', 'realistic', '--sensor-param', 'lidar=1']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3
    assert 'stale_lidars' in err[0]
    assert 'comm_range_m' in err[1]
    assert 'lidar' in err[2]
    assert math.isinf(FaultConfig().comm_range_m)


@NO_NODE
def test_glowworm_robots_run_under_faults(case1_spec):
    spec = dataclasses.replace(
        case1_spec,
        planner=dataclasses.replace(case1_spec.planner, max_mission_time_s=30.0),
    )
    talking = run_bayes(spec, 'glowworm', 4, seed=2)
    # Deaf robots have no brighter neighbour: each stays where its dispersal leg ended.
    deaf = run_bayes(
        dataclasses.replace(spec, faults=FaultConfig(comm_loss_probability=1.0)), 'glowworm', 4, 2
    )
    for path in deaf.trajectories:
        np.testing.assert_array_equal(path[-1], path[-2])
    assert any(np.hypot(*(path[-1] - path[-2])) > 0.1 for path in talking.trajectories)
    # Robots dropped at 0 s never leave their depot; the others still iterate.
    faults = FaultConfig(dropout_robots=2, dropout_time_s=0.0)
    fewer = run_bayes(dataclasses.replace(spec, faults=faults), 'glowworm', 4, seed=2)
    dropped = FaultPlan(faults, 4, 2).robots['dropout']
    for robot in range(4):
        path = fewer.trajectories[robot]
        moved = np.hypot(*(path[-1] - path[0]))
        assert (moved == 0.0) == (robot in dropped)
