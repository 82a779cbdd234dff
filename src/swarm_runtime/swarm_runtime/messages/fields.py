"""Field descriptions of a message type, derived from a rosbags typestore definition.

rosbags describes a field as a nested tuple (``Nodetype.BASE/NAME/ARRAY/SEQUENCE``). The code
generator needs the rosidl view of the same field: its IDL type name, the Python type rosidl
maps it to, whether it is stored as ``array.array`` / ``numpy.ndarray``, bounds, defaults.
:func:`message_spec` turns one typestore entry into a :class:`MessageSpec` holding exactly that.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosbags.interfaces import Nodetype
from rosbags.typesys.base import normalize_fieldname

from .definition import (
    AbstractType,
    Array,
    BasicType,
    BoundedSequence,
    BoundedString,
    NamespacedType,
    UnboundedSequence,
    UnboundedString,
)
from .errors import InterfaceDefinitionError, UnknownMessageTypeError

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

__all__ = [
    'EMPTY_STRUCTURE_MEMBER',
    'ConstantSpec',
    'Container',
    'ElementSpec',
    'FieldSpec',
    'MessageSpec',
    'message_spec',
    'referenced_types',
    'split_typename',
]

#: The placeholder member rosidl adds to messages without fields (std_msgs/Empty).
EMPTY_STRUCTURE_MEMBER = 'structure_needs_at_least_one_member'

# rosbags base name -> IDL name rosidl uses (msg 'char' is an IDL uint8, 'byte' an octet).
_IDL_NAMES = {
    'bool': 'boolean',
    'byte': 'octet',
    'char': 'uint8',
    'float32': 'float',
    'float64': 'double',
    'int8': 'int8',
    'uint8': 'uint8',
    'int16': 'int16',
    'uint16': 'uint16',
    'int32': 'int32',
    'uint32': 'uint32',
    'int64': 'int64',
    'uint64': 'uint64',
}

# IDL numeric type -> (array.array type code, numpy dtype name): rosidl's special nested types.
NUMERIC_STORAGE = {
    'float': ('f', 'float32'),
    'double': ('d', 'float64'),
    'int8': ('b', 'int8'),
    'uint8': ('B', 'uint8'),
    'int16': ('h', 'int16'),
    'uint16': ('H', 'uint16'),
    'int32': ('i', 'int32'),
    'uint32': ('I', 'uint32'),
    'int64': ('q', 'int64'),
    'uint64': ('Q', 'uint64'),
}

INTEGER_BOUNDS = {
    'int8': (-(2**7), 2**7),
    'uint8': (0, 2**8),
    'int16': (-(2**15), 2**15),
    'uint16': (0, 2**16),
    'int32': (-(2**31), 2**31),
    'uint32': (0, 2**32),
    'int64': (-(2**63), 2**63),
    'uint64': (0, 2**64),
}

#: Largest finite magnitude rosidl accepts for 'float' and 'double' fields (its own literals).
FLOAT_LIMITS = {'float': 3.402823466e38, 'double': 1.7976931348623157e308}


class Container(enum.Enum):
    """How a field holds its element type."""

    NONE = 'none'
    ARRAY = 'array'
    SEQUENCE = 'sequence'


def split_typename(typename: str) -> tuple[str, str, str]:
    """Split ``'pkg/msg/Name'`` into ``('pkg', 'msg', 'Name')``."""
    parts = typename.split('/')
    if len(parts) != 3 or not all(parts):
        msg = f'{typename!r} is not a full message type name like "sensor_msgs/msg/LaserScan"'
        raise UnknownMessageTypeError(msg)
    return parts[0], parts[1], parts[2]


@dataclass(frozen=True)
class ElementSpec:
    """The element type of a field (the field's own type when it is not an array/sequence).

    Exactly one of ``base`` (a rosbags primitive name such as 'float32' or 'string') and
    ``nested`` (a message type name such as 'std_msgs/msg/Header') is non-empty.
    """

    base: str
    nested: str
    string_bound: int = 0

    @property
    def is_message(self) -> bool:
        """True for a nested message type."""
        return bool(self.nested)

    @property
    def is_string(self) -> bool:
        """True for ``string`` and ``string<=N``."""
        return self.base == 'string'

    @property
    def idl_name(self) -> str:
        """rosidl's name of a primitive ('float', 'double', 'boolean', 'octet', 'uint8' ...)."""
        return _IDL_NAMES[self.base]

    @property
    def is_numeric(self) -> bool:
        """True for the types rosidl stores in array.array / numpy arrays when nested."""
        return not self.is_message and not self.is_string and self.idl_name in NUMERIC_STORAGE

    @property
    def is_float(self) -> bool:
        """True for float32/float64."""
        return self.base in ('float32', 'float64')

    @property
    def is_integer(self) -> bool:
        """True for the integer types (including msg 'char', an IDL uint8)."""
        return not self.is_message and not self.is_string and self.idl_name in INTEGER_BOUNDS

    @property
    def python_type(self) -> str:
        """Python type rosidl maps the element to: float, int, bool, bytes, str or a class."""
        if self.is_message:
            return self.nested.rsplit('/', 1)[1]
        if self.is_string:
            return 'str'
        if self.base == 'bool':
            return 'bool'
        if self.base == 'byte':
            return 'bytes'
        if self.is_float:
            return 'float'
        return 'int'

    @property
    def typecode(self) -> str:
        """array.array type code of a numeric element."""
        return NUMERIC_STORAGE[self.idl_name][0]

    @property
    def dtype(self) -> str:
        """numpy dtype name of a numeric element."""
        return NUMERIC_STORAGE[self.idl_name][1]

    @property
    def rosidl_text(self) -> str:
        """The element's spelling in ``get_fields_and_field_types()``."""
        if self.is_message:
            package, _, name = split_typename(self.nested)
            return f'{package}/{name}'
        if self.is_string:
            return f'string<{self.string_bound}>' if self.string_bound else 'string'
        return self.idl_name

    def slot_type(self) -> AbstractType:
        """The ``rosidl_parser.definition``-like descriptor of the element."""
        if self.is_message:
            package, interface, name = split_typename(self.nested)
            return NamespacedType((package, interface), name)
        if self.is_string:
            return BoundedString(self.string_bound) if self.string_bound else UnboundedString()
        return BasicType(self.idl_name)


@dataclass(frozen=True)
class FieldSpec:
    """One field of a message type.

    ``length`` is the size of a fixed array, the bound of a bounded sequence, 0 otherwise.
    ``rosbags_name`` is the attribute name in rosbags' own message class (keywords get a suffix).
    """

    name: str
    rosbags_name: str
    element: ElementSpec
    container: Container
    length: int = 0

    @property
    def is_array(self) -> bool:
        """True for a fixed-size array ``T[N]``."""
        return self.container is Container.ARRAY

    @property
    def is_sequence(self) -> bool:
        """True for a bounded or unbounded sequence."""
        return self.container is Container.SEQUENCE

    @property
    def is_nested(self) -> bool:
        """True for arrays and sequences."""
        return self.container is not Container.NONE

    @property
    def rosidl_text(self) -> str:
        """The field's type as ``get_fields_and_field_types()`` spells it."""
        element = self.element.rosidl_text
        if self.is_array:
            return f'{element}[{self.length}]'
        if self.is_sequence:
            return f'sequence<{element}, {self.length}>' if self.length else f'sequence<{element}>'
        return element

    def slot_type(self) -> AbstractType:
        """The ``rosidl_parser.definition``-like descriptor of the field."""
        element = self.element.slot_type()
        if self.is_array:
            return Array(element, self.length)
        if self.is_sequence:
            return (
                BoundedSequence(element, self.length) if self.length else UnboundedSequence(element)
            )
        return element


@dataclass(frozen=True)
class ConstantSpec:
    """A constant of a message type with its rosidl Python value."""

    name: str
    base: str
    value: Any


@dataclass(frozen=True)
class MessageSpec:
    """Everything the code generator needs about one message type."""

    typename: str
    constants: tuple[ConstantSpec, ...]
    fields: tuple[FieldSpec, ...]
    #: True for types without fields, which rosbags pads with a uint8 placeholder member.
    padded_empty: bool = False

    @property
    def package(self) -> str:
        """The interface package, e.g. 'sensor_msgs'."""
        return split_typename(self.typename)[0]

    @property
    def interface(self) -> str:
        """The interface kind: 'msg' (or 'srv'/'action' for their generated parts)."""
        return split_typename(self.typename)[1]

    @property
    def name(self) -> str:
        """The class name, e.g. 'LaserScan'."""
        return split_typename(self.typename)[2]

    def nested_types(self) -> tuple[str, ...]:
        """Type names of the nested messages, in field order, without repetition."""
        seen: dict[str, None] = {}
        for field in self.fields:
            if field.element.is_message:
                seen.setdefault(field.element.nested, None)
        return tuple(seen)


def referenced_types(fielddefs: Any) -> set[str]:
    """Names of the message types a rosbags field list (``fielddefs[name][1]``) refers to."""
    names = set()
    for _, (kind, detail) in fielddefs:
        if kind == Nodetype.NAME:
            names.add(str(detail))
        elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE) and detail[0][0] == Nodetype.NAME:
            names.add(str(detail[0][1]))
    return names


