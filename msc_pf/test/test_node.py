"""The node through its topics: odom + rssi + peers in, cmd_vel + peers/out + state out.

Runs on either runtime (real DDS with rclpy). The node runs on sim time: the probe publishes
/clock four times faster than the wall clock and plays odometry (and RSSI) every 0.1 s of
it, so the formation timeouts below take a quarter of their length on real DDS.
"""

from __future__ import annotations

import math

import pytest
from msc_pf.conversions import stamp_to_ros
from msc_pf.errors import ConfigError
from msc_pf.node import MscPfNode
from msc_pf.peers import Phase, Role
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data
from swarm_runtime.testing import NodeTestBed

nav = message_module('nav_msgs')
geometry = message_module('geometry_msgs')
swarm = message_module('swarm_interfaces')
builtin = message_module('builtin_interfaces')

# Sim time per probe tick (0.01 s of wall time).
CLOCK_STEP_S = 0.04


def odom_at(x: float, y: float) -> object:
    msg = nav.Odometry()
    msg.pose.pose.position.x = x
    msg.pose.pose.position.y = y
    msg.pose.pose.orientation.w = 1.0
    return msg


class Harness:
    """The node in /r2 on sim time, a probe that plays odom/rssi, and the node's output."""

    def __init__(self, bed: NodeTestBed, **parameters: object) -> None:
        overrides = [Parameter(k, value=v) for k, v in parameters.items()]
        overrides.append(Parameter('use_sim_time', value=True))
        self.bed = bed
        self.node = bed.add_node(MscPfNode, namespace='/r2', parameter_overrides=overrides)
        probe = bed.probe
        self.commands = probe.collect('/r2/cmd_vel', geometry.Twist)
        self.states = probe.collect('/r2/state', swarm.MscPfState)
        self.peers = probe.collect('/r2/peers/out', swarm.MscPeer)
        self.odom = probe.player('/r2/odom', nav.Odometry, qos_profile_sensor_data)
        self.rssi = probe.player('/r2/rssi', swarm.RssiArray, qos_profile_sensor_data)
        bed.wait_for_graph()
        self.odom.play(odom_at(1000.0, 1000.0))

    def spin_for(self, seconds: float) -> None:
        """Run for ``seconds`` of sim time."""
        self.bed.spin_for(seconds)

    def spin_until(self, predicate, timeout_s: float = 10.0) -> bool:
        return self.bed.spin_until(predicate, timeout_s)


@pytest.fixture
def make_harness():
    beds: list[NodeTestBed] = []

    def make(**parameters: object) -> Harness:
        bed = NodeTestBed(clock_step_s=CLOCK_STEP_S)
        beds.append(bed)
        return Harness(bed, **parameters)

    yield make
    for bed in beds:
        bed.close()


def test_node_takes_its_id_from_the_namespace_and_reports_its_scheme(make_harness):
    h = make_harness(scheme='msc_pf')
    assert h.spin_until(lambda: h.states and h.peers)
    assert h.node.controller.robot_id == 2
    assert h.states[-1].scheme == 'msc_pf'
    assert h.states[-1].robot == 'r2'
    assert h.peers[-1].robot_id == 2


def test_alone_robot_starts_searching_after_the_formation_timeout(make_harness):
    h = make_harness(scheme='msc')
    h.spin_for(3.05)
    assert h.states[-1].phase == swarm.MscPfState.PHASE_FORMING
    assert h.commands
    assert all(c.linear.x == 0.0 for c in h.commands)
    h.spin_for(4.0)
    assert h.states[-1].phase == swarm.MscPfState.PHASE_SEARCH
    assert any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in h.commands[-10:])


def test_robot_stops_when_odometry_goes_stale(make_harness):
    h = make_harness(scheme='msc')
    h.spin_for(7.0)
    assert any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in h.commands[-10:])
    h.odom.play(None)
    timeout_s = h.node.get_parameter('odom_timeout_s').value
    h.spin_for(timeout_s + 1.0)
    last = h.commands[-1]
    assert last.linear.x == 0.0
    assert last.angular.z == 0.0


