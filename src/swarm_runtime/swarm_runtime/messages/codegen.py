"""Source generation for rosidl-like message classes and their rosbags converters.

Every message type gets its own class, built once from Python source text specialised to its
fields (the same approach rosidl_generator_py takes at build time, done here at first use):
no per-field dispatch happens when a message is constructed, assigned, compared or converted.

The generated class mirrors a Jazzy rosidl class: keyword construction, ``__slots__``
(``_<field>`` plus ``_check_fields``), one property per field whose setter applies rosidl's
assertions when field checks are on, ``__eq__``, ``__repr__``, ``get_fields_and_field_types()``,
``SLOT_TYPES`` and the constants as class attributes.
"""

from __future__ import annotations

import builtins
import keyword
import math
import re
from array import array
from collections import UserString
from collections.abc import Callable, Mapping
from operator import attrgetter
from typing import Any

import numpy as np

from . import checks
from .fields import FLOAT_LIMITS, INTEGER_BOUNDS, FieldSpec, MessageSpec

__all__ = [
    'GeneratedMessage',
    'build_converters',
    'build_message_class',
    'class_source',
    'converter_source',
    'module_name_for',
]


def _camel_to_snake(name: str) -> str:
    """rosidl's module naming: 'LaserScan' -> 'laser_scan', 'TFMessage' -> 'tf_message'."""
    name = re.sub(r'(.)([A-Z][a-z]+)', r'\1_\2', name)
    name = re.sub(r'([a-z0-9])([A-Z])', r'\1_\2', name)
    return name.lower()


def module_name_for(spec: MessageSpec) -> str:
    """The ``__module__`` rosidl gives the class, e.g. 'sensor_msgs.msg._laser_scan'."""
    return f'{spec.package}.{spec.interface}._{_camel_to_snake(spec.name)}'


class _Missing:
    """The default of constructor parameters: the field was not given."""

    __slots__ = ()

    def __repr__(self) -> str:
        return '<not given>'


_MISSING = _Missing()


class GeneratedMessage:
    """Base class of every generated message class (rosidl classes have none; it adds copying)."""

    __slots__ = ()
    __msgtype__: str

    def __copy__(self) -> GeneratedMessage:
        duplicate = object.__new__(type(self))
        for slot in type(self).__slots__:
            setattr(duplicate, slot, getattr(self, slot))
        return duplicate

    def __deepcopy__(self, memo: dict[int, Any]) -> GeneratedMessage:
        from copy import deepcopy

        duplicate = object.__new__(type(self))
        memo[id(self)] = duplicate
        for slot in type(self).__slots__:
            setattr(duplicate, slot, deepcopy(getattr(self, slot), memo))
        return duplicate

    def __reduce__(self) -> tuple[Any, ...]:
        from .registry import restore_message

        state = {slot: getattr(self, slot) for slot in type(self).__slots__}
        return (restore_message, (self.__msgtype__, state))


# --------------------------------------------------------------------------- class source


def _nested_names(spec: MessageSpec) -> dict[str, str]:
    """Namespace name of each nested message class: '_msg_0', '_msg_1', ..."""
    return {typename: f'_msg_{index}' for index, typename in enumerate(spec.nested_types())}


def _element_default(field: FieldSpec, nested: Mapping[str, str]) -> str:
    """Expression of a fresh default element value (rosidl's defaults)."""
    element = field.element
    if element.is_message:
        return f'_default{nested[element.nested]}()'
    if element.is_string:
        return "''"
    if element.base == 'byte':
        return "b'\\x00'"
    if element.base == 'bool':
        return 'False'
    if element.is_float:
        return '0.0'
    return '0'


def _zeros_name(field: FieldSpec) -> str:
    """Namespace name of the ``copy`` method of a fixed numeric array's zero template."""
    return f'_zeros_{field.length}_{field.element.dtype}'


def _zero_templates(spec: MessageSpec) -> dict[str, Any]:
    """``copy`` methods of zero arrays, one per fixed numeric array shape of ``spec``."""
    return {
        _zeros_name(field): np.zeros(field.length, dtype=field.element.dtype).copy
        for field in spec.fields
        if field.is_array and field.element.is_numeric
    }


