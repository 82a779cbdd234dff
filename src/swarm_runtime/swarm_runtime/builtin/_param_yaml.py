"""Parameter values and parameter files, read with rcl's YAML rules.

rcl (``rcl_yaml_param_parser``) does not use YAML's own type resolution. For a plain
(unquoted) scalar it tries, in order: a boolean word (``true``, ``False``, ``yes``, ``on``,
...), an integer as C ``strtoll(s, NULL, 0)`` reads it (so ``0x1A`` is 26 and ``010`` is 8),
a floating-point number as ``strtod`` reads it (plus YAML's ``.inf``/``.nan``), and
otherwise a string. A quoted scalar is always a string. A sequence must hold scalars of one
type and becomes an array parameter. This module reproduces those rules on top of PyYAML's
composer, which keeps each scalar's quoting style.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from .errors import RCLInvalidROSArgsError

__all__ = [
    'ParameterFileEntry',
    'ParameterValueError',
    'load_parameter_file',
    'parse_parameter_value',
]

_TRUE_WORDS = frozenset({'Y', 'y', 'yes', 'Yes', 'YES', 'true', 'True', 'TRUE', 'on', 'On', 'ON'})
_FALSE_WORDS = frozenset(
    {'N', 'n', 'no', 'No', 'NO', 'false', 'False', 'FALSE', 'off', 'Off', 'OFF'}
)
_SPECIAL_FLOATS = {
    '.nan': math.nan,
    '.NaN': math.nan,
    '.NAN': math.nan,
    '.inf': math.inf,
    '.Inf': math.inf,
    '.INF': math.inf,
    '+.inf': math.inf,
    '+.Inf': math.inf,
    '+.INF': math.inf,
    '-.inf': -math.inf,
    '-.Inf': -math.inf,
    '-.INF': -math.inf,
}
_STRTOLL = re.compile(r'\s*([+-]?)(0[xX][0-9a-fA-F]+|0[0-7]*|[1-9][0-9]*)')
_STRTOD = re.compile(r'\s*[+-]?((\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|inf(inity)?|nan)', re.IGNORECASE)
_STRTOD_HEX = re.compile(
    r'\s*[+-]?0[xX]([0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(p[+-]?\d+)?', re.I
)


class ParameterValueError(RCLInvalidROSArgsError):
    """A parameter value or parameter file does not follow rcl's rules."""


def _plain_scalar_value(text: str) -> Any:
    if text in _TRUE_WORDS:
        return True
    if text in _FALSE_WORDS:
        return False
    match = _STRTOLL.fullmatch(text)
    if match:
        sign, digits = match.groups()
        if digits[:2] in ('0x', '0X'):
            value = int(digits, 16)
        elif len(digits) > 1 and digits[0] == '0':
            value = int(digits, 8)
        else:
            value = int(digits)
        value = -value if sign == '-' else value
        if -(2**63) <= value < 2**63:
            return value
    if text in _SPECIAL_FLOATS:
        return _SPECIAL_FLOATS[text]
    if _STRTOD.fullmatch(text):
        return float(text)
    if _STRTOD_HEX.fullmatch(text):
        stripped = text.strip()
        negative = stripped.startswith('-')
        value = float.fromhex(stripped.lstrip('+-'))
        return -value if negative else value
    return text


def _scalar_value(node: yaml.ScalarNode) -> Any:
    if node.style in ("'", '"'):
        return node.value
    return _plain_scalar_value(node.value)


def _array_value(node: yaml.SequenceNode, where: str) -> list[Any]:
    values: list[Any] = []
    for item in node.value:
        if not isinstance(item, yaml.ScalarNode):
            msg = (
                f'{where}: arrays may only hold scalars (nested sequences and maps are not allowed)'
            )
            raise ParameterValueError(msg)
        values.append(_scalar_value(item))
    if not values:
        msg = f'{where}: the type of an empty array cannot be inferred; give at least one value'
        raise ParameterValueError(msg)
    first_type = type(values[0])
    if any(type(value) is not first_type for value in values):
        types = sorted({type(value).__name__ for value in values})
        msg = f'{where}: array values must all have one type, got {", ".join(types)}'
        raise ParameterValueError(msg)
    return values


