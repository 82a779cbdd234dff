"""MPU6050: data block decoding, identity and init, faults, calibration, yaw integration."""

import errno
import math

import pytest
from hw_drivers.errors import (
    CalibrationError,
    ConfigurationError,
    DeviceIdentityError,
    DeviceTimeoutError,
    DeviceUnavailableError,
    ProtocolError,
)
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.fakes.i2c import FakeMpu6050, FakeSMBus
from hw_drivers.heading import (
    BiasCalibrator,
    CalibrationConfig,
    StillnessDetector,
    YawIntegrator,
    ZuptConfig,
    track_bias,
    wrap_pi,
)
from hw_drivers.mpu6050_device import HeadingState, ImuSession, Mounting, Mpu6050
from hw_drivers.mpu6050_protocol import Mpu6050Config, decode_data_block, scale_sample
from hw_drivers.worker import DeviceWorker, DiagnosticLevel


def test_data_block_is_big_endian_signed_words():
    block = [0x40, 0x00, 0xFF, 0xFF, 0x80, 0x00, 0x00, 0x00, 0x00, 0x83, 0x7F, 0xFF, 0xFF, 0x7D]
    raw = decode_data_block(block)
    assert raw.accel == (16384, -1, -32768)
    assert raw.gyro == (131, 32767, -131)
    assert raw.saturated


def test_scaling_uses_the_configured_ranges():
    raw = decode_data_block([0x40, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 131])
    sample = scale_sample(raw, Mpu6050Config())
    assert sample.accel_mps2[0] == pytest.approx(9.80665)
    assert sample.gyro_radps[2] == pytest.approx(math.radians(1.0))
    assert sample.temperature_c == pytest.approx(36.53)
    sample = scale_sample(raw, Mpu6050Config(gyro_fs_sel=3, accel_afs_sel=1))
    assert sample.accel_mps2[0] == pytest.approx(2 * 9.80665)
    assert sample.gyro_radps[2] == pytest.approx(math.radians(131 / 16.4))


def test_short_data_block_is_a_protocol_error():
    with pytest.raises(ProtocolError, match='14 bytes'):
        decode_data_block([0] * 13)


def test_default_configuration_samples_at_100_hz():
    assert Mpu6050Config().sample_rate_hz == pytest.approx(100.0)


@pytest.mark.parametrize('kwargs', [{'address': 0x50}, {'dlpf_cfg': 7}, {'gyro_fs_sel': 4}])
def test_impossible_mpu_configuration_is_refused(kwargs):
    with pytest.raises(ConfigurationError):
        Mpu6050Config(**kwargs)


def _chip(**kwargs):
    clock = FakeClock()
    chip = FakeMpu6050(clock, **kwargs)
    bus = FakeSMBus({0x68: chip})
    return Mpu6050(bus, Mpu6050Config(), sleep=clock.sleep), chip, bus, clock


def test_initialise_wakes_the_chip_and_writes_the_configuration():
    device, chip, _, _ = _chip()
    assert chip.registers[0x6B] == 0x40  # asleep at power-up
    device.initialise()
    assert chip.registers[0x6B] == 0x01
    assert (chip.registers[0x1A], chip.registers[0x19], chip.registers[0x1B]) == (3, 9, 0)


def test_who_am_i_mismatch_is_a_clear_identity_error():
    device, _, _, _ = _chip(who_am_i=0x70)
    with pytest.raises(DeviceIdentityError, match=r'0x70, expected 0x68 \(MPU-6500'):
        device.initialise()


def test_accepted_clone_identity_is_configurable():
    clock = FakeClock()
    bus = FakeSMBus({0x68: FakeMpu6050(clock, who_am_i=0x70)})
    config = Mpu6050Config(accepted_who_am_i=(0x68, 0x70))
    device = Mpu6050(bus, config, sleep=clock.sleep)
    device.initialise()  # the clone's 0x70 is accepted: configured, not refused
    assert device.config_intact()


def test_missing_chip_nacks_as_device_unavailable():
    clock = FakeClock()
    device = Mpu6050(FakeSMBus({}), Mpu6050Config(), sleep=clock.sleep)
    with pytest.raises(DeviceUnavailableError, match='NACK'):
        device.initialise()


def test_bus_timeout_during_init_is_a_timeout_error():
    device, _, bus, _ = _chip()
    bus.fail_next(errno.ETIMEDOUT)
    with pytest.raises(DeviceTimeoutError):
        device.initialise()


