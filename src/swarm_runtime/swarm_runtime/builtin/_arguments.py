"""Command-line ROS arguments, parsed and applied as rcl does.

Only the arguments between ``--ros-args`` and ``--`` (or the end) are ROS arguments::

    prog --ros-args -r __ns:=/r3 -r scan:=lidar -p rate_hz:=5.0 --params-file f.yaml --

Supported: ``-r/--remap [node:]from:=to`` (topic names, ``__ns``, ``__node``/``__name``),
``-p/--param [node:]name:=value`` (rcl's YAML rules), ``--params-file FILE``,
``--log-level [logger:=]LEVEL``. The logging-output flags (``--log-config-file``,
``--[en|dis]able-{rosout,stdout,external-lib}-logs``, ``--log-file-name``) and
``-e/--enclave`` are accepted and have no effect. Anything else after ``--ros-args`` is an
unknown ROS argument (:class:`UnknownROSArgsError`).
"""

from __future__ import annotations

import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ._param_yaml import load_parameter_file, parse_parameter_value
from .errors import RCLInvalidROSArgsError, UnknownROSArgsError

__all__ = [
    'LogLevelRule',
    'ParameterRule',
    'RemapRule',
    'RosArguments',
    'node_key_matches',
    'parameter_overrides_for',
    'parse_ros_arguments',
    'remap_name',
]

_VALUE_FLAGS_IGNORED = frozenset({'--log-config-file', '--log-file-name', '-e', '--enclave'})
_SWITCHES_IGNORED = frozenset(
    f'--{verb}-{what}-logs'
    for verb in ('enable', 'disable')
    for what in ('rosout', 'stdout', 'external-lib')
)
_SEVERITIES = {'unset': 0, 'debug': 10, 'info': 20, 'warn': 30, 'warning': 30, 'error': 40}
_SEVERITIES['fatal'] = 50
_NODE_NAME_REMAPS = ('__node', '__name')


@dataclass(frozen=True)
class RemapRule:
    """``[node_name:]match:=replacement``; ``match`` is a topic name, ``__ns`` or ``__node``."""

    node_name: str | None
    match: str
    replacement: str


@dataclass(frozen=True)
class ParameterRule:
    """A parameter override: from ``-p`` (``node_key`` None unless prefixed) or a file."""

    node_key: str | None
    name: str
    value: Any


@dataclass(frozen=True)
class LogLevelRule:
    """``--log-level``: a severity for one logger, or the default (``logger_name`` None)."""

    logger_name: str | None
    severity: int


@dataclass(frozen=True)
class RosArguments:
    """The parsed ROS arguments of one argument list, in command-line order."""

    remap_rules: tuple[RemapRule, ...] = ()
    parameter_rules: tuple[ParameterRule, ...] = ()
    log_levels: tuple[LogLevelRule, ...] = ()
    non_ros_args: tuple[str, ...] = ()


def _split_rule(rule: str, flag: str) -> tuple[str | None, str, str]:
    left, separator, right = rule.partition(':=')
    if not separator or not left:
        form = '[node:]from:=to' if flag in ('-r', '--remap') else '[node:]name:=value'
        msg = f"Couldn't parse rule '{flag} {rule}': expected '{form}'"
        raise RCLInvalidROSArgsError(msg)
    node_name, colon, name = left.rpartition(':')
    if colon and not node_name:
        msg = f"Couldn't parse rule '{flag} {rule}': empty node name before ':'"
        raise RCLInvalidROSArgsError(msg)
    return (node_name or None), name, right


def _parse_log_level(value: str) -> LogLevelRule:
    logger_name, separator, level = value.rpartition(':=')
    severity = _SEVERITIES.get(level.strip().lower())
    if severity is None:
        msg = f"Couldn't parse log level '--log-level {value}': unknown level '{level}'"
        raise RCLInvalidROSArgsError(msg)
    return LogLevelRule(logger_name if separator else None, severity)


def _parameter_rules_from_file(path: str) -> list[ParameterRule]:
    entries = load_parameter_file(path)
    # Wildcard keys first, so that entries naming the node override them (as rclpy does).
    wildcard = [entry for entry in entries if '*' in entry.node_key]
    exact = [entry for entry in entries if '*' not in entry.node_key]
    return [ParameterRule(entry.node_key, entry.name, entry.value) for entry in wildcard + exact]


