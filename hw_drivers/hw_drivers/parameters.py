"""The driver nodes' parameters, one frozen dataclass per node (ROS-free).

Each node declares its spec (:data:`RPLIDAR_PARAMETERS`, ...) with
:func:`swarm_runtime.parameters.declare_config` and builds its device configuration from the
dataclass; ``config/<node>.yaml``, ``--help`` and the tables in docs/hardware.md are generated
from the same specs. Every driver parameter is read-only: a device is configured when it
connects, so a change could only take effect after a reconnect.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from swarm_common.params import ParameterError, ParameterSpec, parameter

from hw_drivers.errors import ConfigurationError

__all__ = [
    'AOA_RECEIVER_PARAMETERS',
    'BACKENDS',
    'GAS_PARAMETERS',
    'MAX_AVERAGING',
    'MAX_BUFFER_BYTES',
    'MAX_CALIBRATION_S',
    'MAX_PUMP_ON_S',
    'MAX_RATE_HZ',
    'MAX_SCAN_BINS',
    'MIN_RATE_HZ',
    'MPU6050_PARAMETERS',
    'NODE_SPECS',
    'PUMP_PARAMETERS',
    'RPLIDAR_PARAMETERS',
    'STATIC_FRAMES_PARAMETERS',
    'AoaReceiverNodeConfig',
    'DriverParameterError',
    'GasNodeConfig',
    'Mpu6050NodeConfig',
    'PumpNodeConfig',
    'RPLidarNodeConfig',
    'StaticFramesNodeConfig',
    'rate_parameter',
    'required_name',
]

#: Gas ADC backends.
BACKENDS = ('ads1115', 'ads1015', 'grove_hat', 'xiao_serial')


class DriverParameterError(ConfigurationError, ParameterError):
    """A driver parameter is unknown, of the wrong type, out of range or not a choice."""


# Upper bounds of the parameters that size memory, time or a safety limit: a typo such as
# bins:=1000000000 must be a one-line parameter error, not a 4 GiB allocation at the first scan.

#: LaserScan bins: the RPLidar A1 gives at most ~8000 samples/s, ~1500 per revolution at 5.5 Hz.
MAX_SCAN_BINS = 4096
#: Undecoded locator JSON kept while an object is incomplete (a report is ~200 bytes).
#: (At most six digits: the docs print bounds with ``%g``.)
MAX_BUFFER_BYTES = 256 * 1024
#: ADS1x15 conversions per reading (64 at the slowest 8 samples/s already take 8 s).
MAX_AVERAGING = 64
#: Gyro calibration: 3-5 s are recommended; every sample of it is kept.
MAX_CALIBRATION_S = 60.0
#: Longest pump pulse a driver may allow (paper pulse: 0.5 s).
MAX_PUMP_ON_S = 60.0
#: Timer rates: a timer period must be a representable, positive number of nanoseconds.
MIN_RATE_HZ = 0.1
MAX_RATE_HZ = 1000.0

_REQUIRED_KEY = 'hw_drivers.parameters.required'


def required_name(default: str, description: str) -> Any:
    """A string parameter that names something (a device, a frame) and must not be empty."""
    spec_field = parameter(default, f'{description} (must not be empty)')
    metadata = {**spec_field.metadata, _REQUIRED_KEY: True}
    return dataclasses.field(default=default, metadata=metadata)


def rate_parameter(default: float, description: str, *, ge: float = MIN_RATE_HZ) -> Any:
    """A timer rate [Hz] in [``ge``, :data:`MAX_RATE_HZ`]."""
    return parameter(default, description, unit='Hz', ge=ge, le=MAX_RATE_HZ)


class _RequiredNames:
    """Rejects empty :func:`required_name` parameters when the configuration is built."""

    def __post_init__(self) -> None:
        for spec_field in dataclasses.fields(self):  # type: ignore[arg-type]
            if not spec_field.metadata.get(_REQUIRED_KEY):
                continue
            if not getattr(self, spec_field.name).strip():
                raise DriverParameterError(spec_field.name, 'must not be empty')


@dataclass(frozen=True)
class RPLidarNodeConfig(_RequiredNames):
    """The parameters of ``rplidar_node``."""

    port: str = required_name(
        '/dev/rplidar', 'serial device of the lidar (udev symlink or /dev/serial/by-id/...)'
    )
    baudrate: int = parameter(115200, 'serial speed (A1: 115200)', unit='baud', gt=0)
    motor_on_dtr: bool = parameter(False, 'DTR level that runs the motor (Slamtec adapters: false)')
    frame_id: str = required_name('laser', 'frame of the published scans')
    bins: int = parameter(
        360, 'LaserScan bins over [-pi, pi) (A1: ~1500 samples per turn)', ge=4, le=MAX_SCAN_BINS
    )
    angle_direction: int = parameter(
        -1, 'ROS angle = offset + direction * device angle; -1: device is CW', ge=-1, le=1
    )
    zero_offset_rad: float = parameter(
        math.pi, 'ROS angle of the device 0 deg mark; pi = Slamtec mapping', unit='rad'
    )
    range_min_m: float = parameter(
        0.15, 'shortest valid range; shorter readings become -inf (REP 117)', unit='m', ge=0.0
    )
    range_max_m: float = parameter(
        12.0, 'longest valid range; longer readings become +inf', unit='m', gt=0.0
    )
    stall_timeout_s: float = parameter(
        1.0, 'no revolution for this long restarts the motor and scan', unit='s', gt=0.0
    )
    stale_timeout_s: float = parameter(
        1.0, 'no scan published for this long is reported stale', unit='s', gt=0.0
    )
    publish_rate_hz: float = rate_parameter(
        20.0, 'rate of the timer that publishes completed revolutions'
    )
    device_thread: bool = parameter(
        True, 'run the device loop in its own thread (false: from a timer)'
    )
    fake_device: bool = parameter(
        False, 'use a synthetic lidar in a 4 m x 3 m room instead of the port'
    )


RPLIDAR_PARAMETERS = ParameterSpec(RPLidarNodeConfig, error=DriverParameterError)


@dataclass(frozen=True)
class GasNodeConfig(_RequiredNames):
    """The parameters of ``gas_adc_node``."""

    backend: str = parameter(
        'ads1115', 'ADC backend: ads1115, ads1015, grove_hat or xiao_serial', choices=BACKENDS
    )
    i2c_bus: int = parameter(1, 'I2C bus number (/dev/i2c-N)', ge=0)
    i2c_address: int = parameter(
        -1, 'I2C address; -1 = backend default (ADS1x15 0x48, Grove Base Hat 0x04)', ge=-1, le=127
    )
    channel: int = parameter(0, 'ADC input channel the sensor signal is wired to', ge=0, le=7)
    full_scale_v: float = parameter(4.096, 'ADS1x15 PGA full-scale range', unit='V', gt=0.0)
    data_rate_sps: int = parameter(128, 'ADS1x15 conversion rate', unit='samples/s', gt=0)
    averaging: int = parameter(
        4, 'ADS1x15 conversions averaged per reading', ge=1, le=MAX_AVERAGING
    )
    supply_v: float = parameter(
        3.3, 'sensor supply voltage for raw = 1023 * V_signal / V_supply', unit='V', gt=0.0
    )
    serial_port: str = required_name(
        '/dev/gas_mcu', 'serial device of the gas microcontroller (xiao_serial)'
    )
    rate_hz: float = rate_parameter(10.0, 'readings per second (authors: 10)')
    warmup_s: float = parameter(
        120.0, 'heater warm-up: readings are flagged warming_up this long', unit='s', ge=0.0
    )
    frame_id: str = required_name('gas_sensor', 'frame of the published readings')
    stale_timeout_s: float = parameter(
        1.0, 'no reading published for this long is reported stale', unit='s', gt=0.0
    )
    device_thread: bool = parameter(
        True, 'run the device loop in its own thread (false: from a timer)'
    )
    fake_device: bool = parameter(False, 'use a simulated ADC reading a clean-air background')


GAS_PARAMETERS = ParameterSpec(GasNodeConfig, error=DriverParameterError)


@dataclass(frozen=True)
class Mpu6050NodeConfig(_RequiredNames):
    """The parameters of ``mpu6050_node``."""

    i2c_bus: int = parameter(1, 'I2C bus number (/dev/i2c-N)', ge=0)
    i2c_address: int = parameter(
        0x68, 'I2C address: 0x68 (AD0 low) or 0x69 (AD0 high)', ge=0, le=127
    )
    accepted_who_am_i: tuple[int, ...] = parameter(
        (0x68,), 'WHO_AM_I values accepted (genuine MPU6050: 0x68)'
    )
    dlpf_cfg: int = parameter(
        3, 'digital low-pass filter setting 0..6 (3: 42 Hz gyro bandwidth)', ge=0, le=6
    )
    sample_rate_div: int = parameter(
        9, 'SMPLRT_DIV: internal rate = 1 kHz / (1 + div) with the DLPF on', ge=0, le=255
    )
    gyro_fs_sel: int = parameter(0, 'gyro range 0..3 = +-250, 500, 1000, 2000 deg/s', ge=0, le=3)
    accel_afs_sel: int = parameter(0, 'accelerometer range 0..3 = +-2, 4, 8, 16 g', ge=0, le=3)
    rate_hz: float = rate_parameter(100.0, 'polling and publishing rate')
    mounting: str = parameter(
        'z_up', 'board orientation: z_up, or z_down (upside down)', choices=('z_up', 'z_down')
    )
    calibration_s: float = parameter(
        4.0,
        'still time for the gyro-Z bias calibration at start',
        unit='s',
        gt=0.0,
        le=MAX_CALIBRATION_S,
    )
    calibration_max_std_dps: float = parameter(
        0.3, 'gyro-Z spread above which the robot moved', unit='deg/s', gt=0.0
    )
    zupt: bool = parameter(
        True, 'track the gyro-Z bias while cmd_vel has been zero for zupt_hold_s'
    )
    zupt_hold_s: float = parameter(
        1.0, 'how long cmd_vel must be zero before the bias is tracked', unit='s', ge=0.0
    )
    zupt_time_constant_s: float = parameter(
        20.0, 'time constant of the bias tracking', unit='s', gt=0.0
    )
    frame_id: str = required_name('imu_link', 'frame of the published messages')
    stale_timeout_s: float = parameter(
        0.5, 'no message published for this long is reported stale', unit='s', gt=0.0
    )
    device_thread: bool = parameter(
        True, 'run the device loop in its own thread (false: from a timer)'
    )
    fake_device: bool = parameter(False, 'use a simulated, motionless MPU6050')


MPU6050_PARAMETERS = ParameterSpec(Mpu6050NodeConfig, error=DriverParameterError)


@dataclass(frozen=True)
class AoaReceiverNodeConfig(_RequiredNames):
    """The parameters of ``aoa_receiver_node``."""

    listen_host: str = required_name('127.0.0.1', 'address the locator connects to (keep loopback)')
    listen_port: int = parameter(
        8080, 'TCP port the locator connects to (authors: 8080)', ge=0, le=65535
    )
    own_tag_id: str = parameter('', "this robot's own tag id (e.g. D2), never reported as a peer")
    azimuth_sign: int = parameter(
        1, 'robot azimuth = sign * locator azimuth + offset; -1 flips handedness', ge=-1, le=1
    )
    azimuth_offset_rad: float = parameter(
        0.0, "robot-frame azimuth of the array's 0 deg direction", unit='rad'
    )
    publish_rate_hz: float = rate_parameter(10.0, 'rate of bearing publishes')
    max_buffer_bytes: int = parameter(
        16384, 'undecoded JSON beyond this is dropped', unit='bytes', ge=64, le=MAX_BUFFER_BYTES
    )
    frame_id: str = required_name('base_link', 'frame of the published bearings (robot frame)')
    stale_timeout_s: float = parameter(
        2.0, 'no bearing published for this long is reported stale', unit='s', gt=0.0
    )
    device_thread: bool = parameter(
        True, 'run the server loop in its own thread (false: from a timer)'
    )


AOA_RECEIVER_PARAMETERS = ParameterSpec(AoaReceiverNodeConfig, error=DriverParameterError)


@dataclass(frozen=True)
class PumpNodeConfig(_RequiredNames):
    """The parameters of ``pump_node``."""

    chip: str = required_name(
        '/dev/gpiochip0', 'GPIO chip device (Pi 4 40-pin header: /dev/gpiochip0)'
    )
    line: str = required_name(
        'GPIO17', "GPIO line name (GPIO17) or offset as a string ('17'); authors: BCM 17"
    )
    active_low: bool = parameter(
        False, 'true if the driver stage is inverting (line low = pump on)'
    )
    max_on_s: float = parameter(
        1.0,
        'longest pulse the driver allows (paper pulse: 0.5 s)',
        unit='s',
        gt=0.0,
        le=MAX_PUMP_ON_S,
    )
    min_off_s: float = parameter(1.0, 'shortest pause between pulses', unit='s', ge=0.0)
    command_timeout_s: float = parameter(
        0.5, 'commands older than this turn the pump off', unit='s', gt=0.0, le=MAX_PUMP_ON_S
    )
    control_rate_hz: float = rate_parameter(50.0, 'rate of the safety check', ge=1.0)
    fake_device: bool = parameter(False, 'drive a simulated line instead of a GPIO')


PUMP_PARAMETERS = ParameterSpec(PumpNodeConfig, error=DriverParameterError)


@dataclass(frozen=True)
class StaticFramesNodeConfig:
    """The parameters of ``static_frames_node`` (mounting positions in base_link)."""

    frame_prefix: str = parameter(
        '', "prefix of every frame id, e.g. 'r0/' (robot_bringup sets it)"
    )
    laser_xyz_m: tuple[float, float, float] = parameter(
        (0.0, 0.0, 0.0), 'lidar position in base_link: x forward, y left, z up', unit='m'
    )
    imu_xyz_m: tuple[float, float, float] = parameter(
        (0.0, 0.0, 0.0), 'IMU position in base_link', unit='m'
    )
    gas_sensor_xyz_m: tuple[float, float, float] = parameter(
        (0.08, 0.0, 0.0), 'gas sensor position in base_link', unit='m'
    )


STATIC_FRAMES_PARAMETERS = ParameterSpec(StaticFramesNodeConfig, error=DriverParameterError)

#: Node name -> parameter spec, for the tools that handle every driver.
NODE_SPECS: dict[str, ParameterSpec] = {
    'rplidar_node': RPLIDAR_PARAMETERS,
    'gas_adc_node': GAS_PARAMETERS,
    'mpu6050_node': MPU6050_PARAMETERS,
    'aoa_receiver_node': AOA_RECEIVER_PARAMETERS,
    'pump_node': PUMP_PARAMETERS,
    'static_frames_node': STATIC_FRAMES_PARAMETERS,
}