def _default_expr(field: FieldSpec, nested: Mapping[str, str]) -> str:
    """Expression of a fresh default value of ``field``."""
    element = field.element
    if field.is_array:
        if element.is_numeric:
            # A copy of a zero template (never handed out): cheaper than numpy.zeros().
            return f'{_zeros_name(field)}()'
        return f'[{_element_default(field, nested)} for _ in range({field.length})]'
    if field.is_sequence:
        return f'_array({element.typecode!r})' if element.is_numeric else '[]'
    return _element_default(field, nested)


def _sequence_condition(field: FieldSpec, nested: Mapping[str, str]) -> tuple[str, str]:
    """rosidl's assertion (condition, message) for an array or sequence field."""
    element = field.element
    conditions = ['_is_sequence(value)']
    suffixes = ['a set or sequence']
    if element.is_string and element.string_bound:
        conditions.append(f'all(len(v) <= {element.string_bound} for v in value)')
        suffixes.append(f'and each string value not longer than {element.string_bound}')
    if field.is_array:
        conditions.append(f'len(value) == {field.length}')
        suffixes.insert(1, f'with length {field.length}')
    elif field.length:
        conditions.append(f'len(value) <= {field.length}')
        suffixes.insert(1, f'with length <= {field.length}')
    type_expr = nested[element.nested] if element.is_message else element.python_type
    conditions.append(f'_all_instances(value, {type_expr})')
    suffixes.append(f"and each value of type '{element.python_type}'")
    if element.is_integer:
        low, high = INTEGER_BOUNDS[element.idl_name]
        conditions.append(f'_integers_in_range(value, {low}, {high})')
        if low < 0:
            suffixes.append(f'and each integer in [{low}, {high - 1}]')
        else:
            suffixes.append(f'and each unsigned integer in [0, {high - 1}]')
    elif element.is_float:
        limit = FLOAT_LIMITS[element.idl_name]
        conditions.append(f'_floats_in_range(value, {limit!r})')
        suffixes.append(f'and each {element.idl_name} in [{-limit:f}, {limit:f}]')
    return ' and '.join(conditions), f"The '{field.name}' field must be {' '.join(suffixes)}"


def _scalar_assertions(field: FieldSpec, nested: Mapping[str, str]) -> list[str]:
    """rosidl's assertions for a field that is not an array or sequence."""
    name = field.name
    element = field.element
    if element.is_message:
        short = element.nested.rsplit('/', 1)[1]
        message = f"The '{name}' field must be a sub message of type '{short}'"
        return [f'assert isinstance(value, {nested[element.nested]}), {message!r}']
    if element.is_string and element.string_bound:
        bound = element.string_bound
        message = f"The '{name}' field must be string value not longer than {bound}"
        condition = f'isinstance(value, (str, _UserString)) and len(value) <= {bound}'
        return [f'assert {condition}, {message!r}']
    if element.is_string:
        message = f"The '{name}' field must be of type 'str'"
        return [f'assert isinstance(value, str), {message!r}']
    if element.base == 'byte':
        message = f"The '{name}' field must be of type 'bytes' or 'ByteString' with length 1"
        return [f'assert isinstance(value, (bytes, bytearray)) and len(value) == 1, {message!r}']
    python_type = element.python_type
    lines = [
        f'assert isinstance(value, {python_type}), '
        + repr(f"The '{name}' field must be of type '{python_type}'")
    ]
    if element.is_integer:
        low, high = INTEGER_BOUNDS[element.idl_name]
        kind = 'an integer' if low < 0 else 'an unsigned integer'
        message = f"The '{name}' field must be {kind} in [{low}, {high - 1}]"
        lines.append(f'assert value >= {low} and value < {high}, {message!r}')
    elif element.is_float:
        limit = FLOAT_LIMITS[element.idl_name]
        message = f"The '{name}' field must be a {element.idl_name} in [{-limit!r}, {limit!r}]"
        condition = f'not (value < {-limit!r} or value > {limit!r}) or _isinf(value)'
        lines.append(f'assert {condition}, {message!r}')
    return lines


