"""A parameter spec declared on a node, and the command-line check of parameter files."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from swarm_common.params import ParameterError, ParameterSpec, parameter, section
from swarm_runtime.parameters import (
    ParameterFileError,
    check_parameter_arguments,
    declare_config,
)
from swarm_runtime.ros import Node, Parameter, rclpy


@dataclass(frozen=True)
class Limits:
    max_speed_mps: float = parameter(1.0, 'speed limit', unit='m/s', gt=0.0, le=5.0)
    retries: int = parameter(3, 'how often to retry', ge=0, le=10)


@dataclass(frozen=True)
class DriveConfig:
    mode: str = parameter('fast', 'how to drive', choices=('fast', 'slow'))
    gain: float = parameter(2.0, 'heading gain', unit='1/s', gt=0.0, read_only=False)
    speed_mps: float = parameter(0.5, 'cruise speed', unit='m/s', gt=0.0, read_only=False)
    weight: float | None = parameter(None, 'optional weight', ge=0.0)
    limits: Limits = section(Limits)

    def __post_init__(self) -> None:
        if self.speed_mps > self.limits.max_speed_mps:
            raise ValueError('speed_mps must not exceed limits.max_speed_mps')


SPEC = ParameterSpec(DriveConfig)


@pytest.fixture
def init():
    rclpy.init(args=[])
    yield
    rclpy.try_shutdown()


def make_node(**overrides: object) -> Node:
    return rclpy.create_node(
        'drive', parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()]
    )


def test_every_parameter_is_declared_with_a_full_descriptor(init) -> None:
    node = make_node()
    declared = declare_config(node, SPEC)
    assert declared.config == DriveConfig()
    speed = node.describe_parameter('speed_mps')
    assert speed.description == 'cruise speed [m/s]'
    assert not speed.read_only
    assert speed.floating_point_range[0].from_value == 0.0
    assert speed.floating_point_range[0].to_value == math.inf
    retries = node.describe_parameter('limits.retries')
    assert retries.read_only
    assert (retries.integer_range[0].from_value, retries.integer_range[0].to_value) == (0, 10)
    assert node.describe_parameter('mode').additional_constraints == 'one of fast, slow'
    weight = node.describe_parameter('weight')
    assert not weight.floating_point_range  # NaN stands for None: no ROS range
    assert math.isnan(node.get_parameter('weight').value)
    node.destroy_node()


def test_overrides_reach_the_configuration(init) -> None:
    node = make_node(mode='slow', **{'limits.retries': 5, 'weight': 0.5})
    config = declare_config(node, SPEC).config
    assert (config.mode, config.limits.retries, config.weight) == ('slow', 5, 0.5)
    node.destroy_node()


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'mode': 'sideways'}, "mode: 'sideways' is not one of fast, slow"),
        ({'limits.retries': 11}, 'limits.retries'),
        ({'gain': 0.0}, 'gain: must be > 0'),
        ({'gain': 'high'}, 'gain'),
    ],
)
def test_bad_overrides_stop_the_declaration_naming_the_parameter(init, overrides, message):
    node = make_node(**overrides)
    with pytest.raises(ParameterError, match=message):
        declare_config(node, SPEC)
    node.destroy_node()


def test_an_accepted_change_hands_over_a_new_frozen_configuration(init) -> None:
    node = make_node()
    seen: list[DriveConfig] = []
    declared = declare_config(node, SPEC, on_change=seen.append)
    [result] = node.set_parameters([Parameter('gain', value=3.0)])
    assert result.successful
    assert seen == [DriveConfig(gain=3.0)]
    assert declared.config.gain == 3.0
    node.destroy_node()


@pytest.mark.parametrize(
    ('name', 'value', 'reason'),
    [
        ('gain', -1.0, 'gain'),
        ('speed_mps', 2.0, 'speed_mps must not exceed limits.max_speed_mps'),
        ('mode', 'slow', 'read-only'),
        ('gain', 3, 'type'),
    ],
)
def test_a_rejected_change_keeps_the_configuration(init, name, value, reason) -> None:
    node = make_node()
    seen: list[DriveConfig] = []
    declared = declare_config(node, SPEC, on_change=seen.append)
    [result] = node.set_parameters([Parameter(name, value=value)])
    assert not result.successful
    assert reason in result.reason
    assert seen == []
    assert declared.config == DriveConfig()
    assert node.get_parameter(name).value == SPEC.defaults()[name]
    node.destroy_node()


def test_the_base_configuration_gives_the_declared_defaults(init) -> None:
    node = make_node()
    base = DriveConfig(speed_mps=0.8, limits=Limits(retries=1))
    declared = declare_config(node, SPEC, base=base)
    assert node.get_parameter('speed_mps').value == 0.8
    assert declared.config == base
    node.destroy_node()


# ------------------------------------------------------------------------------ command line


def write(tmp_path, text: str, name: str = 'drive.yaml') -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def check(*args: str) -> None:
    check_parameter_arguments(SPEC, 'drive', ['prog', *args])


def test_a_valid_file_and_values_pass(tmp_path) -> None:
    path = write(
        tmp_path,
        '/**/drive:\n  ros__parameters:\n    mode: slow\n    limits:\n      retries: 2\n'
        '/**/other_node:\n  ros__parameters:\n    not_ours: 1\n',
    )
    check('--ros-args', '-r', '__ns:=/r0', '--params-file', path, '-p', 'gain:=4.0')
    check()  # nothing to check


@pytest.mark.parametrize(
    ('text', 'message'),
    [
        ('/**:\n  ros__parameters:\n    mode: [fast\n', 'drive.yaml: '),
        ('/**:\n  ros__parameters:\n    gain: 2\n', 'parameter gain: expected a floating-point'),
        (
            '/**:\n  ros__parameters:\n    gian: 2.0\n',
            "unknown parameter 'gian' (did you mean gain?)",
        ),
        (
            '/**/drive:\n  ros__parameters:\n    limits:\n      retries: 20\n',
            'limits.retries: must',
        ),
        ('/**:\n  ros__parameters:\n    mode: sideways\n', 'parameter mode:'),
        ('/**:\n  ros__parameters:\n    speed_mps: 3.0\n', 'must not exceed'),
        ('/**:\n  drive: 3\n', 'drive.yaml'),
    ],
)
def test_a_malformed_file_gives_one_line_naming_file_and_parameter(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(ParameterFileError) as caught:
        check('--ros-args', '--params-file', path)
    line = str(caught.value)
    assert '\n' not in line
    assert line.startswith(path)
    assert message in line


def test_entries_for_other_nodes_or_namespaces_are_not_checked(tmp_path) -> None:
    path = write(tmp_path, '/r1/drive:\n  ros__parameters:\n    gian: 2.0\n')
    check('--ros-args', '-r', '__ns:=/r0', '--params-file', path)
    with pytest.raises(ParameterFileError, match='gian'):
        check('--ros-args', '-r', '__ns:=/r1', '--params-file', path)
    with pytest.raises(ParameterFileError, match='gian'):
        check(
            '--ros-args',
            '-r',
            '__node:=drive2',
            '-r',
            '__ns:=/r1',
            '--params-file',
            write(tmp_path, '/r1/drive2:\n  ros__parameters:\n    gian: 2.0\n', 'b.yaml'),
        )


def test_common_node_parameters_are_not_unknown(tmp_path) -> None:
    path = write(tmp_path, '/**:\n  ros__parameters:\n    use_sim_time: true\n')
    check('--ros-args', '--params-file', path)


def test_command_line_values_are_checked_too() -> None:
    with pytest.raises(ParameterFileError, match=r'^-p: parameter gain: expected a floating-point'):
        check('--ros-args', '-p', 'gain:=2')
    with pytest.raises(ParameterFileError, match="unknown parameter 'mdoe'"):
        check('--ros-args', '-p', 'mdoe:=slow')
    check('--ros-args', '-p', 'other:gain:=oops')  # for another node


@pytest.mark.builtin_only(reason="checks the built-in runtime's own conformance to rclpy")
def test_the_builtin_runtime_rejects_what_rclpy_rejects(init) -> None:
    node = make_node()
    with pytest.raises(TypeError, match='callable'):
        node.add_on_set_parameters_callback(None)
    node.declare_parameter('x', 1.0)
    node.add_on_set_parameters_callback(lambda _params: True)
    with pytest.warns(UserWarning, match='invalid type'):
        [result] = node.set_parameters([Parameter('x', value=2.0)])
    assert not result.successful
    assert result.reason == 'Callback returned an invalid type'
    node.destroy_node()
