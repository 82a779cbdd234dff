"""Evaluation value, avoidance, movement laws and step limiting."""

import numpy as np
import pytest
from msc_pf.mobility import (
    avoidance_vector,
    count_closer_heading_to,
    direct_approach_vector,
    evaluation_value,
    far_field_leader_vector,
    follower_slot,
    msc_follower_vector,
    rssi_gradient,
    step_displacement,
)
from msc_pf.settings import AvoidanceConfig, MscConfig


def test_evaluation_value_is_penalised_only_above_the_dispersion_threshold():
    assert evaluation_value(-70.0, 3, -100.0, 3) == -70.0
    assert evaluation_value(-70.0, 4, -100.0, 3) == -470.0


def test_count_closer_heading_counts_only_louder_neighbours():
    assert count_closer_heading_to(-70.0, [-60.0, -71.0, -69.9, -70.0]) == 2


def test_linear_avoidance_is_zero_beyond_the_safety_radius_and_pushes_away_inside():
    cfg = AvoidanceConfig()
    me = np.array([0.0, 0.0])
    assert not avoidance_vector(me, np.array([[3.5, 0.0]]), cfg).any()
    push = avoidance_vector(me, np.array([[1.5, 0.0]]), cfg)
    np.testing.assert_allclose(push, [-0.5, 0.0])
    assert not avoidance_vector(me, np.empty((0, 2)), cfg).any()


def test_inverse_square_avoidance_form_decays_with_distance_squared():
    cfg = AvoidanceConfig(form='inverse_square')
    me = np.array([0.0, 0.0])
    near = avoidance_vector(me, np.array([[0.0, 2.0]]), cfg)
    far = avoidance_vector(me, np.array([[0.0, 4.0]]), cfg)
    assert near[1] == pytest.approx(-0.25)
    assert far[1] == pytest.approx(near[1] / 4.0)


def test_eq8_vector_is_the_goal_offset_plus_weighted_avoidance():
    v = direct_approach_vector(
        np.array([0.0, 0.0]), np.array([30.0, 40.0]), np.array([0.1, 0.0]), 20.0
    )
    np.testing.assert_allclose(v, [32.0, 40.0])


def test_goal_steps_stop_at_the_goal_and_other_steps_use_full_speed():
    np.testing.assert_allclose(step_displacement(np.array([0.3, 0.4]), 1.0, True), [0.3, 0.4])
    np.testing.assert_allclose(step_displacement(np.array([0.3, 0.4]), 1.0, False), [0.6, 0.8])
    np.testing.assert_allclose(step_displacement(np.array([30.0, 40.0]), 1.0, True), [0.6, 0.8])
    assert not step_displacement(np.array([1e-9, 0.0]), 1.0, False).any()


def test_far_field_leader_heads_to_the_best_particle():
    v = far_field_leader_vector(np.array([0.0, 0.0]), np.array([0.0, 50.0]), np.zeros(2), 20.0)
    np.testing.assert_allclose(v, [0.0, 1.0])


def test_follower_slots_alternate_left_and_right_of_the_leader_heading():
    leader, heading = np.array([100.0, 100.0]), np.array([1.0, 0.0])
    np.testing.assert_allclose(follower_slot(leader, heading, 0, 20.0), [100.0, 120.0])
    np.testing.assert_allclose(follower_slot(leader, heading, 1, 20.0), [100.0, 80.0])
    np.testing.assert_allclose(follower_slot(leader, heading, 2, 20.0), [100.0, 140.0])


def test_follower_is_pulled_toward_the_best_neighbour():
    rng = np.random.default_rng(0)
    v = msc_follower_vector(
        np.zeros(2), np.array([0.0, 0.0]), np.array([10.0, 0.0]), np.zeros(2), MscConfig(), rng
    )
    assert v[0] > 0.0
    assert v[1] == 0.0


def test_rssi_gradient_recovers_the_slope_of_a_plane():
    rng = np.random.default_rng(1)
    points = rng.uniform(0.0, 20.0, (30, 2))
    values = -80.0 + 0.3 * points[:, 0] - 0.1 * points[:, 1]
    np.testing.assert_allclose(rssi_gradient(points, values), [0.3, -0.1], atol=1e-9)


def test_rssi_gradient_is_zero_for_collinear_samples():
    points = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])
    assert not rssi_gradient(points, np.array([1.0, 2.0, 3.0, 4.0])).any()
