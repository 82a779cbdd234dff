"""Batch simulator of the MSC + PF mission: end-to-end captures, determinism."""

import math

import numpy as np
import pytest
from msc_pf.schemes import Scheme
from swarm_experiments.msc_pf_batch import BatchScenario, run_batch

pytestmark = pytest.mark.runtime_independent(reason='the batch runner, no node')

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


def test_recorded_paths_start_in_the_disc_and_move_at_most_one_metre_per_period():
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
