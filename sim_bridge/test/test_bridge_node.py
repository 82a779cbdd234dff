"""The bridge node standalone: parameters, the topic contract and the message contents."""

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from sim_bridge.bridge_node import SimBridgeNode
from sim_bridge.bridge_parameters import values_from_config
from swarm_runtime.ros import (
    Node,
    Parameter,
    SingleThreadedExecutor,
    message_module,
    qos_profile_sensor_data,
    rclpy,
)
from swarm_runtime.simulation import spin_until
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError
from swarm_sim.site_loading import load_site

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
CONFIG = Path(__file__).parents[1] / 'config' / 'sim_bridge.yaml'
sensor_msgs = message_module('sensor_msgs')
nav_msgs = message_module('nav_msgs')
geometry_msgs = message_module('geometry_msgs')
swarm = message_module('swarm_interfaces')


@pytest.fixture
def ros():
    rclpy.init(args=[])
    executor = SingleThreadedExecutor()
    yield executor
    executor.shutdown()
    rclpy.try_shutdown()


class Listener(Node):
    """Keeps every message of r0's sensor topics and the /sim topics."""

    def __init__(self):
        super().__init__('listener', parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.got = {}
        qos = qos_profile_sensor_data
        topics = [
            (sensor_msgs.LaserScan, '/r0/scan', qos),
            (sensor_msgs.Imu, '/r0/imu', qos),
            (nav_msgs.Odometry, '/r0/odom', qos),
            (swarm.GasReading, '/r0/gas', qos),
            (swarm.PeerBearingArray, '/r0/bearings', qos),
            (swarm.TruePoseArray, '/sim/poses', 10),
        ]
        for msg_type, topic, profile in topics:
            self.got[topic] = []
            self.create_subscription(msg_type, topic, self.got[topic].append, profile)
        self.cmd = self.create_publisher(geometry_msgs.Twist, '/r1/cmd_vel', 10)


def standalone_bridge(**params):
    overrides = {'site_file': str(FIVE_ROOMS), 'robot_count': 2, 'departure': 'edge'}
    overrides.update(params)
    return SimBridgeNode(parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])


def test_standalone_bridge_publishes_the_topic_contract(ros):
    bridge = standalone_bridge()
    listener = Listener()
    for node in (bridge, listener):
        ros.add_node(node)
    assert spin_until(ros, lambda: bridge.sim_time_s >= 2.0, max_wall_time_s=10.0)
    got = listener.got
    assert len(got['/r0/scan']) == pytest.approx(2.0 * 5.5, abs=1)
    assert len(got['/r0/imu']) == pytest.approx(20, abs=1)
    assert len(got['/r0/gas']) == pytest.approx(20, abs=1)
    assert len(got['/r0/bearings']) == pytest.approx(10, abs=1)
    assert len(got['/sim/poses']) == pytest.approx(4, abs=1)

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


def test_bridge_moves_a_robot_by_cmd_vel_and_stops_it_when_commands_stop(ros):
    bridge = standalone_bridge()
    listener = Listener()
    for node in (bridge, listener):
        ros.add_node(node)
    start = bridge.engine.world.poses[1].copy()
    cmd = geometry_msgs.Twist()
    cmd.angular.z = 0.5

    def command_until(t):
        while bridge.sim_time_s < t:
            listener.cmd.publish(cmd)
            target = bridge.sim_time_s + 0.1
            spin_until(ros, lambda t=target: bridge.sim_time_s >= t - 1e-9, max_wall_time_s=5.0)

    command_until(2.0)
    turned = bridge.engine.world.poses[1, 2] - start[2]
    assert math.cos(turned - 1.0) == pytest.approx(1.0, abs=0.01)
    spin_until(ros, lambda: bridge.sim_time_s >= 4.0, max_wall_time_s=5.0)
    after = bridge.engine.world.poses[1, 2] - start[2]
    # The 0.5 s watchdog lets it turn at most 0.25 rad more, then it holds still.
    assert 0.0 <= math.remainder(after - turned, 2 * math.pi) <= 0.26


def test_bridge_without_a_site_explains_what_is_missing(ros):
    with pytest.raises(ConfigurationError, match='site_file'):
        SimBridgeNode()


def test_config_file_mirrors_the_engine_defaults():
    params = yaml.safe_load(CONFIG.read_text())['/sim_bridge']['ros__parameters']
    for name, value in values_from_config(EngineConfig()).items():
        assert params[name] == pytest.approx(value), name


class PeerProbe(Node):
    """Robot-side endpoints of the peer relay for robots r0..r2."""

    def __init__(self):
        super().__init__('peer_probe', parameter_overrides=[Parameter('use_sim_time', value=True)])
        std_msgs = message_module('std_msgs')
        self.out = [
            self.create_publisher(std_msgs.String, f'/r{i}/peers/out', 10) for i in range(3)
        ]
        self.received = {i: [] for i in range(3)}
        for i in range(3):
            self.create_subscription(
                std_msgs.String, f'/r{i}/peers/in', self.received[i].append, 10
            )
        self.string = std_msgs.String


def test_peer_relay_forwards_within_range_only(ros):
    poses = np.array([[1.0, 1.7, 0.0], [2.0, 1.7, 0.0], [5.5, 1.7, 0.0]])
    bridge = SimBridgeNode(
        site=load_site(str(FIVE_ROOMS)),
        initial_poses=poses,
        parameter_overrides=[
            Parameter('peer_msg_type', value='std_msgs/msg/String'),
            Parameter('comm_range_m', value=2.0),
        ],
    )
    probe = PeerProbe()
    for node in (bridge, probe):
        ros.add_node(node)
    probe.out[0].publish(probe.string(data='hello from r0'))
    spin_until(ros, lambda: bridge.sim_time_s >= 0.5, max_wall_time_s=5.0)
    assert [m.data for m in probe.received[1]] == ['hello from r0']
    assert probe.received[0] == []
    assert probe.received[2] == []
