"""The node through its topics: sensor topics in, cmd_vel / pump / state out.

Runs on either runtime (real DDS with rclpy): the probe plays the sensors at 10 Hz after
the graph has matched, and the assertions hold whatever the delivery timing.
"""

from __future__ import annotations

import math

import pytest
from oabug_robot.errors import ConfigError
from oabug_robot.node import OABugNode
from swarm_runtime.ros import Parameter, message_module, qos_profile_sensor_data
from swarm_runtime.testing import NodeTestBed

sensor = message_module('sensor_msgs')
geometry = message_module('geometry_msgs')
std = message_module('std_msgs')
swarm = message_module('swarm_interfaces')

RAYS = 360
SENSOR_TOPICS = {
    'scan': sensor.LaserScan,
    'imu': sensor.Imu,
    'gas': swarm.GasReading,
    'bearings': swarm.PeerBearingArray,
}


def scan_msg(front_m: float = 5.0, fill: float = math.inf) -> object:
    """A 360-ray scan: ``fill`` everywhere, ``front_m`` in a 20-degree cone ahead."""
    ranges = [fill] * RAYS
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


def imu_msg(yaw_rad: float = 0.0) -> object:
    msg = sensor.Imu()
    msg.orientation.z = math.sin(yaw_rad / 2)
    msg.orientation.w = math.cos(yaw_rad / 2)
    return msg


class Harness:
    """The node in /r0, a probe that plays its sensors at 10 Hz, and what the node published."""

    def __init__(self, bed: NodeTestBed, **parameters: object) -> None:
        overrides = [Parameter(k, value=v) for k, v in parameters.items()]
        self.bed = bed
        self.node = bed.add_node(OABugNode, namespace='/r0', parameter_overrides=overrides)
        probe = bed.probe
        self.commands = probe.collect('/r0/cmd_vel', geometry.Twist)
        self.pump = probe.collect('/r0/pump', std.Bool)
        self.states = probe.collect('/r0/state', swarm.OABugState)
        self.players = {
            topic: probe.player(f'/r0/{topic}', msg_type, qos_profile_sensor_data)
            for topic, msg_type in SENSOR_TOPICS.items()
        }
        bed.wait_for_graph()

    def play(self, **messages: object) -> None:
        """Publish these messages every 0.1 s from now on (None stops a topic)."""
        for topic, msg in messages.items():
            self.players[topic].play(msg)

    def spin_for(self, seconds: float) -> None:
        self.bed.spin_for(seconds)

    def spin_until(self, predicate, timeout_s: float = 10.0) -> bool:
        return self.bed.spin_until(predicate, timeout_s)


@pytest.fixture
def make_harness():
    beds: list[NodeTestBed] = []

    def make(**parameters: object) -> Harness:
        bed = NodeTestBed()
        beds.append(bed)
        return Harness(bed, **parameters)

    yield make
    for bed in beds:
        bed.close()


def driving(h: Harness) -> bool:
    return bool(h.commands) and h.commands[-1].linear.x > 0.0


def reported_stale(h: Harness) -> bool:
    return bool(h.states) and h.states[-1].inputs_stale


def stopped(h: Harness) -> bool:
    return bool(h.commands) and h.commands[-1].linear.x == 0.0 and h.commands[-1].angular.z == 0.0


def all_sensors(front_m: float = 5.0, gas_raw: int = 60) -> dict[str, object]:
    return {'scan': scan_msg(front_m), 'imu': imu_msg(0.0), 'gas': swarm.GasReading(raw=gas_raw)}


def test_without_sensor_data_the_robot_holds_still_with_the_pump_off(make_harness) -> None:
    h = make_harness(variant='gas_sound')
    h.spin_for(0.55)
    assert h.commands, 'the node publishes the fail-safe command while waiting'
    assert all(c.linear.x == 0.0 and c.angular.z == 0.0 for c in h.commands)
    assert not any(p.data for p in h.pump)
    assert h.states[-1].inputs_stale
    assert h.states[-1].event == 'stale_inputs'


def test_with_fresh_sensors_the_robot_heads_out_and_pumps(make_harness) -> None:
    h = make_harness(variant='gas', robot_index=0, robot_count=1)
    h.play(**all_sensors())
    assert h.spin_until(lambda: driving(h) and any(p.data for p in h.pump))
    h.spin_for(0.3)
    assert driving(h)
    assert h.pump[-1].data, 'a gas variant pumps while it drives'
    state = h.states[-1]
    assert not state.inputs_stale
    assert state.variant == 'gas'
    assert state.state == swarm.OABugState.STATE_JUST_STARTED
    assert state.mode == swarm.OABugState.MODE_STRAIGHT


def test_variants_without_scent_never_pump(make_harness) -> None:
    h = make_harness(variant='sound', robot_count=1)
    h.play(scan=scan_msg(), imu=imu_msg())
    assert h.spin_until(lambda: driving(h)), 'a non-gas variant does not need the gas topic'
    h.spin_for(0.5)
    assert driving(h)
    assert h.pump
    assert not any(p.data for p in h.pump)


def test_a_wall_ahead_starts_wall_following(make_harness) -> None:
    h = make_harness(variant='gas', robot_count=1)
    h.play(**all_sensors(front_m=5.0))
    assert h.spin_until(lambda: driving(h))
    h.play(scan=scan_msg(front_m=0.22))
    following = swarm.OABugState.STATE_FOLLOWING_WALL
    assert h.spin_until(lambda: h.states and h.states[-1].state == following)
    h.spin_for(0.3)
    state = h.states[-1]
    assert state.state == following
    assert state.wall_hits == 1
    assert state.wall_side == swarm.OABugState.SIDE_LEFT, 'turned right: wall on the left'
    assert h.commands[-1].angular.z < 0.0


