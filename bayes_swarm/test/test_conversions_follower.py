"""Message translations (round trips), the waypoint follower and the parameter table."""

import math

import numpy as np
import pytest
from bayes_swarm.conversions import (
    decision_to_state,
    glowworm_peer_from_ros,
    glowworm_peer_to_ros,
    odometry_to_pose,
    peer_update_from_ros,
    peer_update_to_ros,
    seconds_to_stamp,
    stamp_to_seconds,
    twist,
)
from bayes_swarm.errors import ConfigError, ObservationError
from bayes_swarm.follower import FollowerConfig, WaypointFollower
from bayes_swarm.messages import Decision, DecisionKind, PeerUpdate
from bayes_swarm.node_settings import settings_from_values
from swarm_common.angles import yaw_from_unit_quaternion
from swarm_runtime.ros import message_module
from swarm_runtime.testing import cdr_roundtrip


def test_peer_update_survives_a_cdr_round_trip():
    update = PeerUpdate(
        sender='r2',
        decision_index=4,
        position_m=np.array([0.5, 0.25]),
        waypoint_m=np.array([1.5, 1.0]),
        sample_points_m=np.array([[0.1, 0.2], [0.3, 0.4]]),
        sample_values=np.array([0.7, 0.8]),
        weaker_sources_m=np.array([[2.0, 0.5]]),
    )
    back = peer_update_from_ros(cdr_roundtrip(peer_update_to_ros(update, 12.5)))
    assert back.sender == 'r2'
    assert back.decision_index == 4
    np.testing.assert_array_equal(back.position_m, update.position_m)
    np.testing.assert_array_equal(back.waypoint_m, update.waypoint_m)
    np.testing.assert_array_equal(back.sample_points_m, update.sample_points_m)
    np.testing.assert_array_equal(back.sample_values, update.sample_values)
    np.testing.assert_array_equal(back.weaker_sources_m, update.weaker_sources_m)


def test_empty_peer_update_round_trips_with_empty_arrays():
    update = PeerUpdate('r0', 0, np.zeros(2), np.ones(2))
    back = peer_update_from_ros(cdr_roundtrip(peer_update_to_ros(update, 0.0)))
    assert back.sample_points_m.shape == (0, 2)
    assert back.weaker_sources_m.shape == (0, 2)


def test_peer_message_with_mismatched_arrays_is_rejected():
    msg = message_module('swarm_interfaces').BayesSwarmPeer(
        robot='r1', sample_x=[1.0, 2.0], sample_y=[1.0], sample_value=[0.5, 0.6]
    )
    with pytest.raises(ObservationError, match='r1'):
        peer_update_from_ros(msg)


def test_state_message_carries_the_decision_and_nan_for_the_first_one():
    first = Decision(np.array([1.0, 0.3]), 0, DecisionKind.FIRST)
    msg = cdr_roundtrip(decision_to_state('r1', 'bayes_swarm_p', np.zeros(2), first, 3.0))
    assert msg.decision_kind == 'first'
    assert math.isnan(msg.expected_source_x)
    assert math.isnan(msg.alpha)
    later = Decision(
        np.array([1.0, 0.3]), 2, DecisionKind.ACQUISITION, 0.8, np.array([2.0, 1.0]), 30, 0.004
    )
    msg = decision_to_state('r1', 'bayes_swarm_p', np.zeros(2), later, 3.0)
    assert (msg.expected_source_x, msg.alpha, msg.n_samples) == (2.0, 0.8, 30)
    assert msg.decision_time_s == pytest.approx(0.004)


def test_glowworm_peer_round_trip():
    msg = cdr_roundtrip(glowworm_peer_to_ros('r4', 9, np.array([1.0, 2.0]), 5.5, 1.0))
    sender, index, position, luciferin = glowworm_peer_from_ros(msg)
    assert (sender, index, luciferin) == ('r4', 9, 5.5)
    np.testing.assert_array_equal(position, [1.0, 2.0])


def test_stamps_convert_both_ways():
    stamp = seconds_to_stamp(12.25)
    assert (stamp.sec, stamp.nanosec) == (12, 250_000_000)
    assert stamp_to_seconds(stamp) == 12.25


