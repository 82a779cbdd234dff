"""Batch simulator of the MSC + PF mission: end-to-end captures, determinism."""

import math

import numpy as np
import pytest
from msc_pf.schemes import Scheme
from swarm_experiments.msc_pf_batch import BatchScenario, run_batch

TARGETS = np.array([[1150.0, 1080.0], [820.0, 900.0]])


def scenario_with(scheme, **overrides):
    settings = {
        'scheme': scheme,
        'n_robots': 4,
        'n_targets': 2,
        'seed': 7,
        'max_time_s': 2000.0,
        'target_positions_m': TARGETS,
    }
    settings.update(overrides)
    return BatchScenario(**settings)


@pytest.mark.slow
def test_proposed_scheme_captures_every_target_deterministically():
    scenario = scenario_with(Scheme.PROPOSED)
    first, second = run_batch(scenario), run_batch(scenario)
    assert np.all(np.isfinite(first.capture_times_s))
    np.testing.assert_array_equal(first.capture_times_s, second.capture_times_s)
    # At 1 m/s the two targets (~180 m out, on opposite sides) need more than ~360 s.
    assert first.cct_s > 360.0


@pytest.mark.slow
def test_msc_pf_scheme_captures_targets_within_earshot_of_each_other():
    # MSC+PF forgets its estimates after a capture, so the second target must be audible
    # (< 292 m) from the first.
    near = np.array([[1150.0, 1080.0], [1000.0, 1250.0]])
    result = run_batch(scenario_with(Scheme.MSC_PF, target_positions_m=near))
    assert np.all(np.isfinite(result.capture_times_s))


@pytest.mark.slow
def test_msc_captures_a_near_target():
    scenario = scenario_with(
        Scheme.MSC,
        n_robots=3,
        n_targets=1,
        seed=1,
        max_time_s=1000.0,
        target_positions_m=np.array([[1150.0, 1000.0]]),
    )
    result = run_batch(scenario)
    assert 130.0 < result.cct_s < 600.0


def test_recorded_paths_start_in_the_disc_and_move_at_most_one_metre_per_step():
    scenario = scenario_with(
        Scheme.MSC,
        n_targets=1,
        seed=2,
        max_time_s=60.0,
        target_positions_m=np.array([[100.0, 100.0]]),
    )
    result = run_batch(scenario, record=True)
    paths = result.paths_m
    assert paths.shape == (61, 4, 2)
    assert np.hypot(*(paths[0] - 1000.0).T).max() <= 30.0
    steps = np.hypot(*np.diff(paths, axis=0).transpose(2, 0, 1))
    assert steps.max() <= 1.0 + 1e-9
    assert math.isnan(result.cct_s)


def plain_run(scenario):
    """Spec 0.2's loop written out robot by robot: the oracle for run_batch's fast paths."""
    from msc_pf.robot import RobotController
    from swarm_sim.rssi_targets import RssiTargetConfig, RssiTargetField, place_robots

    config = scenario.controller
    config = type(config)(**{**vars(config), 'scheme': scenario.scheme})
    rng = np.random.default_rng([scenario.seed, 0])
    world = RssiTargetField(
        RssiTargetConfig(n_targets=scenario.n_targets, task_area_m=config.phases.task_area_m),
        scenario.target_positions_m,
    )
    half = config.field_size_m / 2.0
    xy = place_robots(scenario.n_robots, (half, half), scenario.start_radius_m, rng)
    robots = [RobotController(i, config, scenario.seed) for i in range(scenario.n_robots)]
    mail = {i: [] for i in range(scenario.n_robots)}
    told = {i: [] for i in range(scenario.n_robots)}
    t = 0.0
    while not world.all_captured and t < scenario.max_time_s:
        t += 1.0
        rssi = world.sample_rssi(xy, rng)
        sent = []
        for i, robot in enumerate(robots):
            readings = {}
            for target in range(scenario.n_targets):
                if not math.isnan(rssi[i, target]):
                    readings[target] = float(rssi[i, target])
            sent.append(robot.step(t, xy[i], readings, mail[i], told[i], with_estimates=False))
        steps = np.array([s.displacement_m for s in sent])
        moved = np.clip(xy + steps, 0.0, half * 2.0)
        speeds = np.linalg.norm(steps, axis=1)
        told = {i: [] for i in range(scenario.n_robots)}
        for capture in world.work(moved, speeds, 1.0, t):
            for i in capture.robot_indices:
                told[i].append(capture.target_id)
        for i in range(scenario.n_robots):
            mail[i] = [
                sent[j].broadcast
                for j in range(scenario.n_robots)
                if j != i and math.dist(xy[i], xy[j]) <= config.swarm.comm_range_m
            ]
        xy = moved
    return world.capture_time_s, xy