@pytest.mark.parametrize('lost', ['scan', 'imu', 'gas'])
def test_a_stale_input_stops_the_robot_and_the_pump_until_it_returns(make_harness, lost) -> None:
    h = make_harness(variant='gas_sound', robot_count=1, stale_timeout_s=0.5)
    h.play(**all_sensors())
    assert h.spin_until(lambda: driving(h))
    h.play(**{lost: None})
    assert h.spin_until(
        lambda: stopped(h) and h.states and h.states[-1].inputs_stale, timeout_s=2.0
    )
    h.spin_for(0.3)
    assert stopped(h), 'and it stays stopped'
    assert h.pump[-1].data is False
    assert h.states[-1].inputs_stale
    h.play(**all_sensors())
    assert h.spin_until(lambda: driving(h) and not h.states[-1].inputs_stale, timeout_s=2.0)


def test_a_lost_gas_sensor_does_not_stop_variants_that_do_not_smell(make_harness) -> None:
    h = make_harness(variant='minimum', robot_count=1, stale_timeout_s=0.5)
    h.play(scan=scan_msg(), imu=imu_msg())
    assert h.spin_until(lambda: driving(h))
    h.spin_for(1.0)
    assert driving(h)
    assert not h.states[-1].inputs_stale


def test_nan_and_infinite_ranges_do_not_stop_the_controller(make_harness) -> None:
    h = make_harness(variant='gas_sound', robot_count=1)
    scan = scan_msg(front_m=5.0, fill=math.nan)
    h.play(scan=scan, imu=imu_msg(), gas=swarm.GasReading(raw=60))
    assert h.spin_until(lambda: driving(h))
    h.spin_for(0.3)
    assert driving(h)
    assert not h.states[-1].inputs_stale


def test_an_imu_without_orientation_counts_as_missing(make_harness) -> None:
    h = make_harness(variant='minimum', robot_count=1)
    h.play(scan=scan_msg(), imu=sensor.Imu(orientation=geometry.Quaternion(w=0.0)))
    h.spin_for(1.0)
    assert h.states[-1].inputs_stale
    assert all(c.linear.x == 0.0 for c in h.commands)


def test_scent_above_the_threshold_shows_in_the_state(make_harness) -> None:
    h = make_harness(variant='gas', robot_count=1, gas_threshold=200)
    h.play(**all_sensors(gas_raw=350))
    assert h.spin_until(lambda: h.states and h.states[-1].scent_detected)
    assert h.states[-1].gas_raw == 350


@pytest.mark.parametrize(
    ('name', 'value', 'message'),
    [
        ('variant', 'oabug', "variant: 'oabug' is not one of random, minimum"),
        ('departure', 'roof', 'not one of center, edge'),
        ('robot_index', 5, 'robot_index'),
        ('sound_turn_rule', 'sideways', 'sound_turn_rule'),
        ('robot_hit_turn', 'back', 'robot_hit_turn'),
        ('gas_sound_wall_side', 'second_contact', 'gas_sound_wall_side'),
        ('sound_side_deadband_deg', 120.0, 'sound_side_deadband'),
        ('gas_sound_side_deadband_deg', -5.0, 'gas_sound_side_deadband'),
        ('control_rate_hz', 0.0, 'control_rate_hz'),
    ],
)
def test_invalid_parameters_fail_at_start_with_a_clear_error(
    make_harness, name, value, message
) -> None:
    with pytest.raises(ConfigError, match=message):
        make_harness(**{name: value, 'robot_count': 2})


def test_the_parameter_file_starts_a_node_and_command_line_overrides_win() -> None:
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / 'config' / 'oabug.yaml'
    args = ['--ros-args', '--params-file', str(path), '-p', 'variant:=minimum']
    with NodeTestBed(args) as bed:
        node = bed.add_node(OABugNode, namespace='/r3')
        assert node.fsm.config.variant.value == 'minimum'
        assert node.fsm.config.gas_threshold == 200


def stamp_s(msg: object) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_state_is_published_at_its_own_rate_and_at_every_event(make_harness) -> None:
    h = make_harness(variant='gas', robot_count=1, state_rate_hz=2.0)
    h.play(**all_sensors(front_m=5.0))
    assert h.spin_until(lambda: driving(h))
    h.spin_for(0.3)
    h.states.clear()
    h.commands.clear()
    h.spin_for(2.0)
    intervals = [stamp_s(b) - stamp_s(a) for a, b in zip(h.states, h.states[1:], strict=False)]
    assert 3 <= len(h.states) <= 5, 'about 2 Hz while nothing happens'
    assert min(intervals) >= 0.5 - 1e-6, 'never faster than state_rate_hz'
    assert len(h.commands) >= 3 * len(h.states), 'while cmd_vel goes out every control step'

    # A long state period, so that no periodic state falls into the window below.
    h = make_harness(variant='gas', robot_count=1, state_rate_hz=0.2)
    h.play(**all_sensors(front_m=5.0))
    assert h.spin_until(lambda: driving(h))
    h.spin_for(0.3)
    h.states.clear()
    h.play(scan=scan_msg(front_m=0.22))
    assert h.spin_until(lambda: h.states, timeout_s=1.5)
    h.spin_for(0.3)
    assert [s.event for s in h.states] == ['hit_wall'], 'published at once, off the period'