def _session(rate_dps=lambda t: 0.0, bias_dps=0.5, noise_dps=0.02, **kwargs):
    device, chip, bus, clock = _chip(gyro_z_dps=rate_dps, bias_dps=bias_dps, noise_dps=noise_dps)
    device.initialise()
    heading = HeadingState(CalibrationConfig(duration_s=2.0))
    readings = []
    session = ImuSession(device, heading, readings.append, sleep=clock.sleep, clock=clock, **kwargs)
    return session, readings, heading, chip, bus, clock


def _run(session, clock, until_s):
    while clock() < until_s:
        session.poll()


def test_bias_is_calibrated_before_anything_is_reported():
    session, readings, heading, _, _, clock = _session(bias_dps=0.8)
    _run(session, clock, 1.9)
    assert readings == []
    _run(session, clock, 3.0)
    assert heading.calibrated
    assert math.degrees(heading.integrator.bias_radps) == pytest.approx(0.8, abs=0.01)
    assert readings
    assert abs(readings[-1].gyro_radps[2]) < math.radians(0.1)


def test_constant_turn_integrates_to_the_expected_yaw():
    # Still for 2 s (calibration), then 30 deg/s counter-clockwise for 3 s: +90 deg.
    session, readings, _, _, _, clock = _session(rate_dps=lambda t: 30.0 if 2.5 <= t < 5.5 else 0)
    _run(session, clock, 6.0)
    assert math.degrees(readings[-1].yaw_rad) == pytest.approx(90.0, abs=1.0)
    assert readings[-1].yaw_variance > readings[0].yaw_variance


def test_upside_down_mounting_flips_the_yaw_sign():
    session, readings, _, _, _, clock = _session(
        rate_dps=lambda t: 30.0 if 2.5 <= t < 5.5 else 0, mounting=Mounting.Z_DOWN
    )
    _run(session, clock, 6.0)
    assert math.degrees(readings[-1].yaw_rad) == pytest.approx(-90.0, abs=1.0)
    assert readings[-1].accel_mps2[2] == pytest.approx(-9.80665, abs=0.01)


def test_motion_during_calibration_is_rejected_and_retried():
    session, _readings, heading, _, _, clock = _session(rate_dps=lambda t: 20.0 if t < 1.0 else 0)
    _run(session, clock, 2.5)
    assert heading.calibration_failures == 1
    assert 'robot moved' in heading.last_calibration_error
    assert not heading.calibrated
    _run(session, clock, 5.0)
    assert heading.calibrated
    assert math.degrees(heading.integrator.bias_radps) == pytest.approx(0.5, abs=0.02)


def test_single_nack_is_retried_within_the_cycle():
    session, readings, _, _, bus, clock = _session()
    _run(session, clock, 2.5)
    count = len(readings)
    bus.fail_next(errno.EREMOTEIO, count=2, method='read_i2c_block_data')
    _run(session, clock, 2.6)
    assert session.read_errors == 2
    assert len(readings) > count


def test_persistent_nack_raises_for_a_reconnect():
    session, _, _, _, bus, clock = _session()
    bus.fail_next(errno.EREMOTEIO, count=10)
    with pytest.raises(DeviceUnavailableError):
        _run(session, clock, 0.5)


def test_stuck_data_is_detected():
    session, _, _, chip, _, clock = _session()
    chip.frozen_block = [0, 0, 0, 0, 0x40, 0, 0, 0, 0, 0, 0, 0, 0, 5]
    with pytest.raises(ProtocolError, match='stuck sensor'):
        _run(session, clock, 1.0)


def test_brown_out_is_detected_by_the_config_read_back():
    session, _, _, chip, _, clock = _session()
    _run(session, clock, 0.5)
    chip.brown_out()
    with pytest.raises(DeviceUnavailableError, match='brown-out'):
        _run(session, clock, 2.0)


