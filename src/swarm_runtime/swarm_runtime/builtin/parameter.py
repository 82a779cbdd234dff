"""``rclpy.parameter``: typed parameter values and their message conversions."""

from __future__ import annotations

import array
from enum import Enum
from pathlib import Path
from typing import Any

from ._messages import interface_class
from ._param_yaml import load_parameter_file, parse_parameter_value

__all__ = [
    'PARAMETER_SEPARATOR_STRING',
    'Parameter',
    'get_parameter_value',
    'parameter_dict_from_yaml_file',
    'parameter_value_to_python',
]

#: Separator of nested parameter names (``limits.max_speed``).
PARAMETER_SEPARATOR_STRING = '.'

# rcl_interfaces/msg/ParameterValue field holding the value of each type, by type number.
_VALUE_FIELDS = {
    1: 'bool_value',
    2: 'integer_value',
    3: 'double_value',
    4: 'string_value',
    5: 'byte_array_value',
    6: 'bool_array_value',
    7: 'integer_array_value',
    8: 'double_array_value',
    9: 'string_array_value',
}


def _all(values: Any, kind: type | tuple[type, ...]) -> bool:
    return all(isinstance(value, kind) for value in values)


class Parameter:
    """A named parameter value with its type (the Python side of rcl_interfaces/Parameter)."""

    class Type(Enum):
        """Parameter types; values are rcl_interfaces/msg/ParameterType constants."""

        NOT_SET = 0
        BOOL = 1
        INTEGER = 2
        DOUBLE = 3
        STRING = 4
        BYTE_ARRAY = 5
        BOOL_ARRAY = 6
        INTEGER_ARRAY = 7
        DOUBLE_ARRAY = 8
        STRING_ARRAY = 9

        @classmethod
        def from_parameter_value(cls, parameter_value: Any) -> Parameter.Type:
            """Return the type a Python value would have as a parameter.

            Raises:
                TypeError: the value cannot be a parameter (e.g. a dict, a mixed list).
            """
            if parameter_value is None:
                return cls.NOT_SET
            if isinstance(parameter_value, bool):
                return cls.BOOL
            if isinstance(parameter_value, int):
                return cls.INTEGER
            if isinstance(parameter_value, float):
                return cls.DOUBLE
            if isinstance(parameter_value, str):
                return cls.STRING
            if isinstance(parameter_value, (list, tuple, array.array)):
                if _all(parameter_value, bytes):
                    return cls.BYTE_ARRAY
                if _all(parameter_value, bool):
                    return cls.BOOL_ARRAY
                if _all(parameter_value, int):
                    return cls.INTEGER_ARRAY
                if _all(parameter_value, float):
                    return cls.DOUBLE_ARRAY
                if _all(parameter_value, str):
                    return cls.STRING_ARRAY
                msg = (
                    'The given value is not a list of one of the allowed types '
                    f"'{parameter_value}'."
                )
                raise TypeError(msg)
            msg = f"The given value is not one of the allowed types '{parameter_value}'."
            raise TypeError(msg)

        def check(self, parameter_value: Any) -> bool:
            """Return True when ``parameter_value`` is a valid value of this type."""
            kind = Parameter.Type
            if self is kind.NOT_SET:
                return parameter_value is None
            if self is kind.BOOL:
                return isinstance(parameter_value, bool)
            if self is kind.INTEGER:
                return isinstance(parameter_value, int)
            if self is kind.DOUBLE:
                return isinstance(parameter_value, float)
            if self is kind.STRING:
                return isinstance(parameter_value, str)
            if self is kind.BYTE_ARRAY:
                return isinstance(parameter_value, (list, tuple)) and all(
                    isinstance(value, bytes) and len(value) == 1 for value in parameter_value
                )
            if self is kind.BOOL_ARRAY:
                return isinstance(parameter_value, (list, tuple)) and _all(parameter_value, bool)
            if self is kind.INTEGER_ARRAY:
                return isinstance(parameter_value, (list, tuple, array.array)) and _all(
                    parameter_value, int
                )
            if self is kind.DOUBLE_ARRAY:
                return isinstance(parameter_value, (list, tuple, array.array)) and _all(
                    parameter_value, float
                )
            if self is kind.STRING_ARRAY:
                return isinstance(parameter_value, (list, tuple)) and _all(parameter_value, str)
            return False

    def __init__(self, name: str, type_: Parameter.Type | None = None, value: Any = None) -> None:
        if type_ is None:
            type_ = Parameter.Type.from_parameter_value(value)
        if not isinstance(type_, Parameter.Type):
            msg = f"type must be an instance of '{Parameter.Type!r}'"
            raise TypeError(msg)
        if not type_.check(value):
            msg = f"Type '{type_}' and value '{value}' do not agree"
            raise ValueError(msg)
        self._type_ = type_
        self._name = name
        self._value = value

    @property
    def name(self) -> str:
        """Fully qualified parameter name (dotted)."""
        return self._name

    @property
    def type_(self) -> Parameter.Type:
        """The parameter type."""
        return self._type_

    @property
    def value(self) -> Any:
        """The value (None when NOT_SET)."""
        return self._value

    def __repr__(self) -> str:
        return f'Parameter({self._name!r}, {self._type_}, {self._value!r})'

    @classmethod
    def from_parameter_msg(cls, param_msg: Any) -> Parameter:
        """Build a Parameter from an ``rcl_interfaces.msg.Parameter``."""
        type_ = Parameter.Type(param_msg.value.type)
        return cls(param_msg.name, type_, parameter_value_to_python(param_msg.value))

    def get_parameter_value(self) -> Any:
        """Return the value as an ``rcl_interfaces.msg.ParameterValue``."""
        value_msg = interface_class('rcl_interfaces', 'ParameterValue')(type=self._type_.value)
        field = _VALUE_FIELDS.get(self._type_.value)
        if field is not None:
            value = self._value
            if isinstance(value, (tuple, array.array)):
                value = list(value)
            setattr(value_msg, field, value)
        return value_msg

    def to_parameter_msg(self) -> Any:
        """Return this parameter as an ``rcl_interfaces.msg.Parameter``."""
        return interface_class('rcl_interfaces', 'Parameter')(
            name=self._name, value=self.get_parameter_value()
        )


