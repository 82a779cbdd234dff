"""Typed ``NAME=VALUE`` overrides of a node's declared parameters, for spawners and benchmarks.

A spawner starts every robot node with parameters of its own (index, count, departure, ...);
a researcher comparing settings wants to change any other declared parameter from the
command line, as ``ros2 run ... --ros-args -p name:=value`` does on a robot. The value is
read as a YAML scalar, the way rcl reads ``-p`` values, and must have the type of the
parameter's declared default (an integer is accepted for a float parameter). An unknown
name, a parameter the spawner sets itself, or a value of the wrong type is a
:class:`~swarm_sim.errors.ConfigurationError` raised before anything runs.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Collection, Iterable, Mapping

import yaml
from swarm_sim.errors import ConfigurationError

__all__ = ['parse_overrides']


def _split(item: str) -> tuple[str, str]:
    name, sep, text = item.partition(':=')
    if not sep:
        name, sep, text = item.partition('=')
    name = name.strip()
    if not sep or not name:
        raise ConfigurationError(f'a parameter override must look like NAME=VALUE, got {item!r}')
    return name, text.strip()


def _typed(name: str, text: str, default: object) -> object:
    if isinstance(default, str):
        return text
    kinds = {bool: 'true or false', int: 'an integer', float: 'a finite number'}
    if type(default) not in kinds:
        msg = f'parameter {name} ({type(default).__name__}) cannot be set from the command line'
        raise ConfigurationError(msg)
    try:
        value = yaml.safe_load(text) if text else None
    except yaml.YAMLError:
        value = None
    is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
    if isinstance(default, bool):
        if isinstance(value, bool):
            return value
    elif isinstance(default, int):
        if is_number and isinstance(value, int):
            return value
    elif is_number and math.isfinite(float(value)):
        return float(value)
    kind = kinds[type(default)]
    msg = f'parameter {name}={text!r}: expected {kind}, like its default {default!r}'
    raise ConfigurationError(msg)


def parse_overrides(
    items: Iterable[str],
    declared: Mapping[str, object],
    *,
    reserved: Collection[str] = (),
    check: Callable[[dict[str, object]], object] | None = None,
) -> dict[str, object]:
    """Read ``NAME=VALUE`` (or ROS-style ``NAME:=VALUE``) items into typed parameter values.

    Args:
        items: the overrides, in command-line order (a later one wins).
        declared: every parameter the node declares, name to default value.
        reserved: parameters the caller sets itself; overriding one is an error.
        check: the node's own validation, called with the declared defaults updated by the
            overrides; a ``ValueError`` it raises (the packages' ``ConfigError``) becomes a
            ConfigurationError with the same message.

    Returns:
        Parameter name to value, of the declared default's type.

    Raises:
        ConfigurationError: a malformed item, an unknown or reserved name, a value of the
            wrong type, or values ``check`` rejects.
    """
    values: dict[str, object] = {}
    for item in items:
        name, text = _split(item)
        if name in reserved:
            msg = f'parameter {name!r} is set by the spawner from its own options'
            raise ConfigurationError(msg)
        if name not in declared:
            close = difflib.get_close_matches(name, list(declared), n=3)
            hint = f' (did you mean {", ".join(close)}?)' if close else ''
            raise ConfigurationError(f'unknown parameter {name!r}{hint}')
        values[name] = _typed(name, text, declared[name])
    if check is not None:
        try:
            check({**declared, **values})
        except ValueError as err:
            raise ConfigurationError(str(err)) from err
    return values
