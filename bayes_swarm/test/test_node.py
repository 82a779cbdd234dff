"""The node through its topics: fail-safe stop, bad samples, duplicated peer messages.

Runs on either runtime (real DDS with rclpy): inputs go out once the graph has matched.
"""

import math

import numpy as np
import pytest
from bayes_swarm.conversions import glowworm_peer_to_ros, peer_update_to_ros
from bayes_swarm.messages import PeerUpdate
from bayes_swarm.node import BayesSwarmNode
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data
from swarm_runtime.testing import NodeTestBed

nav = message_module('nav_msgs')
geometry = message_module('geometry_msgs')
swarm = message_module('swarm_interfaces')


@pytest.fixture
def graph():
    with NodeTestBed() as bed:
        node = bed.add_node(
            BayesSwarmNode, namespace='/r0', parameter_overrides=[Parameter('robot_index', value=0)]
        )
        commands = bed.probe.collect('/r0/cmd_vel', geometry.Twist)
        sensor_qos = qos_profile_sensor_data
        pubs = {
            'odom': bed.probe.player('/r0/odom', nav.Odometry, sensor_qos),
            'signal': bed.probe.player('/r0/signal', swarm.SignalSample, sensor_qos),
            'peers': bed.probe.player('/r0/peers/in', swarm.BayesSwarmPeer, 10),
        }
        bed.wait_for_graph()
        yield node, pubs, commands, bed


def odom(x=0.0, y=0.0):
    msg = nav.Odometry()
    msg.pose.pose.position.x = x
    msg.pose.pose.position.y = y
    msg.pose.pose.orientation.w = 1.0
    return msg


def test_node_decides_with_fresh_odometry_and_stops_when_it_goes_stale(graph):
    node, pubs, commands, bed = graph
    pubs['odom'].publish(odom())
    assert bed.spin_until(lambda: node.decisions)
    assert bed.spin_until(lambda: any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in commands))
    assert len(node.decisions) == 1
    timeout_s = node.settings.odom_timeout_s
    assert bed.spin_until(
        lambda: commands[-1].linear.x == 0.0 and commands[-1].angular.z == 0.0,
        timeout_s=timeout_s + 2.0,
    ), 'no odometry for longer than odom_timeout_s: stop'
    bed.spin_for(0.3)
    assert commands[-1].linear.x == 0.0
    assert commands[-1].angular.z == 0.0


def test_non_finite_signal_samples_are_dropped_and_finite_ones_kept(graph):
    node, pubs, _, bed = graph
    pubs['odom'].play(odom(0.2, 0.1))
    assert bed.spin_until(lambda: node.decisions)
    for value in (0.5, math.nan, math.inf, 0.6):
        pubs['signal'].publish(swarm.SignalSample(value=value))
    assert bed.spin_until(lambda: node.planner.n_observations >= 2)
    bed.spin_for(0.2)
    assert node.planner.n_observations == 2


def test_duplicated_and_stale_peer_messages_are_ignored(graph):
    node, pubs, _, bed = graph
    update = PeerUpdate('r1', 2, np.zeros(2), np.ones(2), np.array([[0.1, 0.1]]), np.array([0.3]))
    msg = peer_update_to_ros(update, 1.0)
    pubs['peers'].publish(msg)
    pubs['peers'].publish(msg)
    msg.decision_index = 1
    pubs['peers'].publish(msg)
    assert bed.spin_until(lambda: 'r1' in node.planner.peer_waypoints)
    bed.spin_for(0.2)
    assert node.planner.n_observations == 1
    assert node.planner.peer_waypoints['r1'] == pytest.approx([1.0, 1.0])


def test_odometry_with_a_zero_quaternion_is_dropped_so_the_robot_stops(graph):
    node, pubs, commands, bed = graph
    pubs['odom'].publish(odom())
    assert bed.spin_until(lambda: node.decisions)
    assert bed.spin_until(lambda: any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in commands))
    bad = odom()
    bad.pose.pose.orientation.w = 0.0
    deadline_s = node.settings.odom_timeout_s + 2.0
    stopped = False
    while not stopped and deadline_s > 0.0:
        pubs['odom'].publish(bad)
        bed.spin_for(0.1)
        deadline_s -= 0.1
        stopped = commands[-1].linear.x == 0.0 and commands[-1].angular.z == 0.0
    assert stopped, 'only orientation-less odometry arrives: it goes stale and the robot stops'
    assert node.rejected_odometry >= 1


def test_peer_messages_with_absurd_contents_are_dropped_and_counted(graph):
    node, pubs, _, bed = graph
    update = PeerUpdate('r1', 2, np.zeros(2), np.ones(2), np.array([[0.1, 0.1]]), np.array([0.3]))
    far = peer_update_to_ros(update, 1.0)
    far.waypoint_x = far.waypoint_y = 1e300
    pubs['peers'].publish(far)
    assert bed.spin_until(lambda: node.rejected_peer_messages == 1)
    absurd = peer_update_to_ros(update, 1.0)
    absurd.sample_value = [-1e300]
    pubs['peers'].publish(absurd)
    assert bed.spin_until(lambda: 'r1' in node.planner.peer_waypoints)
    assert node.planner.n_observations == 0
    assert node.planner.peer_waypoints['r1'] == pytest.approx([1.0, 1.0])


def test_a_glowworm_robot_broadcasts_and_steps_toward_a_brighter_peer():
    # After its dispersal leg the node's Glowworm timer publishes its luciferin and heads
    # for the brighter peer it heard.
    overrides = [
        Parameter('algorithm', value='glowworm'),
        Parameter('robot_index', value=0),
        Parameter('n_robots', value=2),
    ]
    with NodeTestBed() as bed:
        node = bed.add_node(BayesSwarmNode, namespace='/r0', parameter_overrides=overrides)
        sent = bed.probe.collect('/r0/peers/out', swarm.GlowwormPeer)
        sensor_qos = qos_profile_sensor_data
        odometry = bed.probe.player('/r0/odom', nav.Odometry, sensor_qos, period_s=0.05)
        signal = bed.probe.player('/r0/signal', swarm.SignalSample, sensor_qos, period_s=0.05)
        peers = bed.probe.player('/r0/peers/in', swarm.GlowwormPeer, 10, period_s=0.05)
        bed.wait_for_graph()
        odometry.play(odom(1.0, 1.0))
        assert bed.spin_until(lambda: node.decisions)
        x, y = node.controller.waypoint_m
        odometry.play(odom(float(x), float(y)))  # arrived: the dispersal leg is over
        peers.play(glowworm_peer_to_ros('r1', 1, np.array([x + 0.5, y]), 100.0, 1.0))
        signal.play(swarm.SignalSample(value=1.0))
        assert bed.spin_until(lambda: sent and node.controller.waypoint_m[0] > x + 0.01)
        first = sent[0]
        assert first.robot == 'r0'
        assert (first.position_x, first.position_y) == pytest.approx((x, y))
        assert first.luciferin == pytest.approx(0.6 * 5.0 + 0.6 * 1.0)
        assert node.controller.waypoint_m[1] == pytest.approx(y)
