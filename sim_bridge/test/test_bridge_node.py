"""The bridge node standalone: parameters, the topic contract and the message contents.

The tests run on either runtime (swarm_runtime.testing): on real rclpy the bridge steps in
real time (``real_time_factor`` 1), messages go over DDS and are counted over a window after
the graph has matched, with a margin for best-effort sensor streams.
"""

import math
from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bridge_node import SimBridgeNode
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data, using_real_rclpy
from swarm_runtime.testing import NodeTestBed
from swarm_sim.errors import ConfigurationError
from swarm_sim.site_loading import load_site

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
CONFIG = Path(__file__).parents[1] / 'config' / 'sim_bridge.yaml'
sensor_msgs = message_module('sensor_msgs')
nav_msgs = message_module('nav_msgs')
geometry_msgs = message_module('geometry_msgs')
std_msgs = message_module('std_msgs')
swarm = message_module('swarm_interfaces')

# Messages a window may gain or lose at its edges (and, on DDS, by best-effort delivery).
COUNT_MARGIN = 2 if using_real_rclpy() else 1
# The bridge runs in real time on rclpy: allow for a loaded host's executor.
WAIT_S = 20.0


@pytest.fixture
def bed():
    with NodeTestBed() as bed:
        yield bed


def listen(bed):
    """Collect r0's sensor topics and /sim/poses; a /r1/cmd_vel player."""
    sensors = qos_profile_sensor_data
    topics = [
        (sensor_msgs.LaserScan, '/r0/scan', sensors),
        (sensor_msgs.Imu, '/r0/imu', sensors),
        (nav_msgs.Odometry, '/r0/odom', sensors),
        (swarm.GasReading, '/r0/gas', sensors),
        (swarm.PeerBearingArray, '/r0/bearings', sensors),
        (swarm.TruePoseArray, '/sim/poses', 10),
    ]
    got = {topic: bed.probe.collect(topic, msg_type, qos) for msg_type, topic, qos in topics}
    return got, bed.probe.player('/r1/cmd_vel', geometry_msgs.Twist, 10, period_s=0.1)


def standalone_bridge(bed, **params):
    overrides = {'site_file': str(FIVE_ROOMS), 'robot_count': 2, 'departure': 'edge'}
    overrides.update(params)
    return bed.add_node(
        SimBridgeNode, parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()]
    )


def spin_to(bed, bridge, sim_time_s):
    assert bed.spin_until(lambda: bridge.sim_time_s >= sim_time_s - 1e-9, timeout_s=WAIT_S)


def test_standalone_bridge_publishes_the_topic_contract(bed):
    bridge = standalone_bridge(bed)
    got, _ = listen(bed)
    bed.wait_for_graph()
    start_s = bridge.sim_time_s + 0.5
    spin_to(bed, bridge, start_s)
    before = {topic: len(messages) for topic, messages in got.items()}
    spin_to(bed, bridge, start_s + 2.0)
    counts = {topic: len(messages) - before[topic] for topic, messages in got.items()}
    assert counts['/r0/scan'] == pytest.approx(2.0 * 5.5, abs=COUNT_MARGIN)
    assert counts['/r0/imu'] == pytest.approx(20, abs=COUNT_MARGIN)
    assert counts['/r0/gas'] == pytest.approx(20, abs=COUNT_MARGIN)
    assert counts['/r0/bearings'] == pytest.approx(10, abs=COUNT_MARGIN)
    assert counts['/sim/poses'] == pytest.approx(4, abs=COUNT_MARGIN)

    scan = got['/r0/scan'][-1]
    assert scan.angle_min == pytest.approx(-math.pi)
    assert scan.angle_increment == pytest.approx(2 * math.pi / 360, rel=1e-6)
    assert len(scan.ranges) == 360
    ranges = np.asarray(scan.ranges)
    assert np.all(np.isinf(ranges) | ((ranges >= scan.range_min) & (ranges <= scan.range_max)))
    assert scan.header.frame_id == 'r0/laser'

    gas = got['/r0/gas'][-1]
    assert 0 <= gas.raw < 100
    assert math.isnan(gas.volts)

    peers = got['/r0/bearings'][-1].bearings
    assert [b.tag_id for b in peers] == ['R1']

    truth = got['/sim/poses'][-1].poses
    imu = got['/r0/imu'][-1]
    yaw = 2.0 * math.atan2(imu.orientation.z, imu.orientation.w)
    assert math.cos(yaw - truth[0].yaw) == pytest.approx(1.0, abs=1e-3)


def test_bridge_moves_a_robot_by_cmd_vel_and_stops_it_when_commands_stop(bed):
    bridge = standalone_bridge(bed)
    _, command = listen(bed)
    bed.wait_for_graph()
    initial_yaw = float(bridge.engine.world.poses[1, 2])
    cmd = geometry_msgs.Twist()
    cmd.angular.z = 0.5
    command.play(cmd)
    # From the first command the bridge applies: 2 s of turning at 0.5 rad/s.
    assert bed.spin_until(lambda: bridge.engine.world.poses[1, 2] != initial_yaw, timeout_s=WAIT_S)
    start_yaw, start_s = float(bridge.engine.world.poses[1, 2]), bridge.sim_time_s
    spin_to(bed, bridge, start_s + 2.0)
    command.play(None)
    turned = bridge.engine.world.poses[1, 2] - start_yaw
    assert math.cos(turned - 1.0) == pytest.approx(1.0, abs=0.01)
    spin_to(bed, bridge, start_s + 4.0)
    after = bridge.engine.world.poses[1, 2] - start_yaw
    # The 0.5 s watchdog lets it turn at most 0.25 rad more, then it holds still.
    late_rad = 0.1 if using_real_rclpy() else 0.01
    assert 0.0 <= math.remainder(after - turned, 2 * math.pi) <= 0.25 + late_rad


def test_bridge_without_a_site_explains_what_is_missing(bed):
    with pytest.raises(ConfigurationError, match='site_file'):
        bed.add_node(SimBridgeNode)


def test_peer_relay_forwards_within_range_only(bed):
    poses = np.array([[1.0, 1.7, 0.0], [2.0, 1.7, 0.0], [5.5, 1.7, 0.0]])
    bridge = bed.add_node(
        SimBridgeNode,
        site=load_site(str(FIVE_ROOMS)),
        initial_poses=poses,
        parameter_overrides=[
            Parameter('peer_msg_type', value='std_msgs/msg/String'),
            Parameter('comm_range_m', value=2.0),
        ],
    )
    out = bed.probe.player('/r0/peers/out', std_msgs.String, 10)
    received = {i: bed.probe.collect(f'/r{i}/peers/in', std_msgs.String, 10) for i in range(3)}
    bed.wait_for_graph()
    out.publish(std_msgs.String(data='hello from r0'))
    spin_to(bed, bridge, bridge.sim_time_s + 0.5)
    assert [m.data for m in received[1]] == ['hello from r0']
    assert received[0] == []
    assert received[2] == []
