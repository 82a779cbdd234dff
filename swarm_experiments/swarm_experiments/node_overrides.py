"""Typed ``NAME=VALUE`` overrides of a node's parameters, for spawners and benchmarks.

A spawner starts every robot node with parameters of its own (index, count, departure, ...);
a researcher comparing settings wants to change any other parameter from the command line,
as ``ros2 run ... --ros-args -p name:=value`` does on a robot. The node's
:class:`~swarm_common.params.ParameterSpec` says what each name is: the value is read as a
YAML scalar (or a YAML list for an array parameter), must have the parameter's type (an
integer is accepted for a float parameter), lie in its range and be one of its choices; then
all overrides together must give a valid configuration. Every problem is an
:class:`OverrideError` (a :class:`~swarm_sim.errors.ConfigurationError`) raised before
anything runs, whose one-line message names the parameter and what is wrong.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from typing import Any

from swarm_common.params import ParameterError, ParameterSpec
from swarm_sim.errors import ConfigurationError

__all__ = ['OverrideError', 'parse_overrides']


class OverrideError(ConfigurationError):
    """A ``NAME=VALUE`` override cannot be used.

    Attributes:
        item: the override as given ('' when the problem is the combination of overrides).
        name: the parameter's name ('' when the item has none).
        problem: what is wrong.
        suggestions: for an unknown name, declared names close to it.
    """

    def __init__(
        self, message: str, *, item: str = '', name: str = '', problem: str = '', suggestions=()
    ) -> None:
        super().__init__(message)
        self.item = item
        self.name = name
        self.problem = problem or message
        self.suggestions = tuple(suggestions)


def _split(item: str) -> tuple[str, str]:
    name, sep, text = item.partition(':=')
    if not sep:
        name, sep, text = item.partition('=')
    name = name.strip()
    if not sep or not name:
        msg = f'a parameter override must look like NAME=VALUE, got {item!r}'
        raise OverrideError(msg, item=item, problem='not NAME=VALUE')
    return name, text.strip()


def parse_overrides(
    items: Iterable[str],
    spec: ParameterSpec,
    *,
    reserved: Collection[str] = (),
    base: Any = None,
) -> dict[str, Any]:
    """Read ``NAME=VALUE`` (or ROS-style ``NAME:=VALUE``) items into typed parameter values.

    Args:
        items: the overrides, in command-line order (a later one wins).
        spec: the node's parameter spec.
        reserved: parameters the caller sets itself; overriding one is an error.
        base: the configuration the node's defaults come from (default: the dataclass's).

    Returns:
        Parameter name to value, of the parameter's type (arrays as lists).

    Raises:
        OverrideError: a malformed item, an unknown or reserved name, a value of the wrong
            type, out of range or not a choice, or overrides the configuration rejects
            together (its own cross-field checks).
    """
    values: dict[str, Any] = {}
    for item in items:
        name, text = _split(item)
        if name in reserved:
            msg = f'parameter {name!r} is set by the spawner from its own options'
            raise OverrideError(msg, item=item, name=name, problem='set by the spawner')
        try:
            values[name] = spec.parse_text(name, text)
        except ParameterError as err:
            raise OverrideError(
                str(err), item=item, name=name, problem=err.problem, suggestions=err.suggestions
            ) from err
    try:
        spec.build(values, base)
    except ValueError as err:
        raise OverrideError(' '.join(str(err).split())) from err
    return values
