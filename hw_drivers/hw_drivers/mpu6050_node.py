"""MPU6050 node: publishes ``imu`` (sensor_msgs/Imu, orientation = integrated yaw) and
/diagnostics.

At start the robot must stand still for ``calibration_s`` while the gyro-Z bias is measured;
nothing is published before that (a wrong bias would make every heading wrong). If the robot
moves during calibration, it is repeated. Afterwards, whenever ``cmd_vel`` has been zero for
``zupt_hold_s``, the bias slowly follows the measured rate (zero-velocity update), which
removes most warm-up drift. After a reconnect (brown-out, loose cable) the yaw continues
from where it was.

Run: ``ros2 run hw_drivers mpu6050_node --ros-args -r __ns:=/r0 -p i2c_bus:=1``.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import (
    Node,
    message_module,
    qos_profile_sensor_data,
)

from hw_drivers.backoff import BackoffConfig
from hw_drivers.conversions import imu_to_ros
from hw_drivers.errors import ConfigurationError
from hw_drivers.fakes.i2c import FakeMpu6050, FakeSMBus
from hw_drivers.heading import CalibrationConfig, StillnessDetector, ZuptConfig
from hw_drivers.i2c_transport import SMBusLike, open_smbus
from hw_drivers.mpu6050_device import HeadingState, ImuReading, ImuSession, Mounting, Mpu6050
from hw_drivers.mpu6050_protocol import Mpu6050Config
from hw_drivers.node_common import (
    DIAGNOSTICS_TOPIC,
    DeviceMonitor,
    DevicePoller,
    TimerGate,
    no_sleep,
    publish_diagnostics,
    run_driver_node,
    seconds_clock,
)
from hw_drivers.parameters import MPU6050_PARAMETERS
from hw_drivers.worker import DeviceWorker

__all__ = ['Mpu6050Node', 'main']

sensor_msgs = message_module('sensor_msgs')
geometry_msgs = message_module('geometry_msgs')
diagnostic_msgs = message_module('diagnostic_msgs')


class Mpu6050Node(Node):
    """Publishes calibrated IMU readings with the integrated yaw on ``imu``."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('mpu6050_node', **kwargs)
        config = declare_config(self, MPU6050_PARAMETERS).config
        self._config = config
        self._chip_config = Mpu6050Config(
            address=config.i2c_address,
            accepted_who_am_i=tuple(int(v) for v in config.accepted_who_am_i),
            dlpf_cfg=config.dlpf_cfg,
            sample_rate_div=config.sample_rate_div,
            gyro_fs_sel=config.gyro_fs_sel,
            accel_afs_sel=config.accel_afs_sel,
        )
        try:
            self._mounting = Mounting(config.mounting)
        except ValueError as err:
            raise ConfigurationError(f'mounting must be z_up or z_down: {err}') from err
        self._rate_hz = config.rate_hz
        if not self._rate_hz > 0.0:
            raise ConfigurationError(f'rate_hz must be > 0, got {self._rate_hz}')
        zupt = ZuptConfig(
            enabled=config.zupt,
            hold_s=config.zupt_hold_s,
            time_constant_s=config.zupt_time_constant_s,
        )
        self._heading = HeadingState(
            CalibrationConfig(
                duration_s=config.calibration_s,
                max_std_radps=math.radians(config.calibration_max_std_dps),
            ),
            stillness=StillnessDetector(zupt),
        )
        self._frame_id = config.frame_id
        self._threaded = config.device_thread
        self._device_clock: Callable[[], float] = (
            time.monotonic if self._threaded else seconds_clock(self)
        )
        self._sleep: Callable[[float], None] = time.sleep if self._threaded else no_sleep
        self._fake_chip = (
            FakeMpu6050(self._device_clock, noise_dps=0.02, seed=1) if config.fake_device else None
        )
        self._readings: deque[ImuReading] = deque(maxlen=50)
        self._session: ImuSession | None = None
        self._imu_pub = self.create_publisher(sensor_msgs.Imu, 'imu', qos_profile_sensor_data)
        self.create_subscription(geometry_msgs.Twist, 'cmd_vel', self._on_cmd_vel, 10)
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        hardware_id = f'/dev/i2c-{config.i2c_bus} 0x{self._chip_config.address:02X}'
        self._monitor = DeviceMonitor(
            f'{self.get_fully_qualified_name()}: imu',
            'fake' if self._fake_chip else hardware_id,
            config.stale_timeout_s,
            self.get_logger(),
        )
        worker = DeviceWorker(
            'imu', self._connect, backoff=BackoffConfig(), clock=self._device_clock
        )
        self._poller = DevicePoller(
            self, worker, threaded=self._threaded, poll_period_s=1.0 / self._rate_hz
        )
        self._reading_gate = TimerGate(
            self.create_timer(1.0 / self._rate_hz, self._publish_readings)
        )
        self.create_timer(1.0, self._publish_diagnostics)

    def _on_cmd_vel(self, msg: Any) -> None:
        moving = any(
            v != 0.0
            for v in (msg.linear.x, msg.linear.y, msg.angular.z, msg.angular.x, msg.angular.y)
        )
        self._heading.stillness.command(self._device_clock(), moving)

    def _open_bus(self) -> SMBusLike:
        if self._fake_chip is not None:
            return FakeSMBus({self._chip_config.address: self._fake_chip})
        return open_smbus(int(self._config.i2c_bus))

    def _connect(self) -> ImuSession:
        bus = self._open_bus()
        device = Mpu6050(bus, self._chip_config, sleep=self._sleep)
        try:
            device.initialise()
        except BaseException:
            bus.close()
            raise
        self._session = ImuSession(
            device,
            self._heading,
            self._readings.append,
            rate_hz=self._rate_hz,
            mounting=self._mounting,
            sleep=self._sleep,
            clock=self._device_clock,
        )
        return self._session

    def _publish_readings(self) -> None:
        while self._readings:
            reading = self._readings.popleft()
            now_ns = self.get_clock().now().nanoseconds
            age_ns = round(max(self._device_clock() - reading.time_s, 0.0) * 1e9)
            self._imu_pub.publish(
                imu_to_ros(reading, stamp_ns=now_ns - age_ns, frame_id=self._frame_id)
            )
            self._monitor.mark_data(now_ns)

    def _publish_diagnostics(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        heading = self._heading
        quiet_reason = ''
        extra = {'calibration_failures': str(heading.calibration_failures)}
        if not heading.calibrated and self._poller.worker.connected:
            quiet_reason = 'calibrating gyro bias: keep the robot still'
            if heading.last_calibration_error:
                quiet_reason += f' (last attempt: {heading.last_calibration_error})'
        elif heading.integrator is not None:
            extra['gyro_z_bias_dps'] = f'{math.degrees(heading.integrator.bias_radps):.4f}'
            extra['yaw_deg'] = f'{math.degrees(heading.integrator.yaw_rad):.2f}'
            extra['dt_outliers'] = str(heading.integrator.dt_outliers)
            extra['zupt_updates'] = str(heading.zupt_updates)
        if self._session is not None:
            extra['read_errors'] = str(self._session.read_errors)
            extra['saturations'] = str(self._session.saturations)
        entry = self._monitor.entry(now_ns, self._poller.worker, extra, quiet_reason=quiet_reason)
        publish_diagnostics(self._diag_pub, [entry], now_ns)
        self._reading_gate.update(self._poller.worker.connected or bool(self._readings))

    def destroy_node(self) -> None:
        """Stop the device loop and close the bus before the node goes."""
        self._poller.stop()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers mpu6050_node``."""
    return run_driver_node(
        Mpu6050Node, 'mpu6050_node', args, summary=__doc__ or '', parameters=MPU6050_PARAMETERS
    )


if __name__ == '__main__':
    raise SystemExit(main())
