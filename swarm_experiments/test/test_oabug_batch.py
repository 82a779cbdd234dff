"""The batch path reproduces the ROS path's OA-Bug missions exactly."""

import math
from pathlib import Path

import numpy as np
import pytest
from oabug_robot.fsm import Command
from swarm_experiments.mission import RecordingSpec, StopReason, run_mission
from swarm_experiments.oabug_batch import (
    BatchRobot,
    _deliver_bearings,
    run_oabug_batch,
    run_spawn_batch,
)
from swarm_experiments.spawn import SpawnSettings, build_mission
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.bearings import BearingConfig, BearingModel
from swarm_sim.sensors.lidar import LidarConfig

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
# The ROS path equals the batch path bit for bit only on the deterministic executor: on DDS
# the delivery order and timing of the robots' messages vary from run to run.
BIT_EXACT = pytest.mark.builtin_only(reason='bit-exact determinism of the in-process ROS path')


@pytest.mark.parametrize(
    ('site', 'robots', 'variant', 'departure', 'actions'),
    [
        ('small', 10, 'gas_sound', 'center', 120),
        (str(FIVE_ROOMS), 4, 'gas', 'edge', 300),
    ],
    ids=['small-10-robots', 'five-rooms-all-covered'],
)
@BIT_EXACT
def test_batch_and_ros_paths_give_the_same_poses_and_first_entries(
    site, robots, variant, departure, actions
):
    config = SpawnSettings(
        site=site, robots=robots, variant=variant, departure=departure, actions=actions
    )
    spec, _ = build_mission(config)
    ros = run_mission(spec)
    batch = run_oabug_batch(spec)
    # The robots did something worth comparing: they drove and entered rooms.
    assert ros.distance_travelled_m.min() > 2.0
    assert ros.rooms_covered >= 2
    assert batch.stop_reason == ros.stop_reason
    if site == str(FIVE_ROOMS):
        assert ros.stop_reason == StopReason.ALL_ROOMS_COVERED
    assert batch.sim_time_s == ros.sim_time_s
    np.testing.assert_array_equal(batch.trajectory_times_s, ros.trajectory_times_s)
    np.testing.assert_array_equal(batch.trajectories, ros.trajectories)
    assert batch.room_entries == ros.room_entries
    np.testing.assert_array_equal(batch.distance_travelled_m, ros.distance_travelled_m)


def test_batch_spawn_run_matches_its_config():
    config = SpawnSettings(site=str(FIVE_ROOMS), robots=3, departure='edge', actions=60)
    result = run_spawn_batch(config)
    assert result.mission.sim_time_s == pytest.approx(config.budget_s, abs=0.11)
    assert result.mission.trajectories.shape[1:] == (3, 3)
    assert result.plots == ()


def test_batch_path_refuses_what_it_cannot_do(tmp_path):
    spec, _ = build_mission(SpawnSettings(site=str(FIVE_ROOMS), robots=2, departure='edge'))
    recorded = type(spec)(**{**spec.__dict__, 'recording': RecordingSpec(tmp_path / 'bag')})
    with pytest.raises(ConfigurationError, match='bag'):
        run_oabug_batch(recorded)
    relayed = type(spec)(**{**spec.__dict__, 'bridge_parameters': {'comm_range_m': 5.0}})
    with pytest.raises(ConfigurationError, match='bridge'):
        run_oabug_batch(relayed)
    with pytest.raises(ConfigurationError, match='no_such_parameter'):
        BatchRobot({'no_such_parameter': 1}, LidarConfig())


def test_a_robot_holds_still_until_scan_and_imu_arrive_and_when_they_go_stale():
    robot = BatchRobot({'variant': 'minimum'}, LidarConfig())
    stop = Command(0.0, 0.0, False)
    assert robot.control(0.1) == stop
    robot.receive_imu(0.5, 0.1)
    assert robot.control(0.1) == stop
    robot.receive_scan(np.full(360, math.inf), 0.2)
    moving = robot.control(0.2)
    assert moving != stop
    # Nothing new for longer than stale_timeout_s: the node's fail safe.
    assert robot.control(0.2 + robot.stale_timeout_s + 0.1) == stop


