"""MSC + PF spawner: capture, bag CCT, agreement with the batch sim (built-in runtime)."""

import math

import numpy as np
import pytest
from msc_pf.schemes import Scheme
from swarm_analysis.cct import cct_from_bag
from swarm_common.stamps import stamp_to_seconds
from swarm_experiments.errors import ExperimentError
from swarm_experiments.msc_pf_batch import BatchScenario, run_batch
from swarm_experiments.spawn_msc_pf import SpawnSettings, main, run
from swarm_runtime.bag import read_messages
from swarm_runtime.ros import using_real_rclpy

TARGET = np.array([[1100.0, 1060.0]])
# On real rclpy the mission runs in real time: at this many sim seconds per wall second the
# capture (~130 s of sim time) takes ~30 s (the nodes keep up: 3 robots, a 1 s period).
REAL_TIME_SCALE = 5.0


def settings(tmp_path=None, **overrides):
    values = {
        'scheme': 'proposed',
        'robots': 3,
        'targets': 1,
        'seed': 3,
        'max_time_s': 600.0,
        'target_positions_m': TARGET,
    }
    if tmp_path is not None:
        values.update(record=tmp_path / 'bag', out_dir=tmp_path / 'plots')
    values.update(overrides)
    return SpawnSettings(**values)


@pytest.fixture(scope='module')
def ros_run(tmp_path_factory):
    scale = REAL_TIME_SCALE if using_real_rclpy() else 1.0
    return run(settings(tmp_path_factory.mktemp('spawn'), time_scale=scale))


@pytest.mark.slow
def test_spawned_robots_capture_the_target_and_write_plots(ros_run):
    assert math.isfinite(ros_run.cct_s)
    # ~115 m away at 1 m/s plus 20 s of work (one robot) at the least.
    assert ros_run.cct_s > 100.0
    assert ros_run.cct_s < ros_run.settings.max_time_s
    assert sorted(p.name for p in ros_run.plots) == ['field_paths.png', 'pf_estimates.png']
    assert all(p.stat().st_size > 0 for p in ros_run.plots)
    assert len(ros_run.estimate_log) > 0


@pytest.mark.slow
def test_cct_recomputed_from_the_bag_matches_the_run(ros_run):
    result = cct_from_bag(ros_run.settings.record)
    assert result.all_captured
    assert result.cct_s == pytest.approx(ros_run.cct_s, abs=1e-6)


@pytest.mark.slow
def test_the_bag_shows_the_target_turn_from_open_to_captured(ros_run):
    messages = [
        item.message
        for item in read_messages(ros_run.settings.record, topics=['/sim/markers/targets'])
    ]
    # Latched at the start, then sent again at the capture.
    assert len(messages) == 2
    spheres = [[m for m in array.markers if m.ns == 'targets'] for array in messages]
    (first,), (last,) = spheres
    assert (first.pose.position.x, first.pose.position.y) == tuple(TARGET[0])
    assert first.color.r > first.color.g  # open: orange
    assert last.color.g > last.color.r  # captured: green
    areas = [m for m in messages[0].markers if m.ns == 'target_areas']
    assert areas[0].scale.x == pytest.approx(2.0 * 5.0)  # the work area D_th
    assert stamp_to_seconds(messages[1].markers[0].header.stamp) == pytest.approx(
        ros_run.cct_s, abs=0.2
    )


def batch_of(run_settings):
    return run_batch(
        BatchScenario(
            scheme=Scheme(run_settings.scheme),
            n_robots=run_settings.robots,
            n_targets=run_settings.targets,
            seed=run_settings.seed,
            max_time_s=run_settings.max_time_s,
            comm_loss=run_settings.loss_probability,
            target_positions_m=run_settings.target_positions_m,
        ),
        record=True,
    )


def assert_same_run(ros, batch):
    """Equal capture times, and equal positions at every whole second both recorded."""
    np.testing.assert_array_equal(ros.capture_times_s, batch.capture_times_s)
    times = ros.mission.trajectory_times_s
    whole = np.flatnonzero(np.isclose(times, np.round(times)) & (times < len(batch.paths_m)))
    assert len(whole) > 10
    np.testing.assert_array_equal(
        ros.mission.trajectories[whole, :, :2], batch.paths_m[np.round(times[whole]).astype(int)]
    )


@pytest.mark.slow
@pytest.mark.builtin_only(
    reason='exact agreement needs the deterministic executor order of the built-in runtime'
)
def test_ros_path_and_batch_runner_agree_exactly(ros_run):
    # The same RobotLoop per robot, the same engine and target field, the executor's order.
    assert_same_run(ros_run, batch_of(ros_run.settings))


@pytest.mark.slow
@pytest.mark.builtin_only(
    reason='exact agreement needs the deterministic executor order of the built-in runtime'
)
@pytest.mark.parametrize('scheme', ['msc', 'msc_pf', 'proposed'])
def test_ros_path_and_batch_runner_agree_exactly_with_swarms_and_lossy_relay(scheme):
    run_settings = settings(
        scheme=scheme,
        robots=6,
        targets=2,
        seed=5,
        max_time_s=300.0,
        loss_probability=0.2,
        target_positions_m=np.array([[1150.0, 1080.0], [900.0, 880.0]]),
    )
    ros, batch = run(run_settings), batch_of(run_settings)
    assert_same_run(ros, batch)
    # Robots moved apart from their start disc: swarms formed and searched or approached.
    assert np.hypot(*(batch.paths_m[-1] - batch.paths_m[0]).T).max() > 100.0


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'scheme': 'pso'}, 'unknown scheme'),
        ({'robots': 0}, '--robots'),
        ({'comm_range_m': 0.0}, '--comm-range'),
        ({'loss_probability': 1.5}, 'loss'),
    ],
)
def test_invalid_settings_are_rejected_before_anything_runs(overrides, message):
    with pytest.raises(ExperimentError, match=message):
        run(settings(**overrides))


def test_command_line_reports_bad_settings_with_exit_status_2(capsys):
    assert main(['--robots', '0', '--no-plots']) == 2
    assert '--robots' in capsys.readouterr().err


def test_command_line_parameters_reach_every_robot_node_typed():
    from swarm_experiments.spawn_msc_pf import controller_parameter_overrides, node_parameters

    extra = controller_parameter_overrides(
        ['msc.leader_rule=pbest', 'phases.unheard_updates=true', 'msc.inertia=1']
    )
    assert extra == {'msc.leader_rule': 'pbest', 'phases.unheard_updates': True, 'msc.inertia': 1.0}
    run_settings = settings(extra_parameters=extra)
    for index in range(run_settings.robots):
        params = node_parameters(run_settings, index)
        assert params['msc.leader_rule'] == 'pbest'
        assert params['robot_id'] == index


@pytest.mark.parametrize(
    ('option', 'message'),
    [
        (
            'msc.leader_rul=pbest',
            "unknown parameter 'msc.leader_rul' (did you mean msc.leader_rule?)",
        ),
        ('swarm.comm_range_m=50', "'swarm.comm_range_m' is set by the spawner"),
        ('msc.leader_rule=uphill', "msc.leader_rule: 'uphill' is not one of gradient, pbest"),
        ('phases.unheard_updates=maybe', 'expected true or false'),
    ],
)
def test_command_line_rejects_bad_parameters_with_exit_status_2(capsys, option, message):
    assert main(['--param', option, '--no-plots']) == 2
    assert message in capsys.readouterr().err
