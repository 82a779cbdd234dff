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
    ParamSpec,
    TimerGate,
    declare_parameter_table,
    no_sleep,
    publish_diagnostics,
    run_driver_node,
    seconds_clock,
)
from hw_drivers.serial_transport import SerialPort, open_serial_port
from hw_drivers.worker import DeviceWorker, DiagnosticLevel

__all__ = ['BACKENDS', 'PARAMETERS', 'GasNode', 'main']

swarm_interfaces = message_module('swarm_interfaces')
diagnostic_msgs = message_module('diagnostic_msgs')

BACKENDS = ('ads1115', 'ads1015', 'grove_hat', 'xiao_serial')

PARAMETERS: list[ParamSpec] = [
    ('backend', 'ads1115', 'ADC backend: ads1115, ads1015, grove_hat or xiao_serial'),
    ('i2c_bus', 1, 'I2C bus number (/dev/i2c-N)'),
    ('i2c_address', -1, 'I2C address; -1 = backend default (ADS1x15 0x48, Grove Base Hat 0x04)'),
    ('channel', 0, 'ADC input channel the sensor signal is wired to'),
    ('full_scale_v', 4.096, 'ADS1x15 PGA full-scale range [V]'),
    ('data_rate_sps', 128, 'ADS1x15 conversion rate [samples/s]'),
    ('averaging', 4, 'ADS1x15 conversions averaged per reading'),
    ('supply_v', 3.3, 'sensor supply voltage [V] for raw = 1023 * V_signal / V_supply'),
    ('serial_port', '/dev/gas_mcu', 'serial device of the gas microcontroller (xiao_serial)'),
    ('rate_hz', 10.0, 'readings per second [Hz] (authors: 10)'),
    ('warmup_s', 120.0, 'heater warm-up: readings are flagged warming_up this long [s]'),
    ('frame_id', 'gas_sensor', 'frame of the published readings'),
    ('stale_timeout_s', 1.0, 'no reading published for this long is reported stale [s]'),
    ('device_thread', True, 'run the device loop in its own thread (false: from a timer)'),
    ('fake_device', False, 'use a simulated ADC reading a clean-air background'),
]

_DEFAULT_ADDRESS = {'ads1115': 0x48, 'ads1015': 0x48, 'grove_hat': 0x04}
FAKE_BACKGROUND_V = 0.26  # about 80 on the 10-bit scale: clean air after warm-up


class GasNode(Node):
    """Publishes gas readings on ``gas``."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('gas_adc_node', **kwargs)
        values = declare_parameter_table(self, PARAMETERS)
        self._values = values
        backend = str(values['backend'])
        if backend not in BACKENDS:
            raise ConfigurationError(f'backend must be one of {", ".join(BACKENDS)}, got {backend}')
        self._backend_name = backend
        self._threaded = bool(values['device_thread'])
        self._device_clock: Callable[[], float] = (
            time.monotonic if self._threaded else seconds_clock(self)
        )
        self._sleep: Callable[[float], None] = time.sleep if self._threaded else no_sleep
        self._fake = bool(values['fake_device'])
        self._ads_config: AdsConfig | None = None
        if backend.startswith('ads'):
            self._ads_config = AdsConfig(
                chip=AdsChip(backend),
                channel=int(values['channel']),
                full_scale_v=float(values['full_scale_v']),
                data_rate_sps=int(values['data_rate_sps']),
            )
        address = int(values['i2c_address'])
        self._address = _DEFAULT_ADDRESS.get(backend, 0) if address < 0 else address
        self._rate_hz = float(values['rate_hz'])
        if not self._rate_hz > 0.0:
            raise ConfigurationError(f'rate_hz must be > 0, got {self._rate_hz}')
        self._warm_up = WarmUp(duration_s=float(values['warmup_s']))
        self._frame_id = str(values['frame_id'])
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
            hardware_id = str(values['serial_port'])
        else:
            hardware_id = f'/dev/i2c-{values["i2c_bus"]} 0x{self._address:02X}'
        self._monitor = DeviceMonitor(
            f'{self.get_fully_qualified_name()}: gas ({backend})',
            'fake' if self._fake else hardware_id,
            float(values['stale_timeout_s']),
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
            return open_smbus(int(self._values['i2c_bus']))
        if self._backend_name == 'grove_hat':
            hat = FakeGroveHat()
            hat.channel_mv[int(self._values['channel'])] = round(FAKE_BACKGROUND_V * 1000)
            return FakeSMBus({self._address: hat})
        chip = FakeAds1115(self._device_clock, volts=FAKE_BACKGROUND_V, conversion_time_s=0.0)
        return FakeSMBus({self._address: chip})

    def _open_port(self) -> SerialPort:
        if self._fake:
            return FakeGasMcuPort(FakeGasMcu(lambda: round(1023 * FAKE_BACKGROUND_V / 3.3)))
        return open_serial_port(str(self._values['serial_port']), baudrate=115200, timeout_s=0.05)

    def _make_backend(self) -> GasBackend:
        values = self._values
        if self._backend_name == 'xiao_serial':
            return XiaoGasBackend(self._open_port(), clock=self._device_clock)
        bus = self._open_bus()
        try:
            if self._backend_name == 'grove_hat':
                return GroveHatGasBackend(
                    bus, address=self._address, channel=int(values['channel'])
                )
            return AdsGasBackend(
                bus,
                address=self._address,
                config=self._ads_config,
                supply_v=float(values['supply_v']),
                averaging=int(values['averaging']),
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
        GasNode, 'gas_adc_node', args, summary=__doc__ or '', parameters=PARAMETERS
    )


if __name__ == '__main__':
    raise SystemExit(main())
