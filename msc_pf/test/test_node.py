"""The node on the built-in runtime: odom + rssi + peers in, cmd_vel + peers/out + state out."""

from __future__ import annotations

import math

import pytest
from msc_pf.errors import ConfigError
from msc_pf.node import MscPfNode
from swarm_runtime.messages import get_message_module
from swarm_runtime.ros import Parameter, SingleThreadedExecutor, rclpy, using_real_rclpy

pytestmark = pytest.mark.skipif(using_real_rclpy(), reason='drives the built-in runtime')

nav = get_message_module('nav_msgs')
geometry = get_message_module('geometry_msgs')
swarm = get_message_module('swarm_interfaces')


def odom_at(x: float, y: float) -> object:
    msg = nav.Odometry()
    msg.pose.pose.position.x = x
    msg.pose.pose.position.y = y
    msg.pose.pose.orientation.w = 1.0
    return msg


class Harness:
    """The node plus a probe that plays odom/rssi at 10 Hz and records the node's output."""

    def __init__(self, **parameters: object) -> None:
        from swarm_runtime.simulation import spin_until, wall_time_s

        self._spin_until = spin_until
        self._wall_time_s = wall_time_s
        overrides = [Parameter(k, value=v) for k, v in parameters.items()]
        self.node = MscPfNode(namespace='/r2', parameter_overrides=overrides)
        self.probe = rclpy.create_node('probe')
        self.commands: list = []
        self.states: list = []
        self.peers: list = []
        self.probe.create_subscription(geometry.Twist, '/r2/cmd_vel', self.commands.append, 10)
        self.probe.create_subscription(swarm.MscPfState, '/r2/state', self.states.append, 10)
        self.probe.create_subscription(swarm.MscPeer, '/r2/peers/out', self.peers.append, 10)
        self.odom_pub = self.probe.create_publisher(nav.Odometry, '/r2/odom', 10)
        self.rssi_pub = self.probe.create_publisher(swarm.RssiArray, '/r2/rssi', 10)
        self.odom: object | None = odom_at(1000.0, 1000.0)
        self.rssi: object | None = None
        self.probe.create_timer(0.1, self._play)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.executor.add_node(self.probe)

    def _play(self) -> None:
        if self.odom is not None:
            self.odom_pub.publish(self.odom)
        if self.rssi is not None:
            self.rssi_pub.publish(self.rssi)

    def spin_for(self, seconds: float) -> None:
        end = self._wall_time_s() + seconds
        self._spin_until(self.executor, lambda: self._wall_time_s() >= end)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.probe.destroy_node()


@pytest.fixture
def make_harness():
    rclpy.init(args=[])
    made: list[Harness] = []

    def make(**parameters: object) -> Harness:
        harness = Harness(**parameters)
        made.append(harness)
        return harness

    yield make
    for harness in made:
        harness.close()
    rclpy.try_shutdown()


def test_node_takes_its_id_from_the_namespace_and_reports_its_scheme(make_harness):
    h = make_harness(scheme='msc_pf')
    h.spin_for(1.05)
    assert h.node.controller.robot_id == 2
    assert h.states[-1].scheme == 'msc_pf'
    assert h.states[-1].robot == 'r2'
    assert h.peers[-1].robot_id == 2


def test_alone_robot_starts_searching_after_the_formation_timeout(make_harness):
    h = make_harness(scheme='msc')
    h.spin_for(3.05)
    assert h.states[-1].phase == swarm.MscPfState.PHASE_FORMING
    assert all(c.linear.x == 0.0 for c in h.commands)
    h.spin_for(4.0)
    assert h.states[-1].phase == swarm.MscPfState.PHASE_SEARCH
    assert any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in h.commands[-10:])


def test_robot_stops_when_odometry_goes_stale(make_harness):
    h = make_harness(scheme='msc')
    h.spin_for(7.0)
    h.odom = None
    h.spin_for(2.0)
    last = h.commands[-1]
    assert last.linear.x == 0.0
    assert last.angular.z == 0.0


def test_unknown_and_non_finite_rssi_is_ignored(make_harness):
    h = make_harness(scheme='msc_pf', target_ids=[5, 6])
    h.rssi = swarm.RssiArray(
        readings=[
            swarm.EmitterRssi(emitter_id=5, rssi_dbm=-80.0),
            swarm.EmitterRssi(emitter_id=9, rssi_dbm=-70.0),  # a peer's tag, not a target
            swarm.EmitterRssi(emitter_id=6, rssi_dbm=math.nan),
        ]
    )
    h.spin_for(2.05)
    assert list(h.peers[-1].reading_ids) == [5]
    assert h.node.controller.filters.tracked_ids == (5,)


def test_rssi_stamped_before_the_last_accepted_message_is_ignored(make_harness):
    h = make_harness(scheme='msc_pf')
    builtin = get_message_module('builtin_interfaces')
    newer = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=1, rssi_dbm=-80.0)])
    newer.header.stamp = builtin.Time(sec=5, nanosec=0)
    older = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=2, rssi_dbm=-80.0)])
    older.header.stamp = builtin.Time(sec=3, nanosec=0)
    h.rssi_pub.publish(newer)
    h.rssi_pub.publish(older)
    h.spin_for(1.05)
    assert list(h.peers[-1].reading_ids) == [1]


def test_invalid_parameters_stop_the_node_at_start(make_harness):
    with pytest.raises(ConfigError, match='gamma1 < gamma2 < gamma3'):
        make_harness(**{'phases.gamma2_dbm': -90.0})
    with pytest.raises(ConfigError, match='drive_rate_hz'):
        make_harness(drive_rate_hz=0.0)
