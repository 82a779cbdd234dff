"""Message <-> core translations, with field checks on and the CDR round trip."""

from __future__ import annotations

import array
import math

import numpy as np
import pytest
from oabug_robot.conversions import (
    command_to_pump,
    command_to_twist,
    gas_from_ros,
    peer_arrays_from_ros,
    scan_from_ros,
    state_to_ros,
    yaw_from_imu,
)
from oabug_robot.errors import ScanError
from oabug_robot.fsm import Command, Event, OABugFsm
from oabug_robot.settings import OABugConfig, Variant
from swarm_runtime.ros import message_module
from swarm_runtime.testing import cdr_roundtrip

sensor = message_module('sensor_msgs')
swarm = message_module('swarm_interfaces')
builtin = message_module('builtin_interfaces')


def test_scan_ranges_keep_nan_and_inf_and_their_geometry() -> None:
    msg = sensor.LaserScan(
        angle_min=-math.pi,
        angle_max=-math.pi + 1.5,
        angle_increment=0.5,
        range_min=0.15,
        range_max=12.0,
        ranges=[1.0, math.nan, math.inf, -math.inf],
    )
    scan = scan_from_ros(cdr_roundtrip(msg))
    assert scan.ranges_m[0] == pytest.approx(1.0)
    assert math.isnan(scan.ranges_m[1])
    assert scan.ranges_m[2] == math.inf
    assert scan.ranges_m[3] == -math.inf
    assert scan.angle_min_rad == pytest.approx(-math.pi)
    assert scan.angle_increment_rad == pytest.approx(0.5)


def test_scan_ranges_given_as_a_list_are_accepted() -> None:
    msg = type('Scan', (), {})()
    msg.ranges, msg.angle_min, msg.angle_increment = [1.0, 2.0], 0.0, 0.1
    msg.angle_max, msg.range_min, msg.range_max = 0.1, 0.1, 5.0
    assert scan_from_ros(msg).ranges_m.tolist() == [1.0, 2.0]
    msg.ranges = array.array('f')
    with pytest.raises(ScanError, match='no ranges'):
        scan_from_ros(msg)


def _full_scan(**changes: object) -> object:
    # The sim bridge's and the RPLidar driver's convention: angle_max is the last ray's angle.
    values = {
        'angle_min': -math.pi,
        'angle_max': math.pi - 2 * math.pi / 360,
        'angle_increment': 2 * math.pi / 360,
        'range_min': 0.15,
        'range_max': 12.0,
        'ranges': [0.18] * 360,
        **changes,
    }
    return sensor.LaserScan(**values)


def test_a_full_revolution_as_the_bridge_and_the_driver_publish_it_is_accepted() -> None:
    assert scan_from_ros(cdr_roundtrip(_full_scan())).ranges_m.size == 360


@pytest.mark.parametrize(
    ('changes', 'problem'),
    [
        ({'angle_min': math.nan}, 'finite'),
        ({'angle_max': math.inf}, 'finite'),
        ({'angle_increment': 1e-30}, 'finer than'),
        ({'angle_increment': 0.1, 'angle_max': -math.pi + 359 * 0.1}, 'more than a revolution'),
        ({'ranges': [0.18] * 10}, '10 ranges, but'),
        ({'range_max': math.nan}, 'range limits'),
        ({'range_min': math.nan}, 'range limits'),
        ({'range_min': 0.15, 'range_max': 0.1}, 'range limits'),
        ({'range_min': -1.0}, 'range limits'),
        ({'ranges': [math.nan] * 360}, 'every range'),
    ],
)
def test_a_scan_whose_frame_cannot_be_read_is_refused(changes, problem) -> None:
    # Read as it was, each of these would drop every return and look like free space.
    with pytest.raises(ScanError, match=problem):
        scan_from_ros(cdr_roundtrip(_full_scan(**changes)))


def test_yaw_comes_from_the_imu_orientation() -> None:
    msg = sensor.Imu()
    msg.orientation.z = math.sin(0.4)
    msg.orientation.w = math.cos(0.4)
    assert yaw_from_imu(msg) == pytest.approx(0.8)


@pytest.mark.parametrize('w', [0.0, math.nan])
def test_an_imu_orientation_without_a_yaw_is_rejected(w: float) -> None:
    msg = sensor.Imu()
    msg.orientation.w = w
    with pytest.raises(ValueError, match='orientation'):
        yaw_from_imu(msg)


def test_gas_readings_while_warming_up_carry_no_scent() -> None:
    assert gas_from_ros(swarm.GasReading(raw=321)) == 321
    assert gas_from_ros(swarm.GasReading(raw=900, warming_up=True)) is None


def test_own_tag_is_dropped_from_the_bearings() -> None:
    msg = swarm.PeerBearingArray(
        bearings=[
            swarm.PeerBearing(tag_id='R0', azimuth=0.5, distance=1.0),
            swarm.PeerBearing(tag_id='r1', azimuth=-0.5, distance=math.nan),
        ]
    )
    azimuths, distances = peer_arrays_from_ros(msg, 'r0')
    assert azimuths.tolist() == pytest.approx([-0.5])
    assert math.isnan(distances[0])
    assert peer_arrays_from_ros(msg, '')[0].size == 2


def test_commands_become_twist_and_bool_messages() -> None:
    twist = cdr_roundtrip(command_to_twist(Command(0.25, -0.5, True)))
    assert twist.linear.x == pytest.approx(0.25)
    assert twist.angular.z == pytest.approx(-0.5)
    assert twist.linear.y == 0.0
    assert cdr_roundtrip(command_to_pump(True)).data is True


def test_state_message_carries_the_controller_state() -> None:
    fsm = OABugFsm(OABugConfig(variant=Variant.GAS, robot_count=4, robot_index=1))
    fsm.memory.visit_count = 2
    fsm.memory.counts[Event.HIT_WALL] = 3
    fsm.memory.counts[Event.REVISIT] = 1
    fsm.memory.counts[Event.OUTER_CORNER] = 4
    msg = state_to_ros(
        fsm.memory,
        fsm.config,
        stamp=builtin.Time(sec=5, nanosec=0),
        heading_rad=math.nan,
        pump_on=True,
        gas_raw=1500,
        scent_detected=True,
        inputs_stale=False,
    )
    msg = cdr_roundtrip(msg)
    assert msg.variant == 'gas'
    assert msg.state == swarm.OABugState.STATE_JUST_STARTED
    assert msg.preferred_direction == pytest.approx(math.pi / 2)
    assert math.isnan(msg.heading)
    assert msg.visit_count == 2
    assert msg.wall_hits == 3
    assert msg.outer_corners == 5
    assert msg.gas_raw == 1023, 'clamped to the 10-bit scale'
    assert msg.event == 'none'


def test_stale_state_says_so_in_the_event() -> None:
    fsm = OABugFsm(OABugConfig())
    msg = state_to_ros(
        fsm.memory,
        fsm.config,
        stamp=builtin.Time(),
        heading_rad=0.0,
        pump_on=False,
        gas_raw=None,
        scent_detected=False,
        inputs_stale=True,
    )
    assert msg.event == 'stale_inputs'
    assert msg.gas_raw == 0
    assert np.isfinite(msg.target_heading)