def test_odometry_yaw_comes_from_the_quaternion():
    nav = message_module('nav_msgs')
    msg = nav.Odometry()
    msg.pose.pose.position.x = 1.0
    msg.pose.pose.orientation.z = math.sin(0.6 / 2)
    msg.pose.pose.orientation.w = math.cos(0.6 / 2)
    x, y, yaw = odometry_to_pose(msg)
    assert (x, y) == (1.0, 0.0)
    assert yaw == pytest.approx(0.6)
    assert twist(0.1, -0.2).angular.z == -0.2


def test_follower_turns_in_place_first_then_drives_and_stops_on_arrival():
    follower = WaypointFollower(FollowerConfig(speed_mps=0.1))
    behind = follower.command(0.0, 0.0, 0.0, -1.0, 0.1)
    assert behind.linear_mps == 0.0
    assert behind.angular_radps == pytest.approx(2.0)  # clipped turn rate
    ahead = follower.command(0.0, 0.0, 0.0, 1.0, 0.05)
    assert ahead.linear_mps == pytest.approx(0.1, rel=0.01)
    assert ahead.angular_radps > 0.0
    assert follower.command(1.0, 0.0, 0.0, 1.005, 0.0).arrived


def test_follower_slows_down_near_the_waypoint():
    follower = WaypointFollower(FollowerConfig(speed_mps=1.0, slow_down_m=0.1))
    assert follower.command(0.0, 0.0, 0.0, 0.05, 0.0).linear_mps == pytest.approx(0.5)


def test_parameter_defaults_give_the_papers_case_1_settings():
    settings = settings_from_values({})
    assert settings.algorithm == 'bayes_swarm_p'
    assert settings.planner.max_leg_m == pytest.approx(1.0)
    assert settings.planner.penalty_enabled
    assert not settings_from_values({'algorithm': 'bayes_swarm_o'}).planner.penalty_enabled
    follower = settings_from_values({'velocity_mps': 0.2}).follower
    assert (follower.speed_mps, follower.slow_down_m) == (0.2, pytest.approx(0.02))


@pytest.mark.parametrize(
    ('values', 'match'),
    [
        ({'algorithm': 'ants'}, 'algorithm'),
        ({'n_max': 0}, 'n_max: must be >= 1'),
        ({'detection_radius_m': -0.05}, 'detection_radius_m'),
        ({'control_rate_hz': 0.0}, 'control_rate_hz'),
        ({'speed': 1.0}, "unknown parameter 'speed'"),
    ],
)
def test_invalid_parameters_are_rejected_at_start(values, match):
    with pytest.raises(ConfigError, match=match):
        settings_from_values(values)


@pytest.mark.parametrize(
    'quaternion',
    [(0, 0, 0, 0), (0, 0, 1e-300, 1e-300), (math.nan, 0, 0, 1), (0, 0, math.inf, 1)],
)
def test_odometry_without_an_orientation_is_rejected(quaternion):
    msg = message_module('nav_msgs').Odometry()
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = (float(v) for v in quaternion)
    with pytest.raises(ObservationError):
        odometry_to_pose(msg)


def test_a_slightly_non_unit_odometry_quaternion_is_read_as_if_normalised():
    msg = message_module('nav_msgs').Odometry()
    o = msg.pose.pose.orientation
    for scale in (0.95, 1.05, 1.0 + 1e-7):
        o.z, o.w = scale * math.sin(0.4), scale * math.cos(0.4)
        assert odometry_to_pose(msg)[2] == pytest.approx(0.8)
    o.z, o.w = 0.0, 1.09
    assert odometry_to_pose(msg)[2] == 0.0
    for yaw in np.linspace(-3.1, 3.1, 41):
        o.z, o.w = math.sin(yaw / 2), math.cos(yaw / 2)
        assert odometry_to_pose(msg)[2] == yaw_from_unit_quaternion(0.0, 0.0, o.z, o.w)


@pytest.mark.parametrize('quaternion', [(0, 0, 1, 1), (0, 0, 0, 5), (0, 0, 0.5, 0.5)])
def test_an_odometry_quaternion_far_from_unit_is_rejected_as_the_msc_node_rejects_it(quaternion):
    # A norm of sqrt(2), 5 or 1 / sqrt(2): no integrator drifts that far; a broken publisher.
    msg = message_module('nav_msgs').Odometry()
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = (float(v) for v in quaternion)
    with pytest.raises(ObservationError, match='norm'):
        odometry_to_pose(msg)
