"""Run specifications: one configuration and seed of a study, with a stable run id.

The run id is the first 16 hex digits of the SHA-256 of the canonical JSON of
``{study, config, seed}`` (keys sorted, no whitespace), where ``config`` is the run's whole
parameter set (axis values and fixed parameters). It is the same on every machine and every
run of the command, so a stored row marks its run as done; changing any parameter gives new
run ids.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import yaml
from swarm_common.params import kind_of_value

from .definition import Study
from .errors import StudyDefinitionError, StudyError, UsageError

__all__ = [
    'RunSpec',
    'StudyPlan',
    'check_config',
    'flatten',
    'make_specs',
    'parse_overrides',
    'run_id',
]


@dataclass(frozen=True)
class RunSpec:
    """One run: the study's name, the run's full parameters, its seed and run id.

    ``config`` holds every parameter (axis values and fixed ones, nested as the study
    declared them); ``axes`` names the keys of ``config`` that are the study's axes.
    """

    study: str
    config: Mapping[str, Any]
    seed: int
    run_id: str
    axes: tuple[str, ...] = ()

    @property
    def configuration(self) -> dict[str, Any]:
        """The axis values of this run (what identifies its configuration)."""
        return {axis: self.config[axis] for axis in self.axes}


@dataclass(frozen=True)
class StudyPlan:
    """The runs a study definition produces for one command line."""

    study: Study
    directory_name: str
    axes: Mapping[str, tuple[Any, ...]]
    params: Mapping[str, Any]
    seeds: tuple[int, ...]
    smoke: bool
    specs: tuple[RunSpec, ...] = field(repr=False)

    def manifest(self) -> dict[str, Any]:
        return {
            'study': self.study.name,
            'description': self.study.description,
            'smoke': self.smoke,
            'seed_label': self.study.seed_label,
            'axes': {axis: list(values) for axis, values in self.axes.items()},
            'params': _jsonable(self.params, 'params'),
            'seeds': list(self.seeds),
            'runs': len(self.specs),
        }


def _canonical_float(value: float) -> float | str:
    if math.isfinite(value):
        return value
    return repr(value)


def _jsonable(value: Any, where: str) -> Any:
    """``value`` as plain JSON types (tuples as lists); anything else is an error."""
    if isinstance(value, Mapping):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise StudyDefinitionError(f'{where}: key {key!r} is not a string')
            out[key] = _jsonable(item, f'{where}.{key}')
        return out
    if isinstance(value, (list, tuple)):
        return [_jsonable(item, f'{where}[]') for item in value]
    if isinstance(value, bool) or value is None or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        return _canonical_float(value)
    if hasattr(value, 'item') and callable(value.item):  # numpy scalar
        return _jsonable(value.item(), where)
    raise StudyDefinitionError(
        f'{where}: {type(value).__name__} is not a JSON value (use numbers, strings, '
        'booleans, lists and mappings)'
    )


def run_id(study: str, config: Mapping[str, Any], seed: int) -> str:
    """Stable id of one run: hash of the study name, the full parameters and the seed."""
    payload = json.dumps(
        {'study': study, 'config': _jsonable(config, 'config'), 'seed': int(seed)},
        sort_keys=True,
        separators=(',', ':'),
        allow_nan=False,
    )
    return hashlib.sha256(payload.encode()).hexdigest()[:16]


def flatten(mapping: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    """Nested mappings as one level with dotted keys (``{'a': {'b': 1}}`` -> ``{'a.b': 1}``)."""
    flat: dict[str, Any] = {}
    for key, value in mapping.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping):
            flat.update(flatten(value, f'{name}.'))
        else:
            flat[name] = value
    return flat


def _parse_value(text: str) -> Any:
    try:
        return yaml.safe_load(text) if text.strip() else ''
    except yaml.YAMLError:
        return text


def parse_overrides(items: Sequence[str]) -> dict[str, str]:
    """``['a.b=1', 'robots=2,4']`` -> ``{'a.b': '1', 'robots': '2,4'}`` (values unparsed)."""
    overrides: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition('=')
        key = key.strip()
        if not sep or not key:
            raise UsageError(f'--set {item!r}: expected PARAM=VALUE')
        if key in overrides:
            raise UsageError(f'--set {key} given twice')
        overrides[key] = value
    return overrides


def _set_nested(params: dict[str, Any], dotted: str, text: str) -> None:
    keys = dotted.split('.')
    node = params
    for depth, key in enumerate(keys[:-1]):
        child = node.get(key)
        if not isinstance(child, dict):
            where = '.'.join(keys[: depth + 1])
            raise UsageError(f'--set {dotted}: the study has no parameter group {where!r}')
        node = child
    leaf = keys[-1]
    if leaf not in node:
        raise UsageError(f'--set {dotted}: the study has no parameter {dotted!r}')
    if isinstance(node[leaf], dict):
        raise UsageError(f'--set {dotted}: is a parameter group; set one of its parameters')
    node[leaf] = _coerce(dotted, _parse_value(text), text, (node[leaf],))


def _axis_values(axis: str, text: str, declared: Sequence[Any]) -> tuple[Any, ...]:
    parsed = _parse_value(text)
    if isinstance(parsed, list):
        values = tuple(_coerce(axis, value, str(value), declared) for value in parsed)
    elif isinstance(parsed, str) and ',' in parsed:
        parts = parsed.split(',')
        values = tuple(_coerce(axis, _parse_value(part), part, declared) for part in parts)
    else:
        values = (_coerce(axis, parsed, text, declared),)
    if not values:
        raise UsageError(f'--set {axis}: give at least one value')
    return values


_KIND_NAMES = {
    'bool': 'true or false',
    'int': 'a whole number',
    'float': 'a number',
    'str': 'a word',
}


def _coerce(name: str, value: Any, text: str, declared: Sequence[Any]) -> Any:
    """``value`` (parsed from ``text``) as the type of the study's ``declared`` values.

    A parameter or axis whose declared values are all of one scalar type takes only values
    of that type (an int where a float is declared becomes a float, a number where words are
    declared stays the text given); ``None`` and parameters declared as ``None`` or of mixed
    types take anything, for the study's own check to judge.

    Raises:
        UsageError: the value is not of the declared type.
    """
    kinds = {kind_of_value(item) for item in declared if item is not None}
    if value is None or len(kinds) != 1:
        return value
    kind = kinds.pop()
    got = kind_of_value(value)
    if kind not in _KIND_NAMES or got == kind:
        return value
    if kind == 'float' and got == 'int':
        return float(value)
    if kind == 'float' and got == 'str':
        try:
            return float(value)  # 'inf', '1e3': numbers YAML 1.1 reads as words
        except ValueError:
            pass
    if kind == 'str' and got in ('int', 'float', 'bool'):
        return text.strip()
    example = next(item for item in declared if item is not None)
    raise UsageError(
        f'--set {name}={text.strip()}: expected {_KIND_NAMES[kind]} (like {example!r})'
    )


def check_config(study: Study, config: Mapping[str, Any]) -> None:
    """Run ``study``'s ``check`` hook on one configuration's parameters (if it has one).

    Raises:
        UsageError: the hook rejects a value (a hook's ``ValueError``, ``TypeError`` or
            ``KeyError`` is one too, its message on one line).
    """
    if study.check is None:
        return
    try:
        study.check(config)
    except StudyError:
        raise
    except (ValueError, TypeError, KeyError) as exc:
        text = ' '.join(str(exc).split()) or type(exc).__name__
        raise UsageError(f'study {study.name}: {text}') from exc


def make_specs(
    study: Study,
    *,
    runs: int | None = None,
    overrides: Mapping[str, str] | None = None,
    smoke: bool = False,
    first_seed: int | None = None,
) -> StudyPlan:
    """Expand ``study`` into its run specs, in axis order then seed order.

    ``runs`` replaces the seeds per configuration and ``first_seed`` the study's first seed
    (e.g. held-out sites 300, 301, ...); ``overrides`` (``PARAM -> VALUE`` text,
    values read as YAML) set fixed parameters (dotted names reach nested ones) or restrict an
    axis to the given comma-separated values; ``smoke`` applies the study's :class:`Smoke`
    first. Every configuration is checked by the study's ``check`` hook
    (:func:`check_config`) before a spec is made.

    Raises:
        UsageError: an unknown parameter, a value of the wrong type, or one the study's
            check rejects.
    """
    axes: dict[str, tuple[Any, ...]] = {axis: tuple(values) for axis, values in study.axes.items()}
    params: dict[str, Any] = copy.deepcopy(dict(study.params))
    count = study.runs
    if smoke:
        for axis, values in study.smoke.axes.items():
            axes[axis] = tuple(values)
        for key, value in flatten(study.smoke.params).items():
            _set_nested(params, key, json.dumps(_jsonable(value, key)))
        count = study.smoke.runs
    for key, text in (overrides or {}).items():
        if key in axes:
            axes[key] = _axis_values(key, text, study.axes[key])
        else:
            _set_nested(params, key, text)
    if runs is not None:
        if runs < 1:
            raise UsageError(f'the number of runs must be >= 1, not {runs}')
        count = runs
    if first_seed is None:
        first_seed = study.first_seed
    elif first_seed < 0:
        raise UsageError(f'the first seed must be >= 0, not {first_seed}')
    _jsonable(params, 'params')
    seeds = tuple(range(first_seed, first_seed + count))
    names = tuple(axes)
    specs = []
    for values in itertools.product(*(axes[name] for name in names)):
        config = {**copy.deepcopy(params), **dict(zip(names, values, strict=True))}
        check_config(study, config)
        for seed in seeds:
            specs.append(
                RunSpec(
                    study=study.name,
                    config=config,
                    seed=seed,
                    run_id=run_id(study.name, config, seed),
                    axes=names,
                )
            )
    return StudyPlan(
        study=study,
        directory_name=f'{study.name}-smoke' if smoke else study.name,
        axes=axes,
        params=params,
        seeds=seeds,
        smoke=smoke,
        specs=tuple(specs),
    )