def test_reconnect_after_brown_out_keeps_the_heading():
    clock = FakeClock()
    chip = FakeMpu6050(clock, gyro_z_dps=lambda t: 30.0 if 3.0 <= t < 6.0 else 0.0, noise_dps=0.02)
    bus = FakeSMBus({0x68: chip})
    heading = HeadingState(CalibrationConfig(duration_s=2.0))
    readings = []

    def connect():
        device = Mpu6050(bus, Mpu6050Config(), sleep=clock.sleep)
        device.initialise()
        return ImuSession(device, heading, readings.append, sleep=clock.sleep, clock=clock)

    bus.close = lambda: None  # the fake bus survives the worker closing it
    worker = DeviceWorker('imu', connect, clock=clock)
    while clock() < 4.0:
        worker.run_once()
        clock.advance(0.001)
    chip.brown_out()
    while clock() < 8.0:
        worker.run_once()
        clock.advance(0.001)
    assert worker.connect_count == 2
    assert worker.status.level is DiagnosticLevel.OK
    # About one second of the turn fell into the outage, so yaw lags but continues.
    assert 40.0 < math.degrees(readings[-1].yaw_rad) <= 91.0


def test_calibrator_requires_enough_samples():
    calibrator = BiasCalibrator(CalibrationConfig(duration_s=1.0, min_samples=50))
    calibrator.add(0.0, 0.0)
    with pytest.raises(CalibrationError, match='only 2 gyro samples'):
        calibrator.add(1.5, 0.0)


def test_integrator_caps_long_gaps_and_counts_them():
    integrator = YawIntegrator(0.0, nominal_dt_s=0.01)
    integrator.update(0.0, 1.0)
    integrator.update(1.0, 1.0)  # a 1 s scheduling hiccup
    assert integrator.dt_outliers == 1
    assert integrator.yaw_rad == pytest.approx(0.05)


@pytest.mark.parametrize(
    ('angle', 'wrapped'), [(math.pi, math.pi), (-math.pi, math.pi), (3 * math.pi / 2, -math.pi / 2)]
)
def test_wrap_pi_returns_the_half_open_interval(angle, wrapped):
    assert wrap_pi(angle) == pytest.approx(wrapped)


def test_stillness_needs_a_fresh_zero_command_held_long_enough():
    detector = StillnessDetector(ZuptConfig(hold_s=1.0, command_timeout_s=0.5))
    assert not detector.still(0.0)  # no command yet: unknown, not still
    for k in range(12):
        detector.command(k * 0.1, moving=False)
    assert detector.still(1.1)
    assert not detector.still(2.0)  # commands went stale
    detector.command(2.0, moving=True)
    detector.command(2.1, moving=False)
    assert not detector.still(2.2)  # the zero has to hold again


def test_bias_tracking_ignores_rates_far_from_the_bias():
    integrator = YawIntegrator(0.0)
    config = ZuptConfig(max_rate_radps=0.01, time_constant_s=1.0)
    assert not track_bias(integrator, 0.5, 0.01, config)  # a push, not a bias
    assert track_bias(integrator, 0.005, 0.5, config)
    assert integrator.bias_radps == pytest.approx(0.0025)


def _drift_after_warm_up(zupt_enabled):
    """Bias steps from 0.5 to 0.8 deg/s after calibration; the robot stands still for 60 s."""
    clock = FakeClock()
    chip = FakeMpu6050(clock, bias_dps=0.5, noise_dps=0.02)
    bus = FakeSMBus({0x68: chip})
    device = Mpu6050(bus, Mpu6050Config(), sleep=clock.sleep)
    device.initialise()
    heading = HeadingState(
        CalibrationConfig(duration_s=2.0),
        stillness=StillnessDetector(ZuptConfig(enabled=zupt_enabled, time_constant_s=5.0)),
    )
    readings = []
    session = ImuSession(device, heading, readings.append, sleep=clock.sleep, clock=clock)
    next_command_s = 0.0
    while clock() < 62.0:
        if clock() >= 3.0:
            chip.bias_dps = 0.8
        if clock() >= next_command_s:
            heading.stillness.command(clock(), moving=False)
            next_command_s += 0.1
        session.poll()
    return abs(math.degrees(readings[-1].yaw_rad)), heading


def test_zero_velocity_updates_remove_most_warm_up_drift():
    drift_without, _ = _drift_after_warm_up(zupt_enabled=False)
    drift_with, heading = _drift_after_warm_up(zupt_enabled=True)
    assert drift_without == pytest.approx(0.3 * 59, rel=0.05)  # 0.3 deg/s for 59 s
    assert drift_with < drift_without / 5
    assert heading.zupt_updates > 0
    assert math.degrees(heading.integrator.bias_radps) == pytest.approx(0.8, abs=0.02)