def _node_value(node: yaml.Node, where: str) -> Any:
    if isinstance(node, yaml.ScalarNode):
        return _scalar_value(node)
    if isinstance(node, yaml.SequenceNode):
        return _array_value(node, where)
    msg = f'{where}: a parameter value must be a scalar or an array, not a map'
    raise ParameterValueError(msg)


def parse_parameter_value(text: str, *, where: str = 'parameter value') -> Any:
    """Return the Python value of ``-p name:=<text>``: bool, int, float, str or a list.

    Raises:
        ParameterValueError: ``text`` is not valid YAML, a map, or a mixed-type array.
    """
    if not text.strip():
        return text
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as err:
        msg = f'{where}: {text!r} is not valid YAML: {err}'
        raise ParameterValueError(msg) from err
    if node is None:
        return text
    return _node_value(node, where)


@dataclass(frozen=True)
class ParameterFileEntry:
    """One parameter from a parameter file: the node key it is under, its name and value.

    ``node_key`` is the key as written (``/**``, ``/r0/algo``, ``algo``...); ``name`` is
    dotted for nested maps (``limits.max_speed``).
    """

    node_key: str
    name: str
    value: Any


def _mapping_items(node: yaml.Node, where: str) -> list[tuple[str, yaml.Node]]:
    if not isinstance(node, yaml.MappingNode):
        msg = f'{where}: expected a map'
        raise ParameterValueError(msg)
    items = []
    for key_node, value_node in node.value:
        if not isinstance(key_node, yaml.ScalarNode) or not key_node.value:
            msg = f'{where}: keys must be non-empty strings'
            raise ParameterValueError(msg)
        items.append((key_node.value, value_node))
    return items


def _flatten(node_key: str, prefix: str, node: yaml.Node, where: str) -> list[ParameterFileEntry]:
    entries = []
    for key, value_node in _mapping_items(node, where):
        name = f'{prefix}{key}'
        if isinstance(value_node, yaml.MappingNode):
            entries.extend(_flatten(node_key, name + '.', value_node, f'{where}.{key}'))
        else:
            value = _node_value(value_node, f'{where}.{key}')
            entries.append(ParameterFileEntry(node_key, name, value))
    return entries


def _node_entries(path_key: str, body: yaml.Node, where: str) -> list[ParameterFileEntry]:
    """Entries under one key: ``ros__parameters`` here, or nested namespace/node keys."""
    sections = _mapping_items(body, where)
    keys = [key for key, _ in sections]
    if 'ros__parameters' in keys:
        others = [key for key in keys if key != 'ros__parameters']
        if others:
            msg = f'{where}: only ros__parameters may appear under a node, found {others}'
            raise ParameterValueError(msg)
        return _flatten(path_key, '', dict(sections)['ros__parameters'], f'{where}.ros__parameters')
    entries: list[ParameterFileEntry] = []
    for key, nested in sections:
        if not isinstance(nested, yaml.MappingNode):
            msg = f"{where}.{key}: a node entry needs a 'ros__parameters' map"
            raise ParameterValueError(msg)
        entries.extend(
            _node_entries(f'{path_key.rstrip("/")}/{key.strip("/")}', nested, f'{where}.{key}')
        )
    return entries


def load_parameter_file(path: str | Path) -> list[ParameterFileEntry]:
    """Read a ROS 2 parameter file (``<node key>: {ros__parameters: {...}}``).

    Node keys may also be nested by namespace (``/r1: {algo: {ros__parameters: ...}}`` is
    ``/r1/algo``), as rcl allows.

    Returns:
        The entries in file order.

    Raises:
        ParameterValueError: the file cannot be read or is not a ROS 2 parameter file.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as err:
        msg = f"Couldn't parse params file '{path}': {err}"
        raise ParameterValueError(msg) from err
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as err:
        msg = f"Couldn't parse params file '{path}': {err}"
        raise ParameterValueError(msg) from err
    if root is None:
        return []
    entries: list[ParameterFileEntry] = []
    for node_key, body in _mapping_items(root, str(path)):
        if not isinstance(body, yaml.MappingNode):
            msg = f"{path}: {node_key}: a node entry needs a 'ros__parameters' map"
            raise ParameterValueError(msg)
        entries.extend(_node_entries(node_key, body, f'{path}: {node_key}'))
    return entries