def parse_ros_arguments(args: Sequence[str]) -> RosArguments:
    """Parse an argument list (``sys.argv`` style; ``args[0]`` is not special).

    Raises:
        UnknownROSArgsError: unknown flags inside a ``--ros-args`` section.
        RCLInvalidROSArgsError: a flag without its value, a malformed rule, a bad params file.
    """
    remaps: list[RemapRule] = []
    parameters: list[ParameterRule] = []
    log_levels: list[LogLevelRule] = []
    non_ros: list[str] = []
    unknown: list[str] = []
    in_ros_args = False
    index = 0
    while index < len(args):
        arg = args[index]
        index += 1
        if arg == '--ros-args':
            in_ros_args = True
            continue
        if not in_ros_args:
            non_ros.append(arg)
            continue
        if arg == '--':
            in_ros_args = False
            continue
        takes_value = arg in ('-r', '--remap', '-p', '--param', '--params-file', '--log-level')
        if takes_value or arg in _VALUE_FLAGS_IGNORED:
            if index >= len(args):
                msg = f"Couldn't parse trailing '{arg}' flag: it needs a value"
                raise RCLInvalidROSArgsError(msg)
            value = args[index]
            index += 1
            if arg in ('-r', '--remap'):
                remaps.append(RemapRule(*_split_rule(value, arg)))
            elif arg in ('-p', '--param'):
                node_key, name, text = _split_rule(value, arg)
                parsed = parse_parameter_value(text, where=f"'{arg} {value}'")
                parameters.append(ParameterRule(node_key, name, parsed))
            elif arg == '--params-file':
                parameters.extend(_parameter_rules_from_file(value))
            elif arg == '--log-level':
                log_levels.append(_parse_log_level(value))
        elif arg not in _SWITCHES_IGNORED:
            unknown.append(arg)
    if unknown:
        raise UnknownROSArgsError(str(unknown))  # rclpy's message: the list itself
    return RosArguments(tuple(remaps), tuple(parameters), tuple(log_levels), tuple(non_ros))


def _tokens_match(pattern: list[str], tokens: list[str]) -> bool:
    if not pattern:
        return not tokens
    head, rest = pattern[0], pattern[1:]
    if head == '**':
        return any(_tokens_match(rest, tokens[skip:]) for skip in range(len(tokens) + 1))
    return bool(tokens) and fnmatch.fnmatchcase(tokens[0], head) and _tokens_match(rest, tokens[1:])


def node_key_matches(node_key: str, fully_qualified_name: str) -> bool:
    """Whether a parameter-file node key (``/**``, ``/r*/algo``, ``algo``) names this node.

    Keys without a leading ``/`` are taken as absolute; ``*`` matches within one name token,
    ``**`` any number of tokens.
    """
    key = node_key if node_key.startswith('/') else '/' + node_key
    return _tokens_match(key.strip('/').split('/'), fully_qualified_name.strip('/').split('/'))


def parameter_overrides_for(
    argument_sets: Sequence[RosArguments], fully_qualified_name: str
) -> dict[str, Any]:
    """Collect the parameter values the argument sets give a node; later ones win.

    A node key names the node by its fully qualified name, as in rcl: ``algo`` means
    ``/algo``, so a node ``/r3/algo`` needs ``/r3/algo``, ``/**/algo`` or ``/**``.
    """
    overrides: dict[str, Any] = {}
    for arguments in argument_sets:
        for rule in arguments.parameter_rules:
            if rule.node_key is None or node_key_matches(rule.node_key, fully_qualified_name):
                overrides[rule.name] = rule.value
    return overrides


def remap_name(
    argument_sets: Sequence[RosArguments],
    match: str,
    node_name: str,
    *,
    expand: Any = None,
) -> str | None:
    """Return the replacement of the first rule that applies, or None.

    ``argument_sets`` are searched in order (the node's own arguments before the global
    ones). For topic names, ``expand`` expands a rule's sides before comparing, as rcl does.
    """
    for arguments in argument_sets:
        for rule in arguments.remap_rules:
            if rule.node_name is not None and rule.node_name != node_name:
                continue
            if match in _NODE_NAME_REMAPS:
                if rule.match in _NODE_NAME_REMAPS:
                    return rule.replacement
                continue
            if match == '__ns' or rule.match.startswith('__'):
                if rule.match == match:
                    return rule.replacement
                continue
            if expand is not None and expand(rule.match) == match:
                return expand(rule.replacement)
    return None