def get_parameter_value(string_value: str) -> Any:
    """Guess a parameter's type from text (rcl's YAML rules) as a ``ParameterValue``."""
    value = parse_parameter_value(string_value)
    try:
        parameter = Parameter('value', value=value)
    except TypeError:
        parameter = Parameter('value', value=string_value)
    return parameter.get_parameter_value()


def parameter_value_to_python(parameter_value: Any) -> Any:
    """Return the Python value held by an ``rcl_interfaces.msg.ParameterValue``.

    Raises:
        RuntimeError: the message has an unknown ``type``.
    """
    type_number = parameter_value.type
    if type_number == 0:
        return None
    field = _VALUE_FIELDS.get(type_number)
    if field is None:
        msg = f'unexpected parameter type {type_number}'
        raise RuntimeError(msg)
    value = getattr(parameter_value, field)
    return list(value) if type_number >= 5 else value


def parameter_dict_from_yaml_file(
    parameter_file: str,
    use_wildcard: bool = False,
    target_nodes: list[str] | None = None,
    namespace: str = '',
) -> dict[str, Any]:
    """Read a parameter file into ``{name: rcl_interfaces.msg.Parameter}``.

    Entries under ``/**`` come first (when ``use_wildcard``) so that node entries override
    them; ``target_nodes`` restricts the node keys read; ``namespace`` prefixes every name.

    Raises:
        RuntimeError: a target node is missing from the file, or nothing was selected.
    """
    entries = load_parameter_file(Path(parameter_file))
    keys_in_file = list(dict.fromkeys(entry.node_key for entry in entries))
    selected: list[str] = ['/**'] if use_wildcard and '/**' in keys_in_file else []
    if target_nodes:
        for node in target_nodes:
            if node not in keys_in_file:
                msg = (
                    f'Param file does not contain parameters for {node},'
                    f'only for nodes: {keys_in_file} '
                )
                raise RuntimeError(msg)
            selected.append(node)
    else:
        selected.extend(key for key in keys_in_file if key != '/**')
    if not selected:
        raise RuntimeError('Param file does not contain selected parameters')
    result: dict[str, Any] = {}
    for key in selected:
        for entry in entries:
            if entry.node_key == key:
                name = namespace + entry.name
                result[name] = Parameter(name, value=entry.value).to_parameter_msg()
    return result