def test_unknown_and_non_finite_rssi_is_ignored(make_harness):
    h = make_harness(scheme='msc_pf', target_ids=[5, 6])
    h.rssi.play(
        swarm.RssiArray(
            readings=[
                swarm.EmitterRssi(emitter_id=5, rssi_dbm=-80.0),
                swarm.EmitterRssi(emitter_id=9, rssi_dbm=-70.0),  # a peer's tag, not a target
                swarm.EmitterRssi(emitter_id=6, rssi_dbm=math.nan),
            ]
        )
    )
    assert h.spin_until(lambda: h.peers and list(h.peers[-1].reading_ids) == [5])
    h.spin_for(1.0)
    assert list(h.peers[-1].reading_ids) == [5]
    assert h.node.controller.filters.tracked_ids == (5,)


def test_rssi_stamped_before_the_last_accepted_message_is_ignored(make_harness):
    h = make_harness(scheme='msc_pf')
    newer = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=1, rssi_dbm=-80.0)])
    newer.header.stamp = builtin.Time(sec=5, nanosec=0)
    older = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=2, rssi_dbm=-80.0)])
    older.header.stamp = builtin.Time(sec=3, nanosec=0)
    h.rssi.publish(newer)
    h.rssi.publish(older)

    def reported() -> set[tuple[int, ...]]:
        return {tuple(p.reading_ids) for p in h.peers if len(p.reading_ids)}

    assert h.spin_until(reported)
    h.spin_for(1.05)
    assert reported() == {(1,)}, 'the older message never counted'


def test_rssi_stamped_far_in_the_future_does_not_block_later_messages(make_harness):
    h = make_harness(scheme='msc_pf', target_ids=[5, 6])
    future = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=5, rssi_dbm=-80.0)])
    future.header.stamp = builtin.Time(sec=2**31 - 1, nanosec=0)
    h.rssi.publish(future)
    h.spin_for(0.5)
    assert h.node.loop.last_rssi_stamp_s == -math.inf
    good = swarm.RssiArray(readings=[swarm.EmitterRssi(emitter_id=6, rssi_dbm=-80.0)])
    good.header.stamp = builtin.Time(sec=1, nanosec=0)
    h.rssi.play(good)
    assert h.spin_until(lambda: h.peers and list(h.peers[-1].reading_ids) == [6])
    assert h.node.controller.filters.tracked_ids == (6,)


def test_peer_readings_of_targets_outside_target_ids_are_ignored(make_harness):
    h = make_harness(scheme='msc_pf', target_ids=[5, 6])
    player = h.bed.probe.player('/r2/peers/in', swarm.MscPeer, 10)
    h.bed.wait_for_graph()
    n = 200
    peer = swarm.MscPeer(
        robot='r3',
        robot_id=3,
        position_x=1001.0,
        position_y=1000.0,
        role=int(Role.LEADER),
        leader_id=3,
        members=[3],
        phase=int(Phase.SEARCH),
        target_id=-1,
        target_rssi_dbm=-100.0,
        visited_cell=-1,
        reading_ids=[6, *range(1000, 1000 + n)],
        reading_rssi_dbm=[-75.0] + [-70.0] * n,
    )
    peer.header.stamp = stamp_to_ros(h.bed.probe.sim_time_s(), builtin)
    player.publish(peer)
    assert h.spin_until(lambda: h.node.controller.filters.tracked_ids)
    h.spin_for(1.05)
    assert h.node.controller.filters.tracked_ids == (6,)


def test_odometry_with_a_zero_quaternion_is_dropped_and_the_robot_stops(make_harness):
    h = make_harness(scheme='msc')
    h.spin_for(7.0)
    assert any(c.linear.x > 0.0 or c.angular.z != 0.0 for c in h.commands[-10:])
    broken = odom_at(1000.0, 1000.0)
    broken.pose.pose.orientation.w = 0.0
    h.odom.play(broken)
    timeout_s = h.node.get_parameter('odom_timeout_s').value
    h.spin_for(timeout_s + 1.0)
    last = h.commands[-1]
    assert (last.linear.x, last.angular.z) == (0.0, 0.0)


def test_invalid_parameters_stop_the_node_at_start(make_harness):
    with pytest.raises(ConfigError, match='gamma1 < gamma2 < gamma3'):
        make_harness(**{'phases.gamma2_dbm': -90.0})
    with pytest.raises(ConfigError, match='drive_rate_hz'):
        make_harness(drive_rate_hz=0.0)