def _checked_store(field: FieldSpec, nested: Mapping[str, str]) -> list[str]:
    """Lines that check ``value`` as rosidl's setter does, then store it in the slot."""
    name = field.name
    element = field.element
    slot = f'self._{name}'
    if field.is_nested and element.is_numeric:
        condition, message = _sequence_condition(field, nested)
        if field.is_array:
            dtype = element.dtype
            return [
                'if isinstance(value, _ndarray):',
                f'    assert value.dtype == _np.{dtype}, '
                + repr(f"The '{name}' numpy.ndarray() must have the dtype of 'numpy.{dtype}'"),
                f'    assert value.size == {field.length}, '
                + repr(f"The '{name}' numpy.ndarray() must have a size of {field.length}"),
                f'    {slot} = value',
                'else:',
                f'    assert {condition}, {message!r}',
                f'    {slot} = _np.array(value, dtype=_np.{dtype})',
            ]
        code = element.typecode
        lines = [
            'if isinstance(value, _array):',
            f'    assert value.typecode == {code!r}, '
            + repr(f"The '{name}' array.array() must have the type code of '{code}'"),
        ]
        if field.length:
            lines.append(
                f'    assert len(value) <= {field.length}, '
                + repr(f"The '{name}' array.array() must have a size <= {field.length}")
            )
        return [
            *lines,
            f'    {slot} = value',
            'else:',
            f'    assert {condition}, {message!r}',
            f'    {slot} = _numeric_array({code!r}, value)',
        ]
    if field.is_nested:
        condition, message = _sequence_condition(field, nested)
        return [f'assert {condition}, {message!r}', f'{slot} = value']
    return [*_scalar_assertions(field, nested), f'{slot} = value']


def _unchecked_store(field: FieldSpec) -> str:
    """What the setter stores when checks are off (rosidl still converts numeric arrays)."""
    element = field.element
    if field.is_nested and element.is_numeric:
        if field.is_array:
            return f'_np.array(value, dtype=_np.{element.dtype})'
        return f'_numeric_array({element.typecode!r}, value)'
    return 'value'


def _constructor_checked_given(field: FieldSpec, nested: Mapping[str, str]) -> list[str]:
    """Constructor lines that check and store a given ``value`` of ``field`` (checks on)."""
    element = field.element
    if not (field.is_sequence and element.is_numeric):
        return _checked_store(field, nested)
    # rosidl's constructor wraps the value in array.array before the setter sees it.
    lines = [f'value = _numeric_array({element.typecode!r}, value)']
    if field.length:
        lines.append(
            f'assert len(value) <= {field.length}, '
            + repr(f"The '{field.name}' array.array() must have a size <= {field.length}")
        )
    lines.append(f'self._{field.name} = value')
    return lines


def _constructor_checked(field: FieldSpec, nested: Mapping[str, str]) -> list[str]:
    """Constructor lines for ``field`` when checks are on (``**kwargs`` constructor)."""
    key = repr(field.name)
    lines = [f'if {key} in kwargs:', f'    value = kwargs[{key}]']
    lines.extend(f'    {line}' for line in _constructor_checked_given(field, nested))
    lines += ['else:', f'    self._{field.name} = {_default_expr(field, nested)}']
    return lines


def _constructor_unchecked(field: FieldSpec, nested: Mapping[str, str]) -> str:
    """Constructor line for ``field`` when checks are off."""
    key = repr(field.name)
    default = _default_expr(field, nested)
    if not field.is_nested and not field.element.is_message:
        return f'self._{field.name} = kwargs.get({key}, {default})'
    given = _unchecked_store(field).replace('value', f'kwargs[{key}]')
    return f'self._{field.name} = {given} if {key} in kwargs else {default}'


# Names the generated __init__ uses besides its parameters; fields could be named like them
# ('range', 'type', 'str' ...), so the keyword-parameter constructor reaches them as aliases.
_INIT_BUILTINS = (
    'all',
    'bool',
    'bytearray',
    'bytes',
    'float',
    'int',
    'isinstance',
    'len',
    'sorted',
    'str',
)
_IDENTIFIER_OR_STRING = re.compile(r"""'(?:[^'\\]|\\.)*'|"(?:[^"\\]|\\.)*"|\b[A-Za-z_]\w*\b""")


