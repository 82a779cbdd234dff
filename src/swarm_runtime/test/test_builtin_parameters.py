"""Parameters of the built-in runtime: declaration, overrides, types, descriptors, results."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import pytest
from swarm_runtime.builtin.errors import RCLInvalidROSArgsError, UnknownROSArgsError
from swarm_runtime.builtin.exceptions import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterImmutableException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from swarm_runtime.builtin.node import Node
from swarm_runtime.builtin.parameter import Parameter
from swarm_runtime.messages import get_message_module

from swarm_runtime import builtin as rclpy

rcl_interfaces = get_message_module('rcl_interfaces')
ParameterDescriptor = rcl_interfaces.ParameterDescriptor


@pytest.fixture
def init() -> Iterator[None]:
    """Initialise the default context with the given arguments; shut it down afterwards."""
    yield None
    rclpy.try_shutdown()


def start(*ros_args: str) -> None:
    rclpy.init(args=['prog', '--ros-args', *ros_args] if ros_args else ['prog'])


def write_params(tmp_path: Path, text: str) -> str:
    path = tmp_path / 'params.yaml'
    path.write_text(text)
    return str(path)


def test_declared_parameter_takes_its_default(init) -> None:
    start()
    node = Node('algo')
    assert node.declare_parameter('rate_hz', 10.0).value == 10.0
    assert node.get_parameter('rate_hz').type_ is Parameter.Type.DOUBLE


def test_use_sim_time_is_declared_automatically_and_false(init) -> None:
    start()
    node = Node('algo')
    assert node.has_parameter('use_sim_time')
    assert node.get_parameter('use_sim_time').value is False


def test_command_line_override_wins_over_the_default(init) -> None:
    start('-p', 'rate_hz:=5.0', '-r', '__ns:=/r3')
    node = Node('algo')
    assert node.get_fully_qualified_name() == '/r3/algo'
    assert node.declare_parameter('rate_hz', 10.0).value == 5.0


def test_node_specific_command_line_override_applies_to_that_node_only(init) -> None:
    start('-p', 'algo:rate_hz:=2.0')
    assert Node('algo').declare_parameter('rate_hz', 10.0).value == 2.0
    assert Node('other').declare_parameter('rate_hz', 10.0).value == 10.0


def test_override_values_are_typed_with_rcl_yaml_rules(init) -> None:
    start('-p', 'count:=010', '-p', 'name:="5"', '-p', 'on:=yes', '-p', 'gains:=[1.0, 2.5]')
    node = Node('algo')
    assert node.declare_parameter('count', 0).value == 8
    assert node.declare_parameter('name', 'x').value == '5'
    assert node.declare_parameter('on', False).value is True
    assert node.declare_parameter('gains', [0.0]).value == [1.0, 2.5]


def test_integer_override_of_a_double_parameter_is_a_type_error(init) -> None:
    start('-p', 'rate_hz:=5')
    node = Node('algo')
    with pytest.raises(InvalidParameterTypeException, match="expecting type 'DOUBLE'"):
        node.declare_parameter('rate_hz', 10.0)


def test_params_file_applies_by_node_name_namespace_and_wildcard(init, tmp_path) -> None:
    params = write_params(
        tmp_path,
        """