@pytest.mark.slow
@pytest.mark.parametrize('scheme', list(Scheme))
def test_batch_run_matches_the_plain_robot_by_robot_loop(scheme):
    scenario = scenario_with(scheme, n_robots=5, max_time_s=700.0)
    result = run_batch(scenario, record=True)
    capture_times, final_xy = plain_run(scenario)
    np.testing.assert_array_equal(result.capture_times_s, capture_times)
    np.testing.assert_array_equal(result.paths_m[-1], final_xy)


def test_search_coverage_grows_as_the_swarm_moves_and_repeats_from_its_seed():
    from swarm_experiments.msc_pf_batch import search_coverage

    def run():
        return search_coverage(3, 5, max_time_s=400.0, fractions=(0.05, 0.1, 1.0))

    first = run()
    # At the first check the robots' 292 m earshot around the centre already covers
    # pi 292^2 / 2000^2 = 6.7 % of the field; 10 % needs a few hundred metres of travel,
    # the whole field far more than 400 s.
    assert first.times_s[0] == 10.0
    assert 10.0 < first.times_s[1] < 400.0
    assert math.isnan(first.times_s[2])
    assert first.duration_s == 400.0
    assert run() == first


@pytest.mark.parametrize('fractions', [(), (0.9, 0.5), (0.5, 0.5), (0.5, 1.5), (0.0,), (-0.1, 0.5)])
def test_search_coverage_rejects_fractions_that_do_not_ascend_within_0_1(fractions):
    from swarm_experiments.msc_pf_batch import search_coverage

    with pytest.raises(ValueError, match='fractions'):
        search_coverage(2, 0, max_time_s=10.0, fractions=fractions)


def test_search_coverage_ends_the_run_once_the_last_share_is_reached():
    from swarm_experiments.msc_pf_batch import search_coverage

    coverage = search_coverage(3, 5, max_time_s=400.0, fractions=(0.05,))
    assert coverage.times_s == (10.0,)
    assert coverage.duration_s == 10.0


def test_a_scenario_without_targets_searches_until_max_time():
    result = run_batch(BatchScenario(n_robots=2, n_targets=0, seed=1, max_time_s=30.0))
    assert result.duration_s == 30.0
    assert math.isnan(result.cct_s)
    assert result.capture_times_s.shape == (0,)


def test_first_heard_times_mark_the_first_step_a_target_was_within_earshot():
    # One target 150 m from the start disc (heard at once), one 1270 m away (never, in 5 s).
    scenario = scenario_with(
        Scheme.MSC,
        max_time_s=5.0,
        target_positions_m=np.array([[1150.0, 1000.0], [100.0, 100.0]]),
    )
    result = run_batch(scenario)
    assert result.first_heard_s[0] == 1.0
    assert math.isnan(result.first_heard_s[1])
    assert math.isnan(result.first_heard_range_m[1])


def test_first_heard_range_is_the_distance_of_the_nearest_robot_that_heard():
    # Every robot of the start disc is 120-180 m from the first target (RSSI about -93 dBm,
    # 8 dB above the detection threshold), so all hear it at the first step, where they stand.
    scenario = scenario_with(
        Scheme.MSC,
        max_time_s=3.0,
        target_positions_m=np.array([[1150.0, 1000.0], [100.0, 100.0]]),
    )
    result = run_batch(scenario, record=True)
    start = result.paths_m[0]
    nearest = np.hypot(*(start - result.target_positions_m[0]).T).min()
    assert result.first_heard_range_m[0] == pytest.approx(nearest)
    assert 120.0 <= result.first_heard_range_m[0] <= 180.0