def _rename_identifiers(line: str, names: Mapping[str, str]) -> str:
    """Rename identifiers in a line of generated code, leaving string literals alone."""

    def replace(match: re.Match[str]) -> str:
        text = match.group(0)
        return names.get(text, text)

    return _IDENTIFIER_OR_STRING.sub(replace, line)


def _keyword_constructor_possible(spec: MessageSpec) -> bool:
    """Fields can be keyword parameters unless one is a Python keyword or ``self``."""
    return not any(keyword.iskeyword(f.name) or f.name == 'self' for f in spec.fields)


def _init_source(spec: MessageSpec, nested: Mapping[str, str]) -> list[str]:
    """The constructor: one keyword parameter per field (no kwargs dict to build and search,
    which makes construction much cheaper), or ``**kwargs`` if a field name cannot be one.

    Both behave like rosidl's ``__init__(self, **kwargs)``: keyword arguments only; unknown
    names fail the checks (AssertionError) and are ignored without them; a field that is not
    given gets a fresh default.
    """
    if not _keyword_constructor_possible(spec):
        return _kwargs_init_source(spec, nested)
    aliases = {name: f'_b_{name}' for name in _INIT_BUILTINS}
    aliases['value'] = '_v'
    params = ''.join(f'{f.name}=_MISSING, ' for f in spec.fields)
    out = [f'def __init__(self, *, {params}check_fields=_MISSING, **_unknown):']
    out.append('    check = _CHECK_FIELDS if check_fields is _MISSING else check_fields')
    out.append('    self._check_fields = check')
    out.append('    if check:')
    out.append(
        "        assert not _unknown, 'Invalid arguments passed to constructor: %s' % "
        "', '.join(_b_sorted(_unknown))"
    )
    for field in spec.fields:
        name = field.name
        out.append(f'        if {name} is _MISSING:')
        out.append(f'            self._{name} = {_default_expr(field, nested)}')
        out.append('        else:')
        out.append(f'            _v = {name}')
        for line in _constructor_checked_given(field, nested):
            out.append('            ' + _rename_identifiers(line, aliases))
    if spec.fields:
        out.append('    else:')
        for field in spec.fields:
            name = field.name
            given = _rename_identifiers(_unchecked_store(field), {'value': name})
            default = _default_expr(field, nested)
            out.append(f'        self._{name} = {default} if {name} is _MISSING else {given}')
    return out


def _kwargs_init_source(spec: MessageSpec, nested: Mapping[str, str]) -> list[str]:
    """The constructor as rosidl writes it, ``__init__(self, **kwargs)``."""
    out = ['def __init__(self, **kwargs):']
    out.append("    check = kwargs['check_fields'] if 'check_fields' in kwargs else _CHECK_FIELDS")
    out.append('    self._check_fields = check')
    out.append('    if check:')
    out.append(
        '        assert _VALID_KEYS.issuperset(kwargs), '
        "'Invalid arguments passed to constructor: %s' % "
        "', '.join(sorted(k for k in kwargs if k not in _VALID_KEYS))"
    )
    for field in spec.fields:
        out.extend(f'        {line}' for line in _constructor_checked(field, nested))
    if spec.fields:
        out.append('    else:')
        out.extend(f'        {_constructor_unchecked(field, nested)}' for field in spec.fields)
    return out


