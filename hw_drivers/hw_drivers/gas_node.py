"""MP503 gas sensor node: publishes ``gas`` (swarm_interfaces/GasReading) and /diagnostics.

Backends (parameter ``backend``): ``ads1115`` / ``ads1015`` (TI ADC on I2C), ``grove_hat``
(Seeed Grove Base Hat), ``xiao_serial`` (the authors' Seeed XIAO M0 answering JSON over USB
serial). Every reading is put on the paper's 10-bit scale (``raw``) and flagged
``warming_up`` for the first ``warmup_s`` seconds so that OA-Bug ignores it.

Run: ``ros2 run hw_drivers gas_adc_node --ros-args -r __ns:=/r0 -p backend:=ads1115``.
"""

from __future__ import annotations

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
from hw_drivers.conversions import gas_to_ros
from hw_drivers.errors import ConfigurationError
from hw_drivers.fakes.gas_mcu import FakeGasMcu, FakeGasMcuPort
from hw_drivers.fakes.i2c import FakeAds1115, FakeGroveHat, FakeSMBus
from hw_drivers.gas_device import (
    AdsGasBackend,
    GasBackend,
    GasSample,
    GasSession,
    GroveHatGasBackend,
    WarmUp,
    XiaoGasBackend,
)
from hw_drivers.gas_protocol import AdsChip, AdsConfig
from hw_drivers.i2c_transport import SMBusLike, open_smbus
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
from hw_drivers.parameters import GAS_PARAMETERS
from hw_drivers.serial_transport import SerialPort, open_serial_port
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = ['GasNode', 'main']

swarm_interfaces = message_module('swarm_interfaces')
diagnostic_msgs = message_module('diagnostic_msgs')


_DEFAULT_ADDRESS = {'ads1115': 0x48, 'ads1015': 0x48, 'grove_hat': 0x04}
FAKE_BACKGROUND_V = 0.26  # about 80 on the 10-bit scale: clean air after warm-up