/**:
  ros__parameters:
    use_sim_time: true
    rate_hz: 1.0
/r1/algo:
  ros__parameters:
    rate_hz: 4.0
    limits:
      max_speed_mps: 0.3
algo:
  ros__parameters:
    rate_hz: 9.0
""",
    )
    start('--params-file', params)
    namespaced = Node('algo', namespace='r1')
    assert namespaced.get_parameter('use_sim_time').value is True
    assert namespaced.declare_parameter('rate_hz', 10.0).value == 4.0
    assert namespaced.declare_parameter('limits.max_speed_mps', 1.0).value == 0.3
    assert Node('algo').declare_parameter('rate_hz', 10.0).value == 9.0
    assert Node('algo', namespace='r2').declare_parameter('rate_hz', 10.0).value == 1.0


def test_command_line_arguments_apply_in_order(init, tmp_path) -> None:
    params = write_params(tmp_path, '/**:\n  ros__parameters:\n    rate_hz: 1.0\n')
    start('-p', 'rate_hz:=2.0', '--params-file', params)
    assert Node('algo').declare_parameter('rate_hz', 10.0).value == 1.0


def test_node_cli_args_override_global_arguments(init) -> None:
    start('-p', 'rate_hz:=2.0')
    node = Node('algo', cli_args=['--ros-args', '-p', 'rate_hz:=3.0'])
    assert node.declare_parameter('rate_hz', 10.0).value == 3.0


def test_parameter_overrides_argument_wins_over_command_line(init) -> None:
    start('-p', 'rate_hz:=2.0')
    node = Node('algo', parameter_overrides=[Parameter('rate_hz', value=7.0)])
    assert node.declare_parameter('rate_hz', 10.0).value == 7.0
    assert node.declare_parameter('gain', 1.0, ignore_override=True).value == 1.0


def test_bad_params_file_fails_at_init_with_the_file_named(init, tmp_path) -> None:
    params = write_params(tmp_path, 'algo:\n  rate_hz: 1.0\n')
    with pytest.raises(RCLInvalidROSArgsError, match='ros__parameters'):
        start('--params-file', params)
    with pytest.raises(RCLInvalidROSArgsError, match=r'missing\.yaml'):
        rclpy.init(args=['--ros-args', '--params-file', str(tmp_path / 'missing.yaml')])


def test_unknown_ros_arguments_are_rejected(init) -> None:
    with pytest.raises(UnknownROSArgsError, match='--bogus'):
        start('--bogus')


def test_automatic_declaration_from_overrides(init) -> None:
    start('-p', 'speed:=0.5')
    node = Node('algo', automatically_declare_parameters_from_overrides=True)
    assert node.get_parameter('speed').value == 0.5


def test_declaring_twice_raises(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('rate_hz', 10.0)
    with pytest.raises(ParameterAlreadyDeclaredException, match='rate_hz'):
        node.declare_parameter('rate_hz', 10.0)


def test_reading_an_undeclared_parameter_raises(init) -> None:
    start()
    node = Node('algo')
    with pytest.raises(ParameterNotDeclaredException, match='nope'):
        node.get_parameter('nope')
    assert node.get_parameter_or('nope', Parameter('nope', value=3)).value == 3


def test_undeclared_parameters_are_allowed_when_asked(init) -> None:
    start()
    node = Node('open', allow_undeclared_parameters=True)
    assert node.get_parameter('nope').type_ is Parameter.Type.NOT_SET
    assert node.set_parameters([Parameter('nope', value=1)])[0].successful
    assert node.get_parameter('nope').value == 1


def test_statically_typed_parameter_without_value_is_uninitialized(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('port', Parameter.Type.STRING)
    with pytest.raises(ParameterUninitializedException):
        node.get_parameter('port')


def test_set_parameters_with_a_wrong_type_returns_an_unsuccessful_result(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('rate_hz', 10.0)
    [result] = node.set_parameters([Parameter('rate_hz', value='fast')])
    assert isinstance(result, rcl_interfaces.SetParametersResult)
    assert result.successful is False
    assert result.reason == "Wrong parameter type, expected 'Type.DOUBLE' got 'Type.STRING'"
    assert node.get_parameter('rate_hz').value == 10.0


def test_set_parameters_of_undeclared_parameter_raises(init) -> None:
    start()
    node = Node('algo')
    with pytest.raises(ParameterNotDeclaredException):
        node.set_parameters([Parameter('nope', value=1.0)])


def test_set_parameters_atomically_sets_all_or_none(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('a', 1)
    node.declare_parameter('b', 2)
    result = node.set_parameters_atomically([Parameter('a', value=5), Parameter('b', value='x')])
    assert not result.successful
    assert (node.get_parameter('a').value, node.get_parameter('b').value) == (1, 2)


def float_range(low: float, high: float, step: float = 0.0) -> ParameterDescriptor:
    return ParameterDescriptor(
        floating_point_range=[
            rcl_interfaces.FloatingPointRange(from_value=low, to_value=high, step=step)
        ]
    )


def test_floating_point_range_is_enforced_on_set_and_declare(init) -> None:
    start('-p', 'gain:=7.0')
    node = Node('algo')
    node.declare_parameter('rate_hz', 10.0, float_range(1.0, 50.0))
    [too_high] = node.set_parameters([Parameter('rate_hz', value=60.0)])
    assert not too_high.successful
    assert too_high.reason == 'Parameter rate_hz out of range Min: 1.0, Max: 50.0, value: 60.0'
    assert node.set_parameters([Parameter('rate_hz', value=50.0 + 1e-9)])[0].successful
    with pytest.raises(InvalidParameterValueException, match='out of range'):
        node.declare_parameter('gain', 1.0, float_range(0.0, 5.0))


def test_floating_point_range_step_is_enforced(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('angle', 0.0, float_range(0.0, 1.0, step=0.25))
    assert node.set_parameters([Parameter('angle', value=0.75)])[0].successful
    [off_step] = node.set_parameters([Parameter('angle', value=0.3)])
    assert not off_step.successful
    assert 'not close enough to a valid step' in off_step.reason


def test_integer_range_is_enforced_with_step(init) -> None:
    start()
    node = Node('algo')
    descriptor = ParameterDescriptor(
        integer_range=[rcl_interfaces.IntegerRange(from_value=0, to_value=10, step=2)]
    )
    node.declare_parameter('count', 4, descriptor)
    [odd] = node.set_parameters([Parameter('count', value=5)])
    assert odd.reason == (
        'The parameter value for count is not a valid step. Min: 0, max: 10, value: 5, step: 2'
    )
    [outside] = node.set_parameters([Parameter('count', value=12)])
    assert outside.reason == 'Parameter count out of range. Min: 0, Max: 10, value: 12'


def test_read_only_parameter_cannot_be_set_or_undeclared(init) -> None:
    start('-p', 'robot_id:=3')
    node = Node('algo')
    value = node.declare_parameter('robot_id', 0, ParameterDescriptor(read_only=True)).value
    assert value == 3
    [result] = node.set_parameters([Parameter('robot_id', value=4)])
    assert result.reason == 'Trying to set a read-only parameter: robot_id.'
    with pytest.raises(ParameterImmutableException):
        node.undeclare_parameter('robot_id')


def test_descriptor_is_kept_with_name_and_type(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('rate_hz', 10.0, ParameterDescriptor(description='control rate'))
    descriptor = node.describe_parameter('rate_hz')
    assert descriptor.description == 'control rate'
    assert descriptor.name == 'rate_hz'
    assert descriptor.type == Parameter.Type.DOUBLE.value


def test_on_set_callback_can_reject_and_post_set_callback_sees_accepted_values(init) -> None:
    start()
    node = Node('algo')
    node.declare_parameter('speed', 0.1)
    seen: list[float] = []

    def validate(parameters: list[Parameter]) -> object:
        ok = all(p.value <= 1.0 for p in parameters if p.name == 'speed')
        return rcl_interfaces.SetParametersResult(successful=ok, reason='' if ok else 'too fast')

    node.add_on_set_parameters_callback(validate)
    node.add_post_set_parameters_callback(lambda ps: seen.extend(p.value for p in ps))
    assert node.set_parameters([Parameter('speed', value=2.0)])[0].reason == 'too fast'
    assert node.set_parameters([Parameter('speed', value=0.5)])[0].successful
    assert seen == [0.5]
    node.remove_on_set_parameters_callback(validate)
    assert node.set_parameters([Parameter('speed', value=2.0)])[0].successful


def test_declare_parameters_under_a_namespace(init) -> None:
    start('-p', 'limits.max_speed_mps:=0.2')
    node = Node('algo')
    declared = node.declare_parameters(
        'limits',
        [
            ('max_speed_mps', 1.0, ParameterDescriptor(description='m/s')),
            ('max_turn_rate_rps', math.pi),
        ],
    )
    assert [p.name for p in declared] == ['limits.max_speed_mps', 'limits.max_turn_rate_rps']
    assert [p.value for p in declared] == [0.2, math.pi]
    assert set(node.get_parameters_by_prefix('limits')) == {'max_speed_mps', 'max_turn_rate_rps'}


def test_parameter_events_are_published_for_changes(init) -> None:
    start()
    node = Node('algo')
    events: list[object] = []
    node.create_subscription(rcl_interfaces.ParameterEvent, '/parameter_events', events.append, 10)
    node.declare_parameter('rate_hz', 10.0)
    node.set_parameters([Parameter('rate_hz', value=12.0)])
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    executor.spin_once(timeout_sec=0)
    executor.spin_once(timeout_sec=0)
    assert [e.new_parameters[0].name for e in events[:1]] == ['rate_hz']
    assert events[1].changed_parameters[0].value.double_value == 12.0
    assert events[1].node == '/algo'


def test_parameter_type_inference_matches_rclpy() -> None:
    assert Parameter.Type.from_parameter_value([1, 2]) is Parameter.Type.INTEGER_ARRAY
    assert Parameter.Type.from_parameter_value([True]) is Parameter.Type.BOOL_ARRAY
    with pytest.raises(TypeError):
        Parameter.Type.from_parameter_value([1, 'a'])
    with pytest.raises(ValueError, match='do not agree'):
        Parameter('x', Parameter.Type.DOUBLE, 1)


def test_params_file_node_keys_may_be_nested_by_namespace(init, tmp_path) -> None:
    params = write_params(
        tmp_path,
        """
/r1:
  algo:
    ros__parameters:
      rate_hz: 4.0
/*:
  algo:
    ros__parameters:
      gain: 2.0
""",
    )
    start('--params-file', params)
    node = Node('algo', namespace='r1')
    assert node.declare_parameter('rate_hz', 10.0).value == 4.0
    assert node.declare_parameter('gain', 1.0).value == 2.0
    deeper = Node('algo', namespace='/a/b')
    assert deeper.declare_parameter('gain', 1.0).value == 1.0