def class_source(spec: MessageSpec) -> str:
    """Python source of the functions of ``spec``'s class (see :func:`build_message_class`)."""
    nested = _nested_names(spec)
    out: list[str] = []

    for index, field in enumerate(spec.fields):
        out.append(f'def _set_{index}(self, value):')
        out.append('    if self._check_fields:')
        out.extend(f'        {line}' for line in _checked_store(field, nested))
        out.append('    else:')
        out.append(f'        self._{field.name} = {_unchecked_store(field)}')
        out.append('')

    out.extend(_init_source(spec, nested))
    out.append('')

    out.append('def _new_default():')
    out.append('    m = _new(_CLS)')
    out.append('    m._check_fields = _CHECK_FIELDS')
    out.extend(f'    m._{field.name} = {_default_expr(field, nested)}' for field in spec.fields)
    out.append('    return m')
    out.append('')

    out.append('def __eq__(self, other):')
    out.append('    if not isinstance(other, self.__class__):')
    out.append('        return False')
    for field in spec.fields:
        slot = f'_{field.name}'
        if field.is_array and field.element.is_numeric:
            out.append(f'    if not _arrays_equal(self.{slot}, other.{slot}):')
        else:
            out.append(f'    if self.{slot} != other.{slot}:')
        out.append('        return False')
    out.append('    return True')
    out.append('')

    display = f'{spec.package}.{spec.interface}.{spec.name}'
    out.append('def __repr__(self):')
    parts = []
    for field in spec.fields:
        if field.is_sequence and field.element.is_numeric:
            value = f'_sequence_repr(self._{field.name}, self._check_fields)'
        else:
            value = f'repr(self._{field.name})'
        parts.append(f'{field.name + "="!r} + {value}')
    joined = ', '.join(parts)
    out.append(f"    return {display + '(%s)'!r} % ', '.join(({joined}{',' if parts else ''}))")
    out.append('')
    return '\n'.join(out)


def _class_doc(spec: MessageSpec) -> str:
    if not spec.constants:
        return f"Message class '{spec.name}'."
    names = '\n'.join(f'      {constant.name}' for constant in spec.constants)
    return f"\n    Message class '{spec.name}'.\n\n    Constants:\n{names}\n    "


def build_message_class(
    spec: MessageSpec, nested_classes: Mapping[str, type], *, check_fields: bool
) -> type[GeneratedMessage]:
    """Create the class of ``spec``.

    Args:
        spec: The message type.
        nested_classes: Generated class of every type in ``spec.nested_types()``.
        check_fields: Default of ``_check_fields`` for new instances (rosidl reads
            ROS_PYTHON_CHECK_FIELDS once, when the package's module is imported).
    """
    nested = _nested_names(spec)
    namespace: dict[str, Any] = {
        '_CHECK_FIELDS': check_fields,
        '_VALID_KEYS': frozenset([*(f.name for f in spec.fields), 'check_fields']),
        '_new': object.__new__,
        '_array': array,
        '_ndarray': np.ndarray,
        '_np': np,
        '_isinf': math.isinf,
        '_UserString': UserString,
        '_numeric_array': checks.numeric_array,
        '_is_sequence': checks.is_sequence,
        '_all_instances': checks.all_instances,
        '_floats_in_range': checks.floats_in_range,
        '_integers_in_range': checks.integers_in_range,
        '_sequence_repr': checks.sequence_repr,
        '_arrays_equal': checks.arrays_equal,
        '_MISSING': _MISSING,
        **{f'_b_{name}': getattr(builtins, name) for name in _INIT_BUILTINS},
        **_zero_templates(spec),
    }
    for typename, alias in nested.items():
        namespace[alias] = nested_classes[typename]
        namespace[f'_default{alias}'] = nested_classes[typename]._new_default
    source = class_source(spec)
    exec(compile(source, f'<message {spec.typename}>', 'exec'), namespace)

    body: dict[str, Any] = {
        '__slots__': [*(f'_{f.name}' for f in spec.fields), '_check_fields'],
        '__doc__': _class_doc(spec),
        '__module__': module_name_for(spec),
        '__qualname__': spec.name,
        '__msgtype__': spec.typename,
        '__init__': namespace['__init__'],
        '__eq__': namespace['__eq__'],
        '__repr__': namespace['__repr__'],
        '__hash__': None,
        '_new_default': staticmethod(namespace['_new_default']),
        '_fields_and_field_types': {f.name: f.rosidl_text for f in spec.fields},
        'SLOT_TYPES': tuple(f.slot_type() for f in spec.fields),
        'get_fields_and_field_types': classmethod(_get_fields_and_field_types),
    }
    for constant in spec.constants:
        body[constant.name] = constant.value
    for index, field in enumerate(spec.fields):
        body[field.name] = property(
            attrgetter(f'_{field.name}'),
            namespace[f'_set_{index}'],
            doc=f"Message field '{field.name}'.",
        )
    cls = type(spec.name, (GeneratedMessage,), body)
    namespace['_CLS'] = cls
    return cls