class GasNode(Node):
    """Publishes gas readings on ``gas``."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('gas_adc_node', **kwargs)
        config = declare_config(self, GAS_PARAMETERS).config
        self._config = config
        backend = config.backend
        self._backend_name = backend
        self._threaded = config.device_thread
        self._device_clock: Callable[[], float] = (
            time.monotonic if self._threaded else seconds_clock(self)
        )
        self._sleep: Callable[[float], None] = time.sleep if self._threaded else no_sleep
        self._fake = config.fake_device
        self._ads_config: AdsConfig | None = None
        if backend.startswith('ads'):
            self._ads_config = AdsConfig(
                chip=AdsChip(backend),
                channel=config.channel,
                full_scale_v=config.full_scale_v,
                data_rate_sps=config.data_rate_sps,
            )
        address = config.i2c_address
        self._address = _DEFAULT_ADDRESS.get(backend, 0) if address < 0 else address
        self._rate_hz = config.rate_hz
        if not self._rate_hz > 0.0:
            raise ConfigurationError(f'rate_hz must be > 0, got {self._rate_hz}')
        self._warm_up = WarmUp(duration_s=config.warmup_s)
        self._frame_id = config.frame_id
        self._samples: deque[tuple[GasSample, bool, float]] = deque(maxlen=10)
        self._session: GasSession | None = None
        self._pinned = False
        self._gas_pub = self.create_publisher(
            swarm_interfaces.GasReading, 'gas', qos_profile_sensor_data
        )
        self._diag_pub = self.create_publisher(
            diagnostic_msgs.DiagnosticArray, DIAGNOSTICS_TOPIC, 10
        )
        if backend == 'xiao_serial':
            hardware_id = config.serial_port
        else:
            hardware_id = f'/dev/i2c-{config.i2c_bus} 0x{self._address:02X}'
        self._monitor = DeviceMonitor(
            f'{self.get_fully_qualified_name()}: gas ({backend})',
            'fake' if self._fake else hardware_id,
            config.stale_timeout_s,
            self.get_logger(),
        )
        worker = DeviceWorker(
            'gas', self._connect, backoff=BackoffConfig(), clock=self._device_clock
        )
        self._poller = DevicePoller(self, worker, threaded=self._threaded)
        self._sample_gate = TimerGate(self.create_timer(0.5 / self._rate_hz, self._publish_samples))
        self.create_timer(1.0, self._publish_diagnostics)

    def _open_bus(self) -> SMBusLike:
        if not self._fake:
            return open_smbus(int(self._config.i2c_bus))
        if self._backend_name == 'grove_hat':
            hat = FakeGroveHat()
            hat.channel_mv[int(self._config.channel)] = round(FAKE_BACKGROUND_V * 1000)
            return FakeSMBus({self._address: hat})
        chip = FakeAds1115(self._device_clock, volts=FAKE_BACKGROUND_V, conversion_time_s=0.0)
        return FakeSMBus({self._address: chip})

    def _open_port(self) -> SerialPort:
        if self._fake:
            return FakeGasMcuPort(FakeGasMcu(lambda: round(1023 * FAKE_BACKGROUND_V / 3.3)))
        return open_serial_port(str(self._config.serial_port), baudrate=115200, timeout_s=0.05)

    def _make_backend(self) -> GasBackend:
        config = self._config
        if self._backend_name == 'xiao_serial':
            return XiaoGasBackend(self._open_port(), clock=self._device_clock)
        bus = self._open_bus()
        try:
            if self._backend_name == 'grove_hat':
                return GroveHatGasBackend(bus, address=self._address, channel=config.channel)
            return AdsGasBackend(
                bus,
                address=self._address,
                config=self._ads_config,
                supply_v=config.supply_v,
                averaging=config.averaging,
                sleep=self._sleep,
                clock=self._device_clock,
            )
        except BaseException:
            bus.close()
            raise

    def _connect(self) -> GasSession:
        self._session = GasSession(
            self._make_backend(),
            self._on_sample,
            rate_hz=self._rate_hz,
            warm_up=self._warm_up,
            sleep=self._sleep,
            clock=self._device_clock,
        )
        return self._session

    def _on_sample(self, sample: GasSample, warming_up: bool) -> None:
        self._samples.append((sample, warming_up, self._device_clock()))

    def _publish_samples(self) -> None:
        while self._samples:
            sample, warming_up, read_s = self._samples.popleft()
            now_ns = self.get_clock().now().nanoseconds
            age_ns = round(max(self._device_clock() - read_s, 0.0) * 1e9)
            self._pinned = sample.pinned
            self._gas_pub.publish(
                gas_to_ros(
                    sample, warming_up=warming_up, stamp_ns=now_ns - age_ns, frame_id=self._frame_id
                )
            )
            self._monitor.mark_data(now_ns)

    def _publish_diagnostics(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        note = None
        if self._pinned:
            note = (DiagnosticLevel.WARN, 'gas reading pinned at 0 or full scale: check wiring')
        elif self._warm_up.started_s is not None and self._warm_up.warming_up(self._device_clock()):
            note = (DiagnosticLevel.WARN, 'gas sensor heater warming up')
        extra = {}
        if self._session is not None:
            extra = {'skipped_replies': str(self._session.skipped)}
        entry = self._monitor.entry(now_ns, self._poller.worker, extra, note=note)
        publish_diagnostics(self._diag_pub, [entry], now_ns)
        self._sample_gate.update(self._poller.worker.connected or bool(self._samples))

    def destroy_node(self) -> None:
        """Stop the device loop and close the ADC before the node goes."""
        self._poller.stop()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers gas_adc_node``."""
    return run_driver_node(
        GasNode, 'gas_adc_node', args, summary=__doc__ or '', parameters=GAS_PARAMETERS
    )


if __name__ == '__main__':
    raise SystemExit(main())
