"""Signal mission model: observation clock, noise, continuous detection and tau."""

import math

import numpy as np
import pytest
from swarm_sim.signal_fields import get_case
from swarm_sim.signal_mission import SignalMissionModel


def test_samples_are_published_on_the_observation_clock():
    model = SignalMissionModel(get_case('case1'))
    ticks = []
    for k in range(61):  # 3 s at 20 Hz
        batch = model.step(k * 0.05, np.zeros((2, 2)))
        if batch is not None:
            ticks.append(batch.time_s)
    assert ticks == pytest.approx([0.0, 1.0, 2.0, 3.0])


def test_noise_free_samples_equal_the_field_and_noise_has_the_requested_spread():
    case = get_case('case1')
    pts = np.array([[0.5, 0.5], [1.0, 2.0]])
    exact = SignalMissionModel(case).step(0.0, pts)
    np.testing.assert_allclose(exact.values, case.field(pts))
    noisy = SignalMissionModel(case, noise_std=0.1, seed=3)
    draws = np.array([noisy.sample(pts) for _ in range(4000)])
    assert np.std(draws[:, 0]) == pytest.approx(0.1, rel=0.05)
    assert np.mean(draws[:, 0]) == pytest.approx(case.field(pts)[0], abs=0.01)


def test_detection_is_found_between_physics_steps_and_gives_tau():
    case = get_case('case1')
    model = SignalMissionModel(case)
    direction = case.source_m / np.hypot(*case.source_m)
    model.step(0.0, np.zeros((2, 2)))
    # One long step straight through the source: detection at the eps boundary.
    model.step(30.0, np.array([[0.0, 0.0], 2.5 * direction]))
    entry = (np.hypot(*case.source_m) - case.detection_radius_m) / np.hypot(*(2.5 * direction))
    assert model.found
    assert model.finder == 1
    assert model.found_time_s == pytest.approx(30.0 * entry)
    ideal = np.hypot(*case.source_m) / case.velocity_mps
    assert model.tau() == pytest.approx((model.found_time_s - ideal) / ideal)
    assert model.done


def test_mission_ends_at_t_max_without_a_detection():
    model = SignalMissionModel(get_case('case1'), max_mission_time_s=5.0)
    model.step(0.0, np.zeros((1, 2)))
    assert not model.done
    model.step(5.0, np.zeros((1, 2)))
    assert model.done
    assert not model.found
    assert math.isnan(model.tau())


def test_negative_noise_is_rejected():
    with pytest.raises(ValueError, match='noise'):
        SignalMissionModel(get_case('case1'), noise_std=-1.0)
