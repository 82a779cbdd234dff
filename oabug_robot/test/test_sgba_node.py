"""The SGBA node through its topics: scan, imu, odom, bearings in, cmd_vel out.

Runs on either runtime (real DDS with rclpy): the probe plays the sensors at 10 Hz once the
graph has matched, and the assertions hold whatever the delivery timing.
"""

from __future__ import annotations

import math

import pytest
from oabug_robot.sgba.node import SgbaNode
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data
from swarm_runtime.testing import NodeTestBed

sensor = message_module('sensor_msgs')
geometry = message_module('geometry_msgs')
nav = message_module('nav_msgs')
swarm = message_module('swarm_interfaces')

RAYS = 360


def scan_msg(front_m: float = 5.0) -> object:
    ranges = [5.0] * RAYS
    for k in range(RAYS // 2 - 10, RAYS // 2 + 11):
        ranges[k] = front_m
    return sensor.LaserScan(
        angle_min=-math.pi,
        angle_max=math.pi - 2 * math.pi / RAYS,
        angle_increment=2 * math.pi / RAYS,
        range_min=0.15,
        range_max=12.0,
        ranges=ranges,
    )


def imu_msg(yaw_rad: float) -> object:
    msg = sensor.Imu()
    msg.orientation.z = math.sin(yaw_rad / 2)
    msg.orientation.w = math.cos(yaw_rad / 2)
    return msg


def odom_msg() -> object:
    return nav.Odometry()


def bearings_msg(distance_m: float) -> object:
    return swarm.PeerBearingArray(
        bearings=[swarm.PeerBearing(tag_id='R0', azimuth=0.0, distance=distance_m)]
    )


@pytest.fixture
def harness():
    bed = NodeTestBed()
    made = {}

    def make(**parameters: object):
        overrides = [Parameter(k, value=v) for k, v in parameters.items()]
        node = bed.add_node(SgbaNode, namespace='/r1', parameter_overrides=overrides)
        probe = bed.probe
        commands = probe.collect('/r1/cmd_vel', geometry.Twist)
        players = {
            topic: probe.player(f'/r1/{topic}', msg_type, qos_profile_sensor_data)
            for topic, msg_type in (
                ('scan', sensor.LaserScan),
                ('imu', sensor.Imu),
                ('odom', nav.Odometry),
                ('bearings', swarm.PeerBearingArray),
            )
        }
        bed.wait_for_graph()
        made.update(node=node, commands=commands, players=players)
        return bed, node, commands, players

    yield make
    bed.close()


def test_without_sensors_it_holds_still(harness) -> None:
    bed, _, commands, _ = harness()
    bed.spin_for(0.55)
    assert commands
    assert all(c.linear.x == 0.0 and c.angular.z == 0.0 for c in commands)


def test_with_fresh_sensors_it_turns_to_its_heading_and_stops_when_odometry_is_lost(
    harness,
) -> None:
    # Robot 1 of 4: preferred heading +90 deg; it starts at yaw 0 and turns left.
    bed, node, commands, players = harness(robot_index=1, robot_count=4, own_tag_id='R1')
    players['scan'].play(scan_msg())
    players['imu'].play(imu_msg(0.0))
    players['odom'].play(odom_msg())
    assert bed.spin_until(lambda: bool(commands) and commands[-1].angular.z > 0.0, 10.0)
    assert commands[-1].linear.x == 0.0
    # At the heading it goes forward.
    players['imu'].play(imu_msg(math.pi / 2))
    assert bed.spin_until(lambda: commands[-1].linear.x > 0.0, 10.0)
    # A peer heard: its RSSI and right of way reach the loop.
    players['bearings'].play(bearings_msg(1.0))
    assert bed.spin_until(lambda: node.loop.strongest_peer(node._now_s()) is not None, 10.0)
    peer = node.loop.strongest_peer(node._now_s())
    assert peer.has_way
    assert peer.rssi_dbm == pytest.approx(-48.0, abs=0.01)
    players['odom'].play(None)
    assert bed.spin_until(
        lambda: commands[-1].linear.x == 0.0 and commands[-1].angular.z == 0.0, 10.0
    )


@pytest.mark.parametrize(
    'damage',
    [
        {'angle_min': math.nan},
        {'angle_min': math.inf},
        {'angle_increment': 1e-30},
        {'range_max': math.nan},
    ],
    ids=['angle_min NaN', 'angle_min inf', 'increment 1e-30', 'range_max NaN'],
)
def test_a_scan_it_cannot_read_is_dropped_and_the_robot_stops_until_good_ones_return(
    harness, damage
) -> None:
    bed, _, commands, players = harness(robot_index=1, robot_count=4, own_tag_id='R1')
    players['imu'].play(imu_msg(math.pi / 2))
    players['odom'].play(odom_msg())
    players['scan'].play(scan_msg())
    assert bed.spin_until(lambda: bool(commands) and commands[-1].linear.x > 0.0, 10.0)
    bad = scan_msg()
    for field, value in damage.items():
        setattr(bad, field, value)
    players['scan'].play(bad)  # the node lives on (a callback error would end the spin)
    assert bed.spin_until(lambda: commands[-1].linear.x == 0.0, 10.0), 'stale scan: stop'
    players['scan'].play(scan_msg())
    assert bed.spin_until(lambda: commands[-1].linear.x > 0.0, 10.0)


def test_odometry_that_is_not_finite_is_dropped(harness) -> None:
    bed, node, _, players = harness(robot_index=1, robot_count=4, own_tag_id='R1')
    players['odom'].play(odom_msg())
    bed.spin_for(0.3)
    bad = odom_msg()
    bad.pose.pose.position.x = math.nan
    players['odom'].play(bad)
    bed.spin_for(0.3)
    assert all(math.isfinite(v) for v in node.loop._position)
