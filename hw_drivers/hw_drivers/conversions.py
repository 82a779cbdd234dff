"""Pure translations from the drivers' readings to ROS messages.

Stateless ``*_to_ros`` functions; times are integer nanoseconds of the node clock. Float
fields get Python floats, integer fields Python ints and numeric sequences ``array.array``,
so the messages pass rosidl's field checks (ROS_PYTHON_CHECK_FIELDS=1). Conventions: REP 103
(metres, radians, counter-clockwise), REP 117 (inf/NaN in LaserScan), REP 145 (Imu
covariances; orientation carries the integrated yaw).
"""

from __future__ import annotations

import array
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from swarm_common.angles import yaw_to_quaternion
from swarm_common.stamps import stamp_from_ns as _stamp_from_ns
from swarm_runtime.ros import message_module

from hw_drivers.aoa_bearings import PeerBearingData
from hw_drivers.aoa_protocol import tag_emitter_id
from hw_drivers.gas_device import GasSample
from hw_drivers.mpu6050_device import ImuReading
from hw_drivers.rplidar_protocol import ScanBinning
from hw_drivers.worker import DiagnosticLevel

__all__ = [
    'ACCEL_VARIANCE_MPS2_SQ',
    'GYRO_VARIANCE_RADPS_SQ',
    'LEVEL_VARIANCE_RAD_SQ',
    'DiagnosticEntry',
    'bearings_to_ros',
    'diagnostics_to_ros',
    'gas_to_ros',
    'imu_to_ros',
    'pump_state_to_ros',
    'rssi_to_ros',
    'scan_to_ros',
    'stamp_from_ns',
    'yaw_to_quaternion',
]

_builtin = message_module('builtin_interfaces')
_std = message_module('std_msgs')
_sensor = message_module('sensor_msgs')
_diag = message_module('diagnostic_msgs')
_swarm = message_module('swarm_interfaces')

# MPU6050 datasheet noise densities over the default 42 Hz DLPF bandwidth:
# gyro 0.005 deg/s/sqrt(Hz) -> ~0.032 deg/s rms; accel 400 ug/sqrt(Hz) -> ~2.6 mg rms.
GYRO_VARIANCE_RADPS_SQ = math.radians(0.005 * math.sqrt(42.0)) ** 2
ACCEL_VARIANCE_MPS2_SQ = (400e-6 * math.sqrt(44.0) * 9.80665) ** 2
# Roll and pitch are not estimated: a ground robot is taken as level within about 2 degrees.
LEVEL_VARIANCE_RAD_SQ = math.radians(2.0) ** 2


def stamp_from_ns(stamp_ns: int) -> Any:
    """builtin_interfaces/Time of a node-clock time in nanoseconds."""
    return _stamp_from_ns(max(int(stamp_ns), 0), _builtin.Time)


def _header(stamp_ns: int, frame_id: str) -> Any:
    return _std.Header(stamp=stamp_from_ns(stamp_ns), frame_id=frame_id)


def scan_to_ros(
    ranges_m: npt.NDArray[np.float32],
    intensities: npt.NDArray[np.float32],
    *,
    stamp_ns: int,
    frame_id: str,
    binning: ScanBinning,
    scan_time_s: float,
) -> Any:
    """sensor_msgs/LaserScan of one binned revolution (bins over [-pi, pi), CCW)."""
    increment = binning.angle_increment_rad
    scan_time_s = float(scan_time_s) if math.isfinite(scan_time_s) and scan_time_s > 0 else 0.0
    return _sensor.LaserScan(
        header=_header(stamp_ns, frame_id),
        angle_min=binning.angle_min_rad,
        angle_max=binning.angle_min_rad + increment * (binning.bins - 1),
        angle_increment=increment,
        time_increment=scan_time_s / binning.bins,
        scan_time=scan_time_s,
        range_min=float(binning.range_min_m),
        range_max=float(binning.range_max_m),
        ranges=array.array('f', np.asarray(ranges_m, dtype=np.float32).tobytes()),
        intensities=array.array('f', np.asarray(intensities, dtype=np.float32).tobytes()),
    )


