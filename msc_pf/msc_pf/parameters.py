"""The controller configuration as flat ROS parameters, and back (ROS-free).

Every field of :class:`msc_pf.settings.MscPfConfig` becomes one parameter: top-level fields
keep their name (``scheme``, ``period_s``), nested ones are prefixed by their section
(``particle_filter.n_particles``, ``phases.gamma1_dbm``). Descriptions come from the
``Attributes:`` sections of the dataclass docstrings, so a field documented there is
documented in ``ros2 param describe`` too. Optional floats (None = derived default) are
carried as NaN.
"""

from __future__ import annotations

import dataclasses
import math
import re
import typing
from collections.abc import Mapping
from typing import Any

from msc_pf.errors import ConfigError
from msc_pf.settings import MscPfConfig

__all__ = ['config_from_parameters', 'parameter_defaults', 'parameter_descriptions']

ParameterValue = bool | int | float | str


def _sections() -> dict[str, type]:
    hints = typing.get_type_hints(MscPfConfig)
    return {
        f.name: hints[f.name]
        for f in dataclasses.fields(MscPfConfig)
        if dataclasses.is_dataclass(hints[f.name])
    }


def _plain(value: Any) -> ParameterValue:
    if value is None:
        return math.nan
    if isinstance(value, str):  # includes the Scheme enum
        return str(value)
    if isinstance(value, bool | int | float):
        return value
    raise ConfigError(f'no parameter type for {value!r}')


def parameter_defaults(config: MscPfConfig | None = None) -> dict[str, ParameterValue]:
    """Flat parameter name -> value of ``config`` (default: Table I defaults)."""
    config = config or MscPfConfig()
    sections = _sections()
    values: dict[str, ParameterValue] = {}
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        if f.name in sections:
            for sub in dataclasses.fields(value):
                values[f'{f.name}.{sub.name}'] = _plain(getattr(value, sub.name))
        else:
            values[f.name] = _plain(value)
    return values


def _attribute_docs(cls: type) -> dict[str, str]:
    doc = cls.__doc__ or ''
    if 'Attributes:' not in doc:
        return {}
    body = doc.split('Attributes:', 1)[1]
    docs: dict[str, str] = {}
    current = None
    for line in body.splitlines():
        match = re.match(r'^\s{8}(\w+): (.*)$', line)
        if match:
            current = match.group(1)
            docs[current] = match.group(2).strip()
        elif current and line.strip():
            docs[current] += ' ' + line.strip()
        elif current and not line.strip():
            current = None
    return docs


def parameter_descriptions() -> dict[str, str]:
    """Flat parameter name -> description (from the dataclass docstrings)."""
    sections = _sections()
    top = _attribute_docs(MscPfConfig)
    descriptions: dict[str, str] = {}
    for name in parameter_defaults():
        if '.' in name:
            section, field_name = name.split('.', 1)
            text = _attribute_docs(sections[section]).get(field_name, '')
            descriptions[name] = text or f'{section}: {field_name}'
        else:
            descriptions[name] = top.get(name, name)
    return descriptions


def config_from_parameters(values: Mapping[str, Any]) -> MscPfConfig:
    """Build and validate the configuration from flat parameter values.

    Names missing from ``values`` keep their defaults; unknown names are rejected.

    Raises:
        ConfigError: unknown parameter, wrong type or invalid value.
    """
    defaults = parameter_defaults()
    unknown = sorted(set(values) - set(defaults))
    if unknown:
        raise ConfigError(f'unknown parameters: {", ".join(unknown)}')
    sections = _sections()
    top: dict[str, Any] = {}
    nested: dict[str, dict[str, Any]] = {name: {} for name in sections}
    base = MscPfConfig()
    for name, value in values.items():
        default = defaults[name]
        if isinstance(default, float) and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if type(value) is not type(default):
            raise ConfigError(f'parameter {name} must be {type(default).__name__}, got {value!r}')
        if isinstance(value, float) and math.isnan(value):
            section, _, field_name = name.partition('.')
            current = getattr(getattr(base, section), field_name) if field_name else None
            if current is not None or not field_name:
                raise ConfigError(f'parameter {name} must be a number, got NaN')
            value = None
        if '.' in name:
            section, field_name = name.split('.', 1)
            nested[section][field_name] = value
        else:
            top[name] = value
    for section, cls in sections.items():
        top[section] = cls(**nested[section])
    return MscPfConfig(**top)