def _get_fields_and_field_types(cls: type) -> dict[str, str]:
    """Return a copy of the field name -> rosidl type text mapping."""
    return dict(cls._fields_and_field_types)  # type: ignore[attr-defined]


# --------------------------------------------------------------------------- rosbags converters


def _to_rosbags_expr(field: FieldSpec, nested: Mapping[str, str]) -> str:
    value = f'm._{field.name}'
    element = field.element
    if not field.is_nested:
        if element.is_message:
            return f'_to{nested[element.nested]}({value})'
        if element.base == 'byte':
            return f'_octet_to_int8({value})'
        return value
    if element.is_message:
        return f'[_to{nested[element.nested]}(item) for item in {value}]'
    if element.is_numeric:
        return f'_np.asarray({value}, dtype=_np.{element.dtype})'
    if element.base == 'bool':
        return f'_np.asarray({value}, dtype=_np.bool_)'
    if element.base == 'byte':
        return f'_octets_to_numpy({value})'
    return value


def _from_rosbags_expr(field: FieldSpec, nested: Mapping[str, str]) -> str:
    value = f'r.{field.rosbags_name}'
    element = field.element
    if not field.is_nested:
        if element.is_message:
            return f'_from{nested[element.nested]}({value})'
        if element.base == 'byte':
            return f'_int8_to_octet({value})'
        return value
    if element.is_message:
        return f'[_from{nested[element.nested]}(item) for item in {value}]'
    if element.is_numeric:
        if field.is_array:
            return f'_np.array({value}, dtype=_np.{element.dtype})'
        return f'_array_from_numpy({value}, {element.typecode!r})'
    if element.base == 'bool':
        return f'[bool(item) for item in {value}]'
    if element.base == 'byte':
        return f'_octets_from_numpy({value})'
    return f'list({value})'


def converter_source(spec: MessageSpec) -> str:
    """Python source of ``_to_rosbags(m)`` and ``_from_rosbags(r)`` for ``spec``."""
    nested = _nested_names(spec)
    out = ['def _to_rosbags(m):']
    if spec.padded_empty:
        out.append('    return _RB(0)')
    else:
        args = ''.join(f'        {_to_rosbags_expr(f, nested)},\n' for f in spec.fields)
        out.append(f'    return _RB(\n{args}    )')
    out.append('')
    out.append('def _from_rosbags(r):')
    out.append('    m = _new(_CLS)')
    out.append('    m._check_fields = _CHECK_FIELDS')
    for field in spec.fields:
        out.append(f'    m._{field.name} = {_from_rosbags_expr(field, nested)}')
    out.append('    return m')
    out.append('')
    return '\n'.join(out)


def build_converters(
    spec: MessageSpec,
    cls: type,
    rosbags_cls: type,
    nested_converters: Mapping[str, tuple[Callable[[Any], Any], Callable[[Any], Any]]],
    *,
    check_fields: bool,
) -> tuple[Callable[[Any], Any], Callable[[Any], Any]]:
    """Create ``(to_rosbags, from_rosbags)`` for ``spec``.

    ``to_rosbags`` turns an instance of ``cls`` into rosbags' message object of the same type
    (without checking: a wrongly typed value surfaces when rosbags serializes it);
    ``from_rosbags`` builds an instance of ``cls`` the way rclpy hands a received message over.
    """
    nested = _nested_names(spec)
    namespace: dict[str, Any] = {
        '_RB': rosbags_cls,
        '_CLS': cls,
        '_CHECK_FIELDS': check_fields,
        '_new': object.__new__,
        '_np': np,
        '_octet_to_int8': checks.octet_to_int8,
        '_int8_to_octet': checks.int8_to_octet,
        '_octets_to_numpy': checks.octets_to_numpy,
        '_octets_from_numpy': checks.octets_from_numpy,
        '_array_from_numpy': checks.array_from_numpy,
    }
    for typename, alias in nested.items():
        to_nested, from_nested = nested_converters[typename]
        namespace[f'_to{alias}'] = to_nested
        namespace[f'_from{alias}'] = from_nested
    source = converter_source(spec)
    exec(compile(source, f'<converters {spec.typename}>', 'exec'), namespace)
    return namespace['_to_rosbags'], namespace['_from_rosbags']
