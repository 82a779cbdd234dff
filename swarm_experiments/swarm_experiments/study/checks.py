"""Checks a study's ``check`` hook makes on one configuration before anything runs.

Each raises :class:`~.errors.UsageError` with one line naming the parameter (as ``--set``
names it), the value and the rule, so ``swarm_study`` stops with exit code 2 before it runs
or stores anything. :func:`settings_error` turns the exception of a validator the run itself
calls (a spawner's ``check_settings``, a settings dataclass) into such a line.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from typing import Any

from .errors import UsageError

__all__ = ['check_choice', 'check_number', 'check_whole', 'settings_error']


def _value(config: Mapping[str, Any], name: str) -> Any:
    """``config``'s value of ``name`` (dotted names reach nested parameters)."""
    node: Any = config
    for key in name.split('.'):
        node = node[key]
    return node


def _fail(name: str, value: Any, rule: str) -> UsageError:
    return UsageError(f'{name}={value!r}: {rule}')


def check_number(
    config: Mapping[str, Any],
    name: str,
    *,
    minimum: float | None = None,
    above: bool = False,
    maximum: float | None = None,
    allow_inf: bool = False,
    allow_none: bool = False,
) -> None:
    """``config[name]`` is a number in range: ``>= minimum`` (``> minimum`` with ``above``)
    and ``<= maximum``, finite unless ``allow_inf``, None only with ``allow_none``."""
    value = _value(config, name)
    if value is None and allow_none:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _fail(name, value, 'must be a number')
    if math.isnan(value) or (math.isinf(value) and not allow_inf):
        raise _fail(name, value, 'must be a finite number')
    if minimum is not None and (value <= minimum if above else value < minimum):
        raise _fail(name, value, f'must be {">" if above else ">="} {minimum:g}')
    if maximum is not None and value > maximum:
        raise _fail(name, value, f'must be <= {maximum:g}')


def check_whole(
    config: Mapping[str, Any],
    name: str,
    *,
    minimum: int | None = None,
    maximum: int | None = None,
    allow_none: bool = False,
) -> None:
    """``config[name]`` is a whole number in ``minimum..maximum`` (None with ``allow_none``)."""
    value = _value(config, name)
    if value is None and allow_none:
        return
    if isinstance(value, bool) or not isinstance(value, int):
        raise _fail(name, value, 'must be a whole number')
    if minimum is not None and value < minimum:
        raise _fail(name, value, f'must be >= {minimum}')
    if maximum is not None and value > maximum:
        raise _fail(name, value, f'must be <= {maximum}')


def check_choice(config: Mapping[str, Any], name: str, choices: Collection[Any]) -> None:
    """``config[name]`` is one of ``choices``."""
    value = _value(config, name)
    if value not in choices:
        raise _fail(name, value, f'choose one of {", ".join(str(c) for c in choices)}')


def settings_error(error: BaseException, where: str = '') -> UsageError:
    """A validator's exception as a one-line :class:`UsageError` (``where``: what was built,
    e.g. the parameter group, put first)."""
    text = ' '.join(str(error).split()) or type(error).__name__
    return UsageError(f'{where}: {text}' if where else text)