def _diagonal(xx: float, yy: float, zz: float) -> list[float]:
    return [float(xx), 0.0, 0.0, 0.0, float(yy), 0.0, 0.0, 0.0, float(zz)]


def imu_to_ros(reading: ImuReading, *, stamp_ns: int, frame_id: str) -> Any:
    """sensor_msgs/Imu: yaw-only orientation, bias-corrected rates, acceleration with gravity."""
    msg = _sensor.Imu(header=_header(stamp_ns, frame_id))
    x, y, z, w = yaw_to_quaternion(reading.yaw_rad)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = x, y, z, w
    msg.orientation_covariance = _diagonal(
        LEVEL_VARIANCE_RAD_SQ, LEVEL_VARIANCE_RAD_SQ, reading.yaw_variance
    )
    gx, gy, gz = reading.gyro_radps
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gx, gy, gz
    msg.angular_velocity_covariance = _diagonal(*(GYRO_VARIANCE_RADPS_SQ,) * 3)
    ax, ay, az = reading.accel_mps2
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
    msg.linear_acceleration_covariance = _diagonal(*(ACCEL_VARIANCE_MPS2_SQ,) * 3)
    return msg


def gas_to_ros(sample: GasSample, *, warming_up: bool, stamp_ns: int, frame_id: str) -> Any:
    """swarm_interfaces/GasReading on the paper's 10-bit scale."""
    return _swarm.GasReading(
        header=_header(stamp_ns, frame_id),
        raw=int(sample.raw10),
        volts=float(sample.volts),
        warming_up=bool(warming_up),
    )


def bearings_to_ros(bearings: Sequence[PeerBearingData], *, stamp_ns: int, frame_id: str) -> Any:
    """swarm_interfaces/PeerBearingArray of the tags heard since the last publish."""
    return _swarm.PeerBearingArray(
        header=_header(stamp_ns, frame_id),
        bearings=[
            _swarm.PeerBearing(
                tag_id=b.tag_id,
                azimuth=float(b.azimuth_rad),
                elevation=float(b.elevation_rad),
                distance=float(b.distance_m),
                quality=int(b.quality),
                sequence=int(b.sequence),
            )
            for b in bearings
        ],
    )


def rssi_to_ros(bearings: Sequence[PeerBearingData], *, stamp_ns: int, frame_id: str) -> Any | None:
    """swarm_interfaces/RssiArray of the tags whose report carried an RSSI; None if none did."""
    readings = []
    for b in bearings:
        emitter_id = tag_emitter_id(b.tag_id)
        if emitter_id is not None and math.isfinite(b.rssi_dbm):
            readings.append(_swarm.EmitterRssi(emitter_id=emitter_id, rssi_dbm=float(b.rssi_dbm)))
    if not readings:
        return None
    return _swarm.RssiArray(header=_header(stamp_ns, frame_id), readings=readings)


def pump_state_to_ros(on: bool) -> Any:
    """std_msgs/Bool of the pump's actual state."""
    return _std.Bool(data=bool(on))


@dataclass(frozen=True)
class DiagnosticEntry:
    """One device's status for /diagnostics."""

    name: str
    hardware_id: str
    level: DiagnosticLevel
    message: str
    values: Mapping[str, str]


def diagnostics_to_ros(entries: Iterable[DiagnosticEntry], *, stamp_ns: int) -> Any:
    """diagnostic_msgs/DiagnosticArray (the level is a one-byte ``bytes``, as rosidl wants)."""
    return _diag.DiagnosticArray(
        header=_header(stamp_ns, ''),
        status=[
            _diag.DiagnosticStatus(
                level=bytes((int(e.level),)),
                name=e.name,
                message=e.message,
                hardware_id=e.hardware_id,
                values=[_diag.KeyValue(key=k, value=str(v)) for k, v in e.values.items()],
            )
            for e in entries
        ],
    )
