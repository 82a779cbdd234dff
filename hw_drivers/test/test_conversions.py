"""Message translations: field types survive CDR, units and conventions are right."""

import math

import numpy as np
import pytest
from hw_drivers.aoa_bearings import PeerBearingData
from hw_drivers.conversions import (
    DiagnosticEntry,
    bearings_to_ros,
    diagnostics_to_ros,
    gas_to_ros,
    imu_to_ros,
    pump_state_to_ros,
    rssi_to_ros,
    scan_to_ros,
    stamp_from_ns,
)
from hw_drivers.gas_device import GasSample
from hw_drivers.mpu6050_device import ImuReading
from hw_drivers.rplidar_protocol import ScanBinning
from hw_drivers.worker import DiagnosticLevel
from swarm_runtime.messages import cdr_roundtrip


def _bearing(tag, rssi=math.nan):
    return PeerBearingData(tag, 0.5, math.nan, 2.0, 0, 12, rssi, 0.0)


def test_stamps_split_nanoseconds_into_sec_and_nanosec():
    stamp = stamp_from_ns(1_704_067_200_250_000_001)
    assert (stamp.sec, stamp.nanosec) == (1_704_067_200, 250_000_001)


def test_scan_message_carries_the_binning_and_survives_cdr():
    binning = ScanBinning(bins=8)
    ranges = np.array([1.0, np.inf, np.nan, 2.5, 3.0, 0.2, 4.0, 5.0], dtype=np.float32)
    msg = scan_to_ros(
        ranges,
        np.zeros(8, np.float32),
        stamp_ns=5,
        frame_id='r0/laser',
        binning=binning,
        scan_time_s=0.2,
    )
    back = cdr_roundtrip(msg)
    assert back.angle_min == pytest.approx(-math.pi)
    assert back.angle_max == pytest.approx(math.pi - 2 * math.pi / 8)
    assert back.time_increment == pytest.approx(0.2 / 8)
    assert math.isinf(back.ranges[1])
    assert math.isnan(back.ranges[2])
    assert back.header.frame_id == 'r0/laser'


def test_imu_orientation_is_the_yaw_and_covariances_follow_rep145():
    reading = ImuReading(1.0, (0.0, 0.0, 9.8), (0.0, 0.0, 0.1), math.pi / 2, 0.01, False)
    msg = cdr_roundtrip(imu_to_ros(reading, stamp_ns=0, frame_id='imu_link'))
    q = msg.orientation
    assert 2 * math.atan2(q.z, q.w) == pytest.approx(math.pi / 2)
    assert msg.orientation_covariance[8] == pytest.approx(0.01)
    assert msg.orientation_covariance[0] > 0  # roll/pitch: level within a few degrees
    assert msg.angular_velocity.z == pytest.approx(0.1)
    assert msg.angular_velocity_covariance[4] > 0


def test_gas_reading_keeps_raw_volts_and_warm_up():
    msg = cdr_roundtrip(
        gas_to_ros(GasSample(200, 0.645, 5160), warming_up=True, stamp_ns=0, frame_id='gas')
    )
    assert (msg.raw, msg.warming_up) == (200, True)
    assert msg.volts == pytest.approx(0.645)


def test_bearings_and_rssi_messages():
    bearings = [_bearing('AC'), _bearing('C3', rssi=-70.0)]
    msg = cdr_roundtrip(bearings_to_ros(bearings, stamp_ns=0, frame_id='r0/base_link'))
    assert [b.tag_id for b in msg.bearings] == ['AC', 'C3']
    assert math.isnan(msg.bearings[0].elevation)
    rssi = cdr_roundtrip(rssi_to_ros(bearings, stamp_ns=0, frame_id='r0/base_link'))
    assert [(r.emitter_id, r.rssi_dbm) for r in rssi.readings] == [(0xC3, -70.0)]


def test_no_rssi_message_when_no_tag_reported_one():
    assert rssi_to_ros([_bearing('AC')], stamp_ns=0, frame_id='x') is None


def test_diagnostic_levels_are_single_bytes():
    entry = DiagnosticEntry('n', 'hw', DiagnosticLevel.ERROR, 'stale', {'faults': '3'})
    msg = cdr_roundtrip(diagnostics_to_ros([entry], stamp_ns=0))
    assert msg.status[0].level == b'\x02'
    assert msg.status[0].values[0].key == 'faults'


def test_pump_state_is_a_bool():
    assert cdr_roundtrip(pump_state_to_ros(True)).data is True
