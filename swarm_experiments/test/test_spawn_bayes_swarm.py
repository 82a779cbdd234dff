"""End to end: the spawner on the built-in runtime, bags, and agreement with the harness."""

import dataclasses
import math

import numpy as np
import pytest
from bayes_swarm.messages import DecisionKind
from bayes_swarm.settings import Arena, BayesSwarmConfig
from swarm_analysis.tau import tau_from_bag
from swarm_common.stamps import stamp_to_seconds
from swarm_experiments.bayes_batch import MissionSpec as HarnessSpec
from swarm_experiments.bayes_batch import run_mission as run_harness
from swarm_experiments.errors import ExperimentError
from swarm_experiments.spawn_bayes_swarm import SpawnSettings, batch_mission_spec, main, run
from swarm_runtime.bag import read_messages
from swarm_sim.signal_fields import get_case


def _recorder_available():
    try:
        from swarm_runtime.bag import BagRecorder  # noqa: F401
    except ImportError:
        return False
    return True


def _waypoints(result):
    return [[d.waypoint_m.tolist() for d in ds] for ds in result.decisions]


def test_case_2_decisions_follow_the_samples_and_never_the_true_source():
    """No ground truth leaks into the planners of the batch harness (Case 2, 10 robots).

    Moving only the declared source leaves every decision unchanged. Moving the field with
    its source keeps the first decisions (a fixed fan) and moves every robot's expected source
    (Eq. 5) at its second decision. (At t = 20 s of T_max = 1000 s alpha is about 0.04, so
    the second legs explore and mostly keep their direction.)
    """
    case = get_case('case2')

    def spec(signal_case):  # the world stops after 2 decisions each
        return dataclasses.replace(batch_mission_spec(signal_case), stop_time_s=21.0)

    base = run_harness(spec(case), 'bayes_swarm_p', 10, seed=0)
    decoy_case = dataclasses.replace(case, source_m=np.array([-20.0, -20.0]))
    decoy = run_harness(spec(decoy_case), 'bayes_swarm_p', 10, seed=0)
    moved = run_harness(spec(case.with_source_moved((-2.0, 1.0))), 'bayes_swarm_p', 10, seed=0)
    assert _waypoints(decoy) == _waypoints(base)
    for original, shifted in zip(base.decisions, moved.decisions, strict=True):
        assert len(original) == len(shifted) == 2
        np.testing.assert_array_equal(shifted[0].waypoint_m, original[0].waypoint_m)
        expected = original[1].expected_source_m
        assert np.hypot(*(shifted[1].expected_source_m - expected)) > 0.1


@pytest.fixture(scope='module')
def case1_run(tmp_path_factory):
    """One recorded Case 1 mission with plots (seed 2), shared by the tests below."""
    root = tmp_path_factory.mktemp('case1')
    return run(SpawnSettings(case='case1', seed=2, out_dir=root / 'plots', record=root / 'bag'))


@pytest.mark.slow
def test_case_1_spawn_finds_the_source(case1_run):
    result = case1_run
    assert result.found
    assert result.found_time_s < result.case.max_mission_time_s
    assert result.tau < 1.0
    assert {p.name for p in result.plots} == {'field_paths.png', f'{result.finder}_gp_mean.png'}
    finder = result.robot_nodes[int(result.finder[1:])]
    assert finder.decisions[0].kind is DecisionKind.FIRST
    assert all(t > 0.0 for t in result.decision_times_s[result.finder][1:])


@pytest.mark.slow
@pytest.mark.skipif(not _recorder_available(), reason='swarm_runtime.bag has no recorder node yet')
def test_a_recorded_case_1_bag_gives_the_same_tau(case1_run):
    result = case1_run
    bag = result.settings.record
    assert result.found
    from_bag = tau_from_bag(bag)
    assert from_bag.found
    assert from_bag.reported_tau == pytest.approx(result.tau)
    # /sim/poses is sampled at 2 Hz: the recomputed detection may lag by one sample.
    assert from_bag.found_time_s == pytest.approx(result.found_time_s, abs=0.5)
    assert from_bag.tau == pytest.approx(result.tau, abs=0.5 * 0.1 / math.sqrt(5.0))
    # The viewer topics: the source turns green when found; /tf at 10 Hz of 20 Hz odometry.
    targets = [item.message for item in read_messages(bag, topics=['/sim/markers/targets'])]
    assert len(targets) == 2
    first, last = (next(m for m in a.markers if m.ns == 'targets') for a in targets)
    source = get_case('case1').source_m
    assert (first.pose.position.x, first.pose.position.y) == pytest.approx(tuple(source))
    assert first.color.r > first.color.g
    assert last.color.g > last.color.r
    stamps = [
        stamp_to_seconds(item.message.transforms[0].header.stamp)
        for item in read_messages(bag, topics=['/tf'])
    ]
    assert np.diff(stamps) == pytest.approx(0.1, abs=1e-6)


