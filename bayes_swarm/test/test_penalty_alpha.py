"""Local penalty (Eqs. 8-11) and the adaptive exploitation weight (Algorithm 2)."""

import math

import numpy as np
import pytest
from bayes_swarm.alpha import AlphaBranch, exploitation_weight, scheduled_alpha
from bayes_swarm.penalty import local_penalty, log_local_penalty

PEER = np.array([[1.0, 1.0]])


def penalty(points, mean=0.4, std=0.05, max_signal=1.2, lipschitz=2.0):
    return local_penalty(
        np.asarray(points, float),
        PEER,
        np.array([mean]),
        np.array([std]),
        max_signal=max_signal,
        lipschitz=lipschitz,
    )


def test_penalty_is_near_zero_at_a_peers_planned_waypoint_and_near_one_far_away():
    near, far = penalty([[1.0, 1.0], [2.5, 2.5]])
    assert near < 1e-6
    assert far > 0.999


def test_penalty_grows_with_the_distance_to_the_peer():
    values = penalty([[1.0 + d, 1.0] for d in np.linspace(0, 1, 11)])
    assert np.all(np.diff(values) >= 0)


def test_penalty_is_one_half_at_the_ball_radius():
    radius = (1.2 - 0.4) / 2.0
    assert penalty([[1.0 + radius, 1.0]])[0] == pytest.approx(0.5)


def test_penalty_multiplies_over_peers_and_is_one_without_peers():
    pts = np.array([[1.2, 1.0]])
    single = penalty(pts)[0]
    double = local_penalty(
        pts,
        np.vstack([PEER, PEER]),
        np.array([0.4, 0.4]),
        np.array([0.05, 0.05]),
        max_signal=1.2,
        lipschitz=2.0,
    )[0]
    assert double == pytest.approx(single**2)
    assert local_penalty(pts, np.zeros((0, 2)), [], [], max_signal=1.2, lipschitz=2.0)[0] == 1.0


def test_log_penalty_is_the_log_of_the_penalty_and_stays_finite_where_it_underflows():
    pts = np.array([[1.0 + d, 1.0] for d in np.linspace(0.0, 1.5, 16)])
    peers = np.array([[1.0, 1.0], [1.3, 0.8]])
    args = (pts, peers, np.array([0.4, 0.1]), np.array([0.05, 0.2]))
    kwargs = {'max_signal': 1.2, 'lipschitz': 2.0}
    gamma = local_penalty(*args, **kwargs)
    log_gamma = log_local_penalty(*args, **kwargs)
    resolved = gamma > 1e-200
    np.testing.assert_allclose(log_gamma[resolved], np.log(gamma[resolved]), rtol=1e-10, atol=1e-14)
    # Forty-seven peers deep inside their balls: the product underflows to 0, its log does
    # not, and it still ranks the points (further from the peers is less penalized).
    crowd = np.repeat(PEER, 47, axis=0)
    inside = np.array([[1.0, 1.0], [1.05, 1.0], [1.1, 1.0]])
    crowd_args = (inside, crowd, np.full(47, 0.0), np.full(47, 1e-3))
    assert np.all(local_penalty(*crowd_args, **kwargs) == 0.0)
    logs = log_local_penalty(*crowd_args, **kwargs)
    assert np.all(np.isfinite(logs))
    assert np.all(np.diff(logs) > 0)
    assert log_local_penalty(pts[:1], np.zeros((0, 2)), [], [], **kwargs)[0] == 0.0


def test_negated_maximum_as_m_makes_the_penalty_inert():
    # The authors' code passes M = -max(mu): every factor is then ~1 even at the waypoint.
    assert penalty([[1.0, 1.0]], max_signal=-1.0)[0] > 0.999


def test_schedule_is_one_half_at_a_third_of_t_max_and_near_point_97_at_70_percent():
    assert scheduled_alpha(100.0, 300.0) == pytest.approx(0.5)
    assert scheduled_alpha(70.0, 100.0) == pytest.approx(1 / (1 + math.exp(-10 * (0.7 - 1 / 3))))
    assert scheduled_alpha(70.0, 100.0) == pytest.approx(0.975, abs=0.005)
    assert scheduled_alpha(0.0, 100.0) == pytest.approx(1 / (1 + math.exp(10 / 3)))


def test_time_scale_reproduces_the_authors_faster_schedule():
    assert scheduled_alpha(10.0, 100.0, time_scale=0.1) == pytest.approx(0.9987, abs=1e-4)


def weight(peers, weaker, t=20.0, weaker_radius=None):
    return exploitation_weight(
        np.array([1.0, 2.0]),
        np.asarray(peers, float).reshape(-1, 2),
        np.asarray(weaker, float).reshape(-1, 2),
        robot_size_m=0.1,
        time_s=t,
        max_mission_time_s=100.0,
        weaker_source_radius_m=weaker_radius,
    )


def test_alpha_is_low_when_the_expected_source_is_a_known_weaker_source():
    result = weight([[1.0, 2.0]], [[1.1, 2.0]])
    assert (result.value, result.branch) == (0.1, AlphaBranch.WEAKER_SOURCE)


def test_a_weaker_source_radius_replaces_the_squared_distance_test():
    # 0.3 m away: squared distance 0.09 < 2 l_robot = 0.2, so the paper's test holds it down.
    assert weight([], [[1.3, 2.0]]).branch is AlphaBranch.WEAKER_SOURCE
    assert weight([], [[1.3, 2.0]], weaker_radius=0.15).branch is AlphaBranch.NO_PEER_NEAR
    assert weight([], [[1.1, 2.0]], weaker_radius=0.15).branch is AlphaBranch.WEAKER_SOURCE
    # The peers' test keeps the paper's threshold.
    peer = weight([[1.3, 2.0]], [], t=50.0, weaker_radius=0.15)
    assert peer.branch is AlphaBranch.SCHEDULE


def test_alpha_is_point_eight_when_no_peer_heads_to_the_expected_source():
    result = weight([[2.0, 0.5]], [])
    assert (result.value, result.branch) == (0.8, AlphaBranch.NO_PEER_NEAR)
    assert weight([], []).value == 0.8


def test_alpha_follows_the_schedule_when_a_peer_heads_to_the_expected_source():
    result = weight([[1.2, 2.1]], [], t=50.0)  # squared distance 0.05 < 2 l_robot
    assert result.branch is AlphaBranch.SCHEDULE
    assert result.value == pytest.approx(scheduled_alpha(50.0, 100.0))