def _element(desc: tuple[Any, Any], typename: str, field: str) -> ElementSpec:
    kind, detail = desc
    if kind == Nodetype.NAME:
        return ElementSpec(base='', nested=str(detail))
    if kind == Nodetype.BASE:
        base, bound = detail
        if base != 'string' and base not in _IDL_NAMES:
            msg = f"{typename}: field '{field}' has unsupported type {base!r}"
            raise InterfaceDefinitionError(msg)
        return ElementSpec(base=str(base), nested='', string_bound=int(bound or 0))
    msg = f"{typename}: field '{field}' nests arrays, which ROS messages cannot"
    raise InterfaceDefinitionError(msg)


def _constant_value(base: str, value: Any) -> Any:
    if base == 'byte':
        return bytes([int(value) & 0xFF])
    if base == 'bool':
        return bool(value)
    if base in ('float32', 'float64'):
        return float(value)
    if base == 'string':
        return str(value)
    return int(value)


def message_spec(typestore: Typestore, typename: str) -> MessageSpec:
    """Describe ``typename`` (e.g. 'sensor_msgs/msg/LaserScan') from ``typestore``.

    Raises:
        UnknownMessageTypeError: the typestore does not know the type.
        InterfaceDefinitionError: the definition uses something ROS messages cannot hold.
    """
    try:
        constants, fielddefs = typestore.fielddefs[typename]
    except KeyError:
        msg = f'unknown message type {typename!r}'
        raise UnknownMessageTypeError(msg) from None
    fields: list[FieldSpec] = []
    for name, desc in fielddefs:
        kind, detail = desc
        if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            subdesc, length = detail
            container = Container.ARRAY if kind == Nodetype.ARRAY else Container.SEQUENCE
            element = _element(subdesc, typename, name)
        else:
            container, length = Container.NONE, 0
            element = _element(desc, typename, name)
        fields.append(
            FieldSpec(
                name=name,
                rosbags_name=normalize_fieldname(name),
                element=element,
                container=container,
                length=int(length),
            )
        )
    padded = len(fields) == 1 and fields[0].name == EMPTY_STRUCTURE_MEMBER
    return MessageSpec(
        typename=typename,
        constants=tuple(
            ConstantSpec(name, str(base), _constant_value(str(base), value))
            for name, base, value in constants
        ),
        fields=() if padded else tuple(fields),
        padded_empty=padded,
    )