@pytest.mark.slow
@pytest.mark.builtin_only(
    reason='bit-exact determinism: the first decisions equal the harness only when the '
    'messages arrive in the deterministic executor order'
)
def test_ros_path_and_harness_take_the_same_first_decisions():
    case = get_case('case1')
    spawned = run(SpawnSettings(case='case1', seed=3, max_mission_time_s=12.0))
    harness_spec = HarnessSpec(
        field=case.field,
        source_m=case.source_m,
        depots_m=case.depots_m,
        planner=BayesSwarmConfig(arena=Arena(*case.arena_m)),
    )
    harness = run_harness(harness_spec, 'bayes_swarm_p', 5, seed=3)
    for node, decisions in zip(spawned.robot_nodes, harness.decisions, strict=True):
        assert node.decisions[0].kind is DecisionKind.FIRST
        np.testing.assert_allclose(node.decisions[0].waypoint_m, decisions[0].waypoint_m)
        # Second decisions: the same planner on nearly the same data. ROS robots arrive a
        # few control ticks later, so a peer's latest samples may not have arrived yet.
        assert len(node.decisions) >= 2
        assert node.decisions[1].kind is decisions[1].kind
        assert abs(node.decisions[1].n_samples - decisions[1].n_samples) <= 5
    # r0 decides first in both runs, on its own first leg: the same decision.
    ros, sim = spawned.robot_nodes[0].decisions[1], harness.decisions[0][1]
    assert np.hypot(*(ros.expected_source_m - sim.expected_source_m)) < 0.15
    assert np.hypot(*(ros.waypoint_m - sim.waypoint_m)) < 0.1


@pytest.mark.slow
def test_levy_spawn_reports_a_failure_within_a_short_t_max():
    result = run(SpawnSettings(algorithm='levy', case='case1', seed=0, max_mission_time_s=5.0))
    assert not result.found
    assert math.isnan(result.tau)


def test_bad_settings_are_rejected_before_the_run(capsys):
    with pytest.raises(ExperimentError, match='unknown case'):
        run(SpawnSettings(case='case9'))
    with pytest.raises(ExperimentError, match='--comm-range'):
        run(SpawnSettings(comm_range_m=-1.0))
    with pytest.raises(ExperimentError, match='depots'):
        run(SpawnSettings(depots=np.array([[50.0, 50.0]])))
    assert main(['--case', 'case1', '--robots', '0', '--no-plots']) == 2
    assert 'robots' in capsys.readouterr().err


def test_command_line_parameters_override_the_case_for_every_robot():
    from swarm_experiments.spawn_bayes_swarm import node_parameter_overrides, node_parameters

    extra = node_parameter_overrides(['horizon_s=20', 'lipschitz=3'])
    assert extra == {'horizon_s': 20.0, 'lipschitz': 3.0}
    case = get_case('case1')
    settings = SpawnSettings(case='case1', extra_parameters=extra)
    for i in range(3):
        params = node_parameters(case, settings, 3, i)
        assert (params['horizon_s'], params['lipschitz']) == (20.0, 3.0)
        assert params['robot_index'] == i
    assert node_parameters(case, SpawnSettings(case='case1'), 3, 0)['horizon_s'] != 20.0


@pytest.mark.parametrize(
    ('option', 'message'),
    [
        ('horizn_s=3', "unknown parameter 'horizn_s' (did you mean horizon_s?)"),
        ('n_robots=4', "'n_robots' is set by the spawner"),
        ('horizon_s=-3', 'parameter horizon_s: must be > 0 s, got -3 s'),
    ],
)
def test_command_line_rejects_bad_parameters_with_exit_status_2(capsys, option, message):
    assert main(['--param', option, '--no-plots']) == 2
    assert message in capsys.readouterr().err
