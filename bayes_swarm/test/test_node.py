"""The node on the built-in runtime: fail-safe stop, bad samples, duplicated peer messages."""

import math

import numpy as np
import pytest
from bayes_swarm.conversions import peer_update_to_ros
from bayes_swarm.messages import PeerUpdate
from bayes_swarm.node import BayesSwarmNode
from swarm_runtime.messages import get_message_module
from swarm_runtime.ros import Parameter, SingleThreadedExecutor, rclpy, using_real_rclpy

pytestmark = pytest.mark.skipif(using_real_rclpy(), reason='drives the built-in runtime')

nav = get_message_module('nav_msgs')
geometry = get_message_module('geometry_msgs')
swarm = get_message_module('swarm_interfaces')


@pytest.fixture
def graph():
    from swarm_runtime.simulation import spin_until, wall_time_s

    rclpy.init(args=[])
    node = BayesSwarmNode(namespace='/r0', parameter_overrides=[Parameter('robot_index', value=0)])
    probe = rclpy.create_node('probe')
    commands = []
    probe.create_subscription(geometry.Twist, '/r0/cmd_vel', commands.append, 10)
    pubs = {
        'odom': probe.create_publisher(nav.Odometry, '/r0/odom', 10),
        'signal': probe.create_publisher(swarm.SignalSample, '/r0/signal', 10),
        'peers': probe.create_publisher(swarm.BayesSwarmPeer, '/r0/peers/in', 10),
    }
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    executor.add_node(probe)

    def spin_for(seconds):
        end = wall_time_s() + seconds
        spin_until(executor, lambda: wall_time_s() >= end)

    yield node, pubs, commands, spin_for
    executor.shutdown()
    node.destroy_node()
    probe.destroy_node()
    rclpy.try_shutdown()


def odom(x=0.0, y=0.0):
    msg = nav.Odometry()
    msg.pose.pose.position.x = x
    msg.pose.pose.position.y = y
    msg.pose.pose.orientation.w = 1.0
    return msg


def test_node_decides_with_fresh_odometry_and_stops_when_it_goes_stale(graph):
    node, pubs, commands, spin_for = graph
    pubs['odom'].publish(odom())
    spin_for(0.2)
    assert len(node.decisions) == 1
    assert any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in commands)
    spin_for(1.0)  # no odometry for 1 s > odom_timeout_s
    assert commands[-1].linear.x == 0.0
    assert commands[-1].angular.z == 0.0


def test_non_finite_signal_samples_are_dropped_and_finite_ones_kept(graph):
    node, pubs, _, spin_for = graph
    pubs['odom'].publish(odom(0.2, 0.1))
    spin_for(0.1)
    for value in (0.5, math.nan, math.inf, 0.6):
        pubs['signal'].publish(swarm.SignalSample(value=value))
    spin_for(0.1)
    assert node.planner.n_observations == 2


def test_duplicated_and_stale_peer_messages_are_ignored(graph):
    node, pubs, _, spin_for = graph
    update = PeerUpdate('r1', 2, np.zeros(2), np.ones(2), np.array([[0.1, 0.1]]), np.array([0.3]))
    msg = peer_update_to_ros(update, 1.0)
    pubs['peers'].publish(msg)
    pubs['peers'].publish(msg)
    msg.decision_index = 1
    pubs['peers'].publish(msg)
    spin_for(0.1)
    assert node.planner.n_observations == 1
    assert node.planner.peer_waypoints['r1'] == pytest.approx([1.0, 1.0])
