"""A :class:`~swarm_common.params.ParameterSpec` declared on a node, on real rclpy or built-in.

:func:`declare_config` declares every parameter of a spec with a real
``rcl_interfaces/ParameterDescriptor`` (description with the unit, ``read_only``, the range as
``floating_point_range``/``integer_range``, choices and ranges in ``additional_constraints``),
builds the frozen configuration once from the declared values, and registers an on-set
callback that validates a change (type, range, choices, and the configuration's own
cross-field checks) and a post-set callback that hands the node the new configuration::

    class Drive(Node):
        def __init__(self, **kwargs):
            super().__init__('drive', **kwargs)
            self._params = declare_config(self, DRIVE_PARAMETERS, on_change=self._apply)
            self._apply(self._params.config)

        def _apply(self, config: DriveConfig) -> None:
            self._speed_mps = config.speed_mps

The node reads its configuration at start and in ``on_change``, never per tick. Only
parameters declared ``read_only=False`` can change; ROS rejects the others.

:func:`check_parameter_arguments` reads the ``--params-file`` files and ``-p`` values of a
command line before ``rclpy.init`` and raises :class:`ParameterFileError` (one line naming
the file and the parameter) for a file that is not YAML, a wrong type, an unknown name or a
value out of range: rcl would otherwise stop ``rclpy.init`` with a multi-line parser error,
or the node would fail on its first bad parameter without naming the file.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from typing import Any

from swarm_common.errors import SwarmError
from swarm_common.params import ParameterDef, ParameterError, ParameterSpec

from swarm_runtime.ros import message_module, rclpy

__all__ = [
    'COMMON_PARAMETERS',
    'DeclaredConfig',
    'ParameterFileError',
    'check_parameter_arguments',
    'declare_config',
    'descriptor_of',
]

#: Parameters every node has besides its own (rclpy declares them), never reported unknown.
COMMON_PARAMETERS = frozenset({'use_sim_time', 'start_type_description_service'})
_COMMON_PREFIXES = ('qos_overrides.',)
_VALUE_FLAGS = ('-r', '--remap', '-p', '--param', '--params-file')
_INT64_MIN = -(2**63)
_INT64_MAX = 2**63 - 1


class ParameterFileError(SwarmError, ValueError):
    """A parameter from the command line (a ``--params-file`` or ``-p``) is not acceptable.

    Attributes:
        source: the parameter file's path, or ``-p`` for a command-line value.
        name: the parameter's name ('' when the problem is the file itself).
        problem: what is wrong.
    """

    def __init__(self, source: str, name: str, problem: str) -> None:
        where = f'{source}: parameter {name}' if name else source
        super().__init__(f'{where}: {problem}')
        self.source = source
        self.name = name
        self.problem = problem


def descriptor_of(definition: ParameterDef) -> Any:
    """The ``rcl_interfaces/ParameterDescriptor`` of one parameter."""
    rcl = message_module('rcl_interfaces')
    descriptor = rcl.ParameterDescriptor(
        description=definition.description_text,
        additional_constraints=definition.constraints_text,
        read_only=definition.read_only,
    )
    info = definition.info
    low = info.ge if info.ge is not None else info.gt
    high = info.le if info.le is not None else info.lt
    if definition.optional or (low is None and high is None):
        return descriptor
    if definition.kind == 'float':
        descriptor.floating_point_range = [
            rcl.FloatingPointRange(
                from_value=-math.inf if low is None else float(low),
                to_value=math.inf if high is None else float(high),
                step=0.0,
            )
        ]
    elif definition.kind == 'int':
        from_value = _INT64_MIN if low is None else math.ceil(low)
        to_value = _INT64_MAX if high is None else math.floor(high)
        if info.gt is not None and from_value == info.gt:
            from_value += 1
        if info.lt is not None and to_value == info.lt:
            to_value -= 1
        descriptor.integer_range = [
            rcl.IntegerRange(from_value=int(from_value), to_value=int(to_value), step=0)
        ]
    return descriptor


def _exceptions() -> Any:
    import importlib

    return importlib.import_module(f'{rclpy.__name__}.exceptions')


class DeclaredConfig:
    """The parameters of one spec on one node, and the configuration they give.

    Attributes:
        spec: the parameter spec.
        config: the current frozen configuration (replaced on every accepted change).
    """

    def __init__(
        self,
        node: Any,
        spec: ParameterSpec,
        *,
        base: Any = None,
        on_change: Callable[[Any], None] | None = None,
    ) -> None:
        self.spec = spec
        self._base = base
        self._on_change = on_change
        exceptions = _exceptions()
        rejected = (
            exceptions.InvalidParameterTypeException,
            exceptions.InvalidParameterValueException,
        )
        defaults = spec.defaults(base)
        values: dict[str, Any] = {}
        for definition in spec.parameters:
            name = definition.name
            try:
                declared = node.declare_parameter(name, defaults[name], descriptor_of(definition))
            except rejected as err:
                raise spec.error(name, ' '.join(str(err).split())) from err
            values[name] = declared.value
        self._values = values
        self.config = spec.build(values, base, strict=True)
        self._result = message_module('rcl_interfaces').SetParametersResult
        node.add_on_set_parameters_callback(self._validate)
        node.add_post_set_parameters_callback(self._apply)

    @property
    def values(self) -> dict[str, Any]:
        """Parameter name -> current value."""
        return dict(self._values)

    def _changed(self, parameters: Sequence[Any]) -> dict[str, Any]:
        return {p.name: p.value for p in parameters if p.name in self.spec}

    def _validate(self, parameters: list[Any]) -> Any:
        changes = self._changed(parameters)
        if not changes:
            return self._result(successful=True)
        try:
            self.spec.build({**self._values, **changes}, self._base, strict=True)
        except ValueError as err:
            return self._result(successful=False, reason=' '.join(str(err).split()))
        return self._result(successful=True)

    def _apply(self, parameters: list[Any]) -> None:
        changes = self._changed(parameters)
        if not changes:
            return
        self._values.update(changes)
        self.config = self.spec.build(self._values, self._base, strict=True)
        if self._on_change is not None:
            self._on_change(self.config)


def declare_config(
    node: Any,
    spec: ParameterSpec,
    *,
    base: Any = None,
    on_change: Callable[[Any], None] | None = None,
) -> DeclaredConfig:
    """Declare ``spec`` on ``node``; return the declared parameters and their configuration.

    Args:
        node: the rclpy (or built-in) node.
        spec: the parameter spec.
        base: the configuration whose values are the declared defaults (default: the
            dataclass defaults); overrides (``-p``, parameter files, parameter_overrides) win.
        on_change: called with the new configuration after an accepted change.

    Raises:
        ParameterError: (the spec's error class) ROS rejected an override (wrong type, out of
            the descriptor's range) or a value fails the spec's checks; the configuration's
            own errors for values that do not fit together.
    """
    return DeclaredConfig(node, spec, base=base, on_change=on_change)


# ------------------------------------------------------------------------------ command line


def _ros_sections(argv: Sequence[str]) -> list[tuple[str, str]]:
    """(flag, value) pairs of the value-taking flags inside ``--ros-args`` sections."""
    pairs: list[tuple[str, str]] = []
    inside = False
    index = 0
    while index < len(argv):
        arg = argv[index]
        index += 1
        if arg == '--ros-args':
            inside = True
        elif arg == '--':
            inside = False
        elif inside and arg in _VALUE_FLAGS and index < len(argv):
            pairs.append((arg, argv[index]))
            index += 1
    return pairs


def _node_name_rules(pairs: Sequence[tuple[str, str]], node_name: str) -> tuple[str, str]:
    namespace, name = '/', node_name
    for flag, rule in pairs:
        if flag not in ('-r', '--remap'):
            continue
        left, _, right = rule.partition(':=')
        target, _, match = left.rpartition(':')
        if target and target != node_name:
            continue
        if match == '__ns':
            namespace = right if right.startswith('/') else '/' + right
        elif match in ('__node', '__name'):
            name = right
    return namespace, name


def check_parameter_arguments(
    spec: ParameterSpec,
    node_name: str,
    args: Sequence[str] | None = None,
    *,
    base: Any = None,
) -> None:
    """Check the parameter files and ``-p`` values a command line gives a node.

    Only entries whose node key matches the node (after ``__ns``/``__node`` remaps) are
    checked: wildcard keys (``/**``, ``/**/name``) and the node's own name. Values are
    checked as ROS types them (an integer for a float parameter is an error, as it is on
    rclpy), then all together against the configuration's own rules.

    Args:
        spec: the node's parameter spec.
        node_name: the node's default name.
        args: the argument list given to ``rclpy.init`` (None: ``sys.argv``).
        base: the configuration the node declares its defaults from.

    Raises:
        ParameterFileError: one line naming the file (or ``-p``) and the parameter.
    """
    from swarm_runtime.builtin._arguments import node_key_matches
    from swarm_runtime.builtin._param_yaml import (
        ParameterValueError,
        load_parameter_file,
        parse_parameter_value,
    )

    argv = list(sys.argv if args is None else args)
    pairs = _ros_sections(argv)
    namespace, name = _node_name_rules(pairs, node_name)
    fully_qualified = f'{namespace.rstrip("/")}/{name}'
    values: dict[str, Any] = {}
    sources: list[str] = []

    def take(source: str, key: str | None, pname: str, value: Any) -> None:
        if key is not None and not node_key_matches(key, fully_qualified):
            return
        if pname not in spec:
            if pname in COMMON_PARAMETERS or pname.startswith(_COMMON_PREFIXES):
                return
            raise ParameterFileError(source, '', str(spec.unknown(pname)))
        try:
            spec.check(pname, value, strict=True)
        except ParameterError as err:
            raise ParameterFileError(source, pname, err.problem) from err
        values[pname] = value
        if source not in sources:
            sources.append(source)

    for flag, value in pairs:
        if flag == '--params-file':
            try:
                entries = load_parameter_file(value)
            except ParameterValueError as err:
                problem = ' '.join(str(err).split())
                problem = problem.replace(f"Couldn't parse params file '{value}': ", '')
                problem = problem.removeprefix(f'{value}: ')
                raise ParameterFileError(value, '', problem) from err
            wildcard = [e for e in entries if '*' in e.node_key]
            exact = [e for e in entries if '*' not in e.node_key]
            for entry in wildcard + exact:
                take(value, entry.node_key, entry.name, entry.value)
        elif flag in ('-p', '--param'):
            left, separator, text = value.partition(':=')
            target, _, pname = left.rpartition(':')
            if not separator or (target and target != name):
                continue
            try:
                parsed = parse_parameter_value(text, where=f'-p {value}')
            except ParameterValueError as err:
                raise ParameterFileError('-p', pname, ' '.join(str(err).split())) from err
            take('-p', None, pname, parsed)
    if not values:
        return
    try:
        spec.build(values, base, strict=True)
    except ValueError as err:
        raise ParameterFileError(', '.join(sources), '', ' '.join(str(err).split())) from err
