"""MSC + PF spawner on the built-in runtime: capture, bag CCT, agreement with the batch sim."""

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

TARGET = np.array([[1100.0, 1060.0]])


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
    return run(settings(tmp_path_factory.mktemp('spawn')))


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


@pytest.mark.slow
def test_ros_path_and_batch_simulator_agree_on_a_simple_scenario(ros_run):
    batch = run_batch(
        BatchScenario(
            scheme=Scheme.PROPOSED,
            n_robots=3,
            n_targets=1,
            seed=3,
            max_time_s=600.0,
            target_positions_m=TARGET,
        )
    )
    assert math.isfinite(batch.cct_s)
    # Same controllers and start; the ROS robots steer a unicycle and see the world through
    # topics a step later, so the CCTs differ by turning and latency only.
    assert abs(ros_run.cct_s - batch.cct_s) <= max(30.0, 0.25 * batch.cct_s)


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'scheme': 'pso'}, 'unknown scheme'),
        ({'robots': 0}, '--robots'),
        ({'comm_range_m': 0.0}, 'comm_range_m'),
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
