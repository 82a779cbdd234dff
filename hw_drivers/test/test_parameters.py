"""Driver parameter specs: bounds on what sizes memory, timers and safety limits; names."""

import os

import pytest
from hw_drivers.errors import ConfigurationError
from hw_drivers.parameters import (
    AOA_RECEIVER_PARAMETERS,
    GAS_PARAMETERS,
    MAX_SCAN_BINS,
    MPU6050_PARAMETERS,
    NODE_SPECS,
    PUMP_PARAMETERS,
    RPLIDAR_PARAMETERS,
    DriverParameterError,
)
from hw_drivers.rplidar_protocol import MAX_BINS

from hw_drivers import pump_node, rplidar_node


@pytest.mark.parametrize(
    ('spec', 'name', 'value', 'match'),
    [
        (RPLIDAR_PARAMETERS, 'bins', 1_000_000_000, 'must be <= 4096'),
        (RPLIDAR_PARAMETERS, 'bins', 2, 'must be >= 4'),
        (AOA_RECEIVER_PARAMETERS, 'max_buffer_bytes', 2**40, 'must be <= 262144 bytes'),
        (AOA_RECEIVER_PARAMETERS, 'max_buffer_bytes', 10, 'must be >= 64 bytes'),
        (GAS_PARAMETERS, 'averaging', 10**12, 'must be <= 64'),
        (MPU6050_PARAMETERS, 'calibration_s', 1e300, 'must be <= 60 s'),
    ],
)
def test_parameters_that_size_memory_are_bounded(spec, name, value, match):
    with pytest.raises(DriverParameterError, match=match):
        spec.build({name: value}, strict=True)


@pytest.mark.parametrize('spec', list(NODE_SPECS.values()))
def test_every_rate_gives_a_timer_period_rclpy_can_represent(spec):
    rates = [p for p in spec.parameters if p.name.endswith('_hz')]
    for p in rates:
        for value in (1e-300, 0.0, 1e300):
            with pytest.raises(DriverParameterError, match=p.name):
                spec.build({p.name: value}, strict=True)
        high = spec.build({p.name: p.info.le}, strict=True)
        period_ns = int(1.0 / getattr(high, p.name) * 1e9)
        assert period_ns >= 1_000_000  # 1 kHz at most


@pytest.mark.parametrize('name', ['max_on_s', 'command_timeout_s'])
def test_pump_limits_cannot_be_made_to_disappear(name):
    with pytest.raises(DriverParameterError, match=f'parameter {name}: must be <= 60 s'):
        PUMP_PARAMETERS.build({name: 1e300}, strict=True)
    assert getattr(PUMP_PARAMETERS.build({name: 60.0}, strict=True), name) == 60.0


@pytest.mark.parametrize(
    ('spec', 'name'),
    [
        (RPLIDAR_PARAMETERS, 'port'),
        (RPLIDAR_PARAMETERS, 'frame_id'),
        (GAS_PARAMETERS, 'serial_port'),
        (GAS_PARAMETERS, 'frame_id'),
        (MPU6050_PARAMETERS, 'frame_id'),
        (AOA_RECEIVER_PARAMETERS, 'listen_host'),
        (AOA_RECEIVER_PARAMETERS, 'frame_id'),
        (PUMP_PARAMETERS, 'chip'),
        (PUMP_PARAMETERS, 'line'),
    ],
)
def test_names_of_devices_and_frames_must_not_be_empty(spec, name):
    for empty in ('', '   '):
        with pytest.raises(DriverParameterError, match=f'parameter {name}: must not be empty'):
            spec.build({name: empty}, strict=True)
    assert 'must not be empty' in spec[name].description_text


def test_names_that_may_be_empty_still_may():
    config = AOA_RECEIVER_PARAMETERS.build({'own_tag_id': ''}, strict=True)
    assert config.own_tag_id == ''


def test_the_bins_parameter_bound_is_the_binning_bound():
    assert MAX_SCAN_BINS == MAX_BINS
    assert RPLIDAR_PARAMETERS['bins'].info.le == MAX_BINS
    assert RPLIDAR_PARAMETERS.build({'bins': MAX_BINS}, strict=True).bins == MAX_BINS


def test_a_parameter_error_is_a_configuration_error():
    with pytest.raises(ConfigurationError):
        RPLIDAR_PARAMETERS.build({'bins': 10**9}, strict=True)


@pytest.fixture
def runtime(monkeypatch):
    # Without rclpy a driver runs on the built-in runtime only when asked to; the test legs
    # set SWARM_RUNTIME themselves.
    if 'SWARM_RUNTIME' not in os.environ:
        monkeypatch.setenv('SWARM_RUNTIME', 'builtin')


@pytest.mark.parametrize(
    ('main', 'argument', 'line'),
    [
        (
            rplidar_node.main,
            'bins:=1000000000',
            'rplidar_node: -p: parameter bins: must be <= 4096, got 1000000000',
        ),
        (rplidar_node.main, "port:=''", 'rplidar_node: -p: parameter port: must not be empty'),
        (
            rplidar_node.main,
            "frame_id:=''",
            'rplidar_node: -p: parameter frame_id: must not be empty',
        ),
        (
            pump_node.main,
            'max_on_s:=1e300',
            'pump_node: -p: parameter max_on_s: must be <= 60 s, got 1e+300 s',
        ),
    ],
)
def test_a_driver_refuses_a_bad_parameter_in_one_line_before_ros_starts(
    runtime, capsys, main, argument, line
):
    assert main(['--ros-args', '-p', 'fake_device:=true', '-p', argument]) == 2
    assert capsys.readouterr().err.strip() == line