@BIT_EXACT
def test_without_the_cdr_round_trip_both_paths_still_agree(monkeypatch):
    # In-process messages then keep Python floats in their float32 fields; the batch path
    # follows the runtime's setting.
    monkeypatch.setenv('SWARM_RUNTIME_CDR_ROUNDTRIP', '0')
    config = SpawnSettings(
        site=str(FIVE_ROOMS), robots=4, variant='gas', departure='edge', actions=150
    )
    spec, _ = build_mission(config)
    ros = run_mission(spec)
    batch = run_oabug_batch(spec)
    assert ros.distance_travelled_m.min() > 2.0
    np.testing.assert_array_equal(batch.trajectories, ros.trajectories)
    assert batch.room_entries == ros.room_entries
    # Rounding the bearings and scan angles as serialization does changes the run.
    rounded = run_oabug_batch(spec, float32_fields=True)
    assert not np.array_equal(rounded.trajectories, ros.trajectories)


@pytest.mark.parametrize('float32_fields', [True, False])
def test_a_bearing_cycle_is_held_as_each_robots_report_would_be(float32_fields):
    """_deliver_bearings on one flat BearingCycle gives every robot the bearings its own
    receive_bearings gives from its report (own tags dropped, fields rounded), bit for bit."""
    rng = np.random.default_rng(8)
    lidar = LidarConfig()
    for _ in range(50):
        n = int(rng.integers(1, 8))
        model = BearingModel(n, BearingConfig(range_m=20.0), np.random.default_rng(1))
        cycle = model.measure_cycle(np.column_stack((rng.uniform(0, 5, (n, 2)), np.zeros(n))))
        # A robot may carry a tag another robot's id names (it keeps that tag's bearings
        # out), or a tag nobody has (-1).
        tag_ids = tuple(f'R{i}' for i in range(n))
        own = [str(rng.choice([*tag_ids, 'X'])) for _ in range(n)]
        batch = [
            BatchRobot({'own_tag_id': tag}, lidar, float32_fields=float32_fields) for tag in own
        ]
        single = [
            BatchRobot({'own_tag_id': tag}, lidar, float32_fields=float32_fields) for tag in own
        ]
        own_tags = np.array([robot.own_tag_index(tag_ids) for robot in batch], dtype=np.int64)
        _deliver_bearings(batch, cycle, own_tags, 1.5)
        for robot, report in zip(single, cycle.reports(), strict=True):
            robot.receive_bearings(report, tag_ids, 1.5)
        for got, want in zip(batch, single, strict=True):
            a, b = got.loop.peer_bearings(1.5), want.loop.peer_bearings(1.5)
            assert a[0].tobytes() == b[0].tobytes()
            assert a[1].tobytes() == b[1].tobytes()


def test_the_spawner_starts_robots_in_free_space_on_a_seeded_fan():
    from swarm_sim.departure import place_starts
    from swarm_sim.site_loading import load_site

    site = load_site('small')
    for seed in (0, 1):
        config = SpawnSettings(site='small', robots=10, departure='edge', seed=seed)
        spec, bias = build_mission(config)
        starts = place_starts(site, 'edge', 10, seed=seed, body=config.engine.body)
        np.testing.assert_array_equal(spec.initial_poses, starts.poses)
        assert bias == starts.bias_rad
        headings = [float(r.parameters['heading_bias_deg']) for r in spec.robots]
        assert headings == [math.degrees(bias)] * 10
    first, _ = build_mission(SpawnSettings(site='small', robots=10, departure='edge', seed=0))
    second, _ = build_mission(SpawnSettings(site='small', robots=10, departure='edge', seed=1))
    assert not np.allclose(first.initial_poses[:, 2], second.initial_poses[:, 2])


def test_the_spawner_profile_sets_the_node_parameters_under_the_explicit_ones():
    paper, _ = build_mission(
        SpawnSettings(site=str(FIVE_ROOMS), robots=2, departure='edge', profile='paper')
    )
    assert all(r.parameters['gas_sound_wall_side'] == 'every_contact' for r in paper.robots)
    assert all(r.parameters['robot_hit_repeat_s'] == 0.0 for r in paper.robots)
    mixed, _ = build_mission(
        SpawnSettings(
            site=str(FIVE_ROOMS),
            robots=2,
            departure='edge',
            profile='paper',
            robot_parameters={'robot_hit_repeat_s': 2.0},
        )
    )
    assert all(r.parameters['robot_hit_repeat_s'] == 2.0 for r in mixed.robots)
    tuned, _ = build_mission(SpawnSettings(site=str(FIVE_ROOMS), robots=2, departure='edge'))
    assert 'gas_sound_wall_side' not in tuned.robots[0].parameters
    with pytest.raises(ConfigurationError, match='profile'):
        SpawnSettings(profile='fast')
